// Fixture recipes (sim/fixtures), as `gbdcs fixture render` and the recipe camera read them.
//
// Checks: recipe_from_json accepts or throws RecipeError, nothing else; an accepted recipe
// has a finite, non-negative duration and a frame count that agrees with it.
#include <cmath>
#include <optional>

#include "fuzz_harness.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/sim/recipe.hpp"

namespace gbdcs::fuzz {
namespace {
constexpr std::string_view kName = "fixture_recipe";
}

void fixture_recipe(Bytes input) {
  nlohmann::json doc;
  try {
    doc = contracts::parse_json(as_text(input));
  } catch (const contracts::ContractError&) {
    return;
  }
  std::optional<sim::Recipe> r;
  try {
    r = sim::recipe_from_json(doc, "fuzz.json");
  } catch (const sim::RecipeError&) {
    return;
  }
  const double duration = r->duration_s();
  require(std::isfinite(duration) && duration >= 0, kName,
          "accepted a recipe of duration " + std::to_string(duration) + " s");
  require(r->frame_count() >= 0, kName, "negative frame count");
}

}  // namespace gbdcs::fuzz

GBDCS_FUZZ_ENTRY(fixture_recipe)
