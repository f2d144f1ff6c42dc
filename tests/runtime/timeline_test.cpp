#include <gtest/gtest.h>

#include "gbdcs/sim/gesture_timeline.hpp"

namespace gbdcs::sim {
namespace {

std::string error_of(const std::string& text) {
  try {
    GestureTimeline::from_json(nlohmann::json::parse(text));
  } catch (const TimelineError& e) {
    return e.what();
  }
  return "no error";
}

TEST(GestureTimeline, FramesFollowSegments) {
  auto t = GestureTimeline::from_json(nlohmann::json::parse(
      R"({"seed":5,"fps":10,"segments":[{"pose":"NO_HAND","duration_s":1},
          {"pose":"FIST","duration_s":0.5}]})"));
  EXPECT_EQ(t.frame_count(), 15u);
  for (int i = 0; i < 10; ++i) {
    auto f = t.next_frame();
    EXPECT_FALSE(f.hand.has_value());
    EXPECT_EQ(f.label, "NO_HAND");
  }
  auto f = t.next_frame();
  ASSERT_TRUE(f.hand.has_value());
  EXPECT_EQ(f.label, "FIST");
  EXPECT_EQ(f.deliberate, contracts::GestureType::kFist);
  EXPECT_DOUBLE_EQ(f.time_s, 1.0);
}

TEST(GestureTimeline, SameSeedSameLandmarks) {
  const auto doc = nlohmann::json::parse(
      R"({"seed":9,"segments":[{"pose":"VICTORY","duration_s":0.2}]})");
  auto a = GestureTimeline::from_json(doc);
  auto b = GestureTimeline::from_json(doc);
  for (int i = 0; i < 6; ++i) {
    auto fa = a.next_frame();
    auto fb = b.next_frame();
    for (std::size_t k = 0; k < contracts::kLandmarkCount; ++k) {
      EXPECT_DOUBLE_EQ(fa.hand->points[k].x, fb.hand->points[k].x);
    }
  }
}

TEST(GestureTimeline, BadFilesNameTheProblem) {
  EXPECT_NE(error_of(R"({"segments":[]})").find("non-empty"), std::string::npos);
  EXPECT_NE(error_of(R"({"segments":[{"pose":"WAVE","duration_s":1}]})").find("unknown pose 'WAVE'"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"segments":[{"pose":"FIST"}]})").find("segments[0]: 'duration_s'"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"segments":[{"pose":"FIST","duration_s":1,"size":7}]})").find("'size'"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"fps":"fast","segments":[{"pose":"FIST","duration_s":1}]})").find("'fps'"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"segmnts":[]})").find("unknown field 'segmnts'"), std::string::npos);
  EXPECT_THROW(GestureTimeline::load_file("/nonexistent.json"), TimelineError);
}

TEST(GestureTimeline, TheDemoFlightLoads) {
  auto t = GestureTimeline::load_file(std::string(GBDCS_SOURCE_DIR) +
                                      "/fixtures/timelines/demo_flight.json");
  EXPECT_GT(t.duration_s(), 20);
}

}  // namespace
}  // namespace gbdcs::sim
