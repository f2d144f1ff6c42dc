// The pixel cameras: a rendered recipe through the real vision stages gives the same flight
// twice (everything but the wall-clock processing time), the recipe's cached rendering read
// back as a recorded video + labels gives the same flight again, and a missing or broken
// recipe, video or labels file is named with its field and the fix.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "gbdcs/sim/scenario.hpp"
#include "gbdcs/sim/scenario_runner.hpp"

namespace gbdcs::sim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class PixelCameraTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("gbdcs-pixel-camera-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // The demo's take-off variant (seed 36, read by the tracker), then a half-closed hand.
    const json recipe = json::parse(R"({
      "name": "hop", "seed": 5, "width": 640, "height": 480, "fps": 15,
      "hand": {"skin_tone": "medium"}, "lighting": {"preset": "studio"},
      "background": {"kind": "textured"},
      "segments": [
        {"no_hand": true, "duration_s": 1.0},
        {"pose": "THUMB_UP", "duration_s": 3.0, "transition_s": 0, "seed": 36},
        {"pose": "HALF_CLOSED", "duration_s": 1.5, "transition_s": 0.5}]})");
    std::ofstream(dir_ / "hop.json") << recipe.dump(1);
  }
  void TearDown() override { fs::remove_all(dir_); }

  json scenario(const json& camera) const {
    json doc = json::parse(R"({
      "name": "pixels", "description": "take-off by a rendered thumb up", "drone": "dummy",
      "timeout_s": 6.5,
      "criteria": [
        {"name": "took off", "type": "command_sequence", "contains": ["TAKEOFF:THUMB_UP"]},
        {"name": "recognised", "type": "recognition_accuracy", "min": 1.0},
        {"name": "nothing spurious", "type": "false_positives", "scope": "all", "max": 0},
        {"name": "onset", "type": "latency", "measure": "onset_to_dispatch", "p95_ms": 3000},
        {"name": "processing", "type": "latency", "measure": "processing", "p95_ms": 60000}]})");
    doc["camera"] = camera;
    return doc;
  }

  RunOptions options() const {
    RunOptions o;
    o.keep_record = true;
    o.fixture_cache_dir = (dir_ / "cache").string();
    return o;
  }

  fs::path dir_;
};

void expect_same_flight(const ScenarioResult& a, const ScenarioResult& b) {
  ASSERT_EQ(a.record.commands.size(), b.record.commands.size());
  for (std::size_t i = 0; i < a.record.commands.size(); ++i) {
    const auto& x = a.record.commands[i];
    const auto& y = b.record.commands[i];
    EXPECT_EQ(x.t_s, y.t_s) << "command " << i;
    EXPECT_EQ(x.command.type, y.command.type) << "command " << i;
    EXPECT_EQ(x.command.source_id, y.command.source_id) << "command " << i;
    EXPECT_EQ(x.outcome, y.outcome) << "command " << i;
  }
  ASSERT_EQ(a.record.gestures.size(), b.record.gestures.size());
  for (std::size_t i = 0; i < a.record.gestures.size(); ++i) {
    EXPECT_EQ(a.record.gestures[i].t_s, b.record.gestures[i].t_s) << "gesture " << i;
    EXPECT_EQ(a.record.gestures[i].event.gesture, b.record.gestures[i].event.gesture);
    EXPECT_EQ(a.record.gestures[i].event.confidence, b.record.gestures[i].event.confidence);
  }
  ASSERT_EQ(a.criteria.size(), b.criteria.size());
  for (std::size_t i = 0; i < a.criteria.size(); ++i) {
    if (a.criteria[i].name == "processing") continue;  // wall time: differs run to run
    EXPECT_EQ(a.criteria[i].actual, b.criteria[i].actual) << a.criteria[i].name;
    EXPECT_EQ(a.criteria[i].verdict, b.criteria[i].verdict) << a.criteria[i].name;
  }
}

