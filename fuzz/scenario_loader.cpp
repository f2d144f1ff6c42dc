// Scenario files (sim/scenario), as `gbdcs scenario run` reads them: JSON text, then
// Scenario::from_json with the repository's scenarios/ folder as the base for the relative
// paths they name (profiles, timelines, recipes).
//
// Checks: the loader accepts or throws ScenarioError, nothing else; an accepted scenario has
// its events sorted by time and a positive, finite timeout.
#include <algorithm>
#include <cmath>

#include "fuzz_harness.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/sim/scenario.hpp"

namespace gbdcs::fuzz {
namespace {
constexpr std::string_view kName = "scenario_loader";
}

void scenario_loader(Bytes input) {
  nlohmann::json doc;
  try {
    doc = contracts::parse_json(as_text(input));
  } catch (const contracts::ContractError&) {
    return;
  }
  sim::Scenario s;
  try {
    s = sim::Scenario::from_json(doc, GBDCS_SOURCE_DIR "/scenarios", "fuzz.json");
  } catch (const sim::ScenarioError&) {
    return;
  }
  require(std::is_sorted(s.events.begin(), s.events.end(),
                         [](const auto& a, const auto& b) { return a.at_s < b.at_s; }),
          kName, "events not sorted by time");
  require(std::isfinite(s.timeout_s) && s.timeout_s > 0, kName,
          "accepted timeout_s " + std::to_string(s.timeout_s));
}

}  // namespace gbdcs::fuzz

GBDCS_FUZZ_ENTRY(scenario_loader)
