#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validation_results.hpp>
#include <valijson/validator.hpp>

#include "gbdcs/sim/recipe.hpp"

namespace gbdcs::sim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json minimal() { return json::parse(R"({"segments": [{"pose": "FIST", "duration_s": 1}]})"); }

std::string error_of(const json& doc) {
  try {
    recipe_from_json(doc, "r.json");
  } catch (const RecipeError& e) {
    return e.what();
  }
  return "";
}

TEST(Recipe, DefaultsFillTheRest) {
  const Recipe r = recipe_from_json(minimal());
  EXPECT_EQ(r.width, 640);
  EXPECT_EQ(r.height, 480);
  EXPECT_EQ(r.fps, 30);
  ASSERT_EQ(r.segments.size(), 1u);
  EXPECT_EQ(r.segments[0].pose->name(), "FIST");
  EXPECT_EQ(r.frame_count(), 30);
  EXPECT_EQ(r.segments[0].placement.distance_m, 0.45);
}

TEST(Recipe, ErrorsNameTheFieldAndTheFix) {
  json d = minimal();
  d["segments"][0]["pose"] = "FISTS";
  EXPECT_NE(error_of(d).find("r.json: segments[0].pose is \"FISTS\"; use one of OPEN_PALM"),
            std::string::npos)
      << error_of(d);

  d = minimal();
  d["segments"][0]["placement"] = {{"distance_m", 3.0}};
  EXPECT_NE(error_of(d).find("segments[0].placement.distance_m is 3; use a value from 0.3 to 2"),
            std::string::npos)
      << error_of(d);

  d = minimal();
  d["lighting"] = {{"colour", {1, 1}}};
  EXPECT_NE(error_of(d).find("lighting.colour must be [r, g, b]"), std::string::npos);

  d = minimal();
  d["backgroud"] = {{"kind", "plain"}};
  EXPECT_NE(error_of(d).find("backgroud is not a recipe field here; known fields:"),
            std::string::npos)
      << error_of(d);

  d = minimal();
  d["hand"] = {{"skin_tone", "green"}};
  EXPECT_NE(error_of(d).find("hand.skin_tone is \"green\"; use one of light"), std::string::npos);

  d = minimal();
  d["segments"][0]["transition_s"] = 2;
  EXPECT_NE(error_of(d).find("transition_s must be shorter than duration_s"), std::string::npos);

  d = minimal();
  d["segments"] = json::array();
  EXPECT_NE(error_of(d).find("segments must be a non-empty array"), std::string::npos);

  d = minimal();
  d["segments"][0] = {{"duration_s", 1}};
  EXPECT_NE(error_of(d).find("segments[0].pose is missing"), std::string::npos);

  d = minimal();
  d["seed"] = -1;
  EXPECT_NE(error_of(d).find("seed must be a whole number"), std::string::npos);
}

TEST(Recipe, LoadingAFileNamesIt) {
  const fs::path dir = fs::temp_directory_path() / ("gbdcs_recipe_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "bad.json") << "{\"segments\": [";
  try {
    load_recipe(dir / "bad.json");
    FAIL() << "no error";
  } catch (const RecipeError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json: not valid JSON"), std::string::npos);
  }
  EXPECT_THROW(load_recipe(dir / "missing.json"), RecipeError);
  fs::remove_all(dir);
}

// Every recipe shipped in fixtures/ loads, and is valid against fixtures/recipe.schema.json:
// the loader and the schema describe the same format.
TEST(Recipe, ShippedRecipesLoadAndMatchTheSchema) {
  const fs::path root = fs::path(GBDCS_SOURCE_DIR) / "fixtures";
  std::ifstream schema_in(root / "recipe.schema.json");
  ASSERT_TRUE(schema_in);
  const json schema_doc = json::parse(schema_in);
  valijson::Schema schema;
  valijson::SchemaParser parser(valijson::SchemaParser::kDraft7);
  valijson::adapters::NlohmannJsonAdapter schema_adapter(schema_doc);
  parser.populateSchema(schema_adapter, schema);
  int count = 0;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const fs::path& p = entry.path();
    if (p.extension() != ".json" || p.filename() == "recipe.schema.json") continue;
    if (const auto dir = p.parent_path().filename(); dir != "suite" && dir != "recipes" && dir != "bank") continue;
    SCOPED_TRACE(p.string());
    EXPECT_NO_THROW(load_recipe(p));
    std::ifstream in(p);
    const json doc = json::parse(in);
    valijson::Validator validator;
    valijson::ValidationResults results;
    valijson::adapters::NlohmannJsonAdapter target(doc);
    EXPECT_TRUE(validator.validate(schema, target, &results));
    ++count;
  }
  EXPECT_GE(count, 12);
  // And the schema rejects what the loader rejects.
  json bad = minimal();
  bad["segments"][0]["pose"] = "WAVE";
  valijson::Validator validator;
  valijson::adapters::NlohmannJsonAdapter target(bad);
  EXPECT_FALSE(validator.validate(schema, target, nullptr));
}

TEST(Recipe, SegmentPosesCoverTheVocabularyAndTheNonDeliberatePoses) {
  const auto names = segment_pose_names();
  EXPECT_EQ(names.size(), kAllPoses.size() + 2);
  int deliberate = 0;
  for (const auto& n : names) {
    const auto p = segment_pose_from_string(n);
    ASSERT_TRUE(p) << n;
    EXPECT_EQ(p->name(), n);
    if (p->gesture()) ++deliberate;
  }
  EXPECT_EQ(deliberate, 9);
}

}  // namespace
}  // namespace gbdcs::sim