TEST_F(PixelCameraTest, RecipeCameraIsDeterministicAndMatchesItsRecording) {
  const auto doc = scenario({{"recipe", (dir_ / "hop.json").string()}});
  const auto first = run_scenario(Scenario::from_json(doc), options());
  ASSERT_TRUE(first.error.empty()) << first.error;
  for (const auto& c : first.criteria) {
    EXPECT_NE(c.verdict, Verdict::kFailure) << c.name << ": " << c.actual;
  }
  EXPECT_NE(first.camera.find("recipe 'hop'"), std::string::npos) << first.camera;
  // The take-off came from pixels: its processing time (capture -> dispatch) was measured.
  ASSERT_FALSE(first.record.commands.empty());
  EXPECT_GT(first.record.commands.front().processing_ms, 0);

  const auto second = run_scenario(Scenario::from_json(doc), options());  // from the cache
  ASSERT_TRUE(second.error.empty()) << second.error;
  expect_same_flight(first, second);

  // The cached rendering is a fixture folder: as a recorded camera it flies the same.
  fs::path rendered;
  for (const auto& e : fs::directory_iterator(dir_ / "cache")) rendered = e.path();
  ASSERT_TRUE(fs::exists(rendered / "labels.json")) << rendered;
  const auto recorded =
      run_scenario(Scenario::from_json(scenario({{"video", (rendered / "video.mp4").string()},
                                                 {"labels", (rendered / "labels.json").string()}})),
                   options());
  ASSERT_TRUE(recorded.error.empty()) << recorded.error;
  expect_same_flight(first, recorded);
}

// What the runner says when the scenario loads but its camera cannot be opened.
std::string run_error(const json& doc) {
  try {
    const auto r = run_scenario(Scenario::from_json(doc, ".", "s.json"));
    return r.error.empty() ? "ran" : r.error;
  } catch (const std::exception& e) {
    return e.what();
  }
}

std::string load_error(const json& doc) {
  try {
    (void)Scenario::from_json(doc, ".", "s.json");
  } catch (const ScenarioError& e) {
    return e.what();
  }
  return "loaded";
}

TEST_F(PixelCameraTest, MissingFilesNameTheFieldAndTheFix) {
  auto e = load_error(scenario({{"recipe", (dir_ / "nope.json").string()}}));
  EXPECT_NE(e.find("camera.recipe"), std::string::npos) << e;
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;
  EXPECT_NE(e.find("give the path of a fixture recipe"), std::string::npos) << e;

  e = load_error(scenario(
      {{"video", (dir_ / "none.mp4").string()}, {"labels", (dir_ / "hop.json").string()}}));
  EXPECT_NE(e.find("camera.video"), std::string::npos) << e;
  EXPECT_NE(e.find("recorded fixture folder"), std::string::npos) << e;

  std::ofstream(dir_ / "video.mp4") << "not a video";
  e = load_error(scenario({{"video", (dir_ / "video.mp4").string()}}));
  EXPECT_NE(e.find("camera.labels"), std::string::npos) << e;
  EXPECT_NE(e.find("labels.json"), std::string::npos) << e;

  e = load_error(scenario(
      {{"video", (dir_ / "video.mp4").string()}, {"labels", (dir_ / "labels.json").string()}}));
  EXPECT_NE(e.find("camera.labels"), std::string::npos) << e;
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;

  // Files that exist but are not what they claim: the run fails naming the field.
  std::ofstream(dir_ / "labels.json") << R"({"format": "something else"})";
  auto r = run_error(scenario(
      {{"video", (dir_ / "video.mp4").string()}, {"labels", (dir_ / "labels.json").string()}}));
  EXPECT_NE(r.find("camera.labels"), std::string::npos) << r;
  EXPECT_NE(r.find("gbdcs fixture check"), std::string::npos) << r;

  std::ofstream(dir_ / "bad_recipe.json") << R"({"name": "x", "segments": [{"pose": "WAVE"}]})";
  r = run_error(scenario({{"recipe", (dir_ / "bad_recipe.json").string()}}));
  EXPECT_NE(r.find("camera.recipe"), std::string::npos) << r;
  EXPECT_NE(r.find("segments[0].pose"), std::string::npos) << r;
}

}  // namespace
}  // namespace gbdcs::sim
