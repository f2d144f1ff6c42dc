#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "gbdcs/sim/fixture_renderer.hpp"

namespace gbdcs::sim {
namespace {

using nlohmann::json;

Recipe small_recipe(std::uint32_t seed) {
  return recipe_from_json(json::parse(R"({
    "seed": )" + std::to_string(seed) + R"(, "width": 160, "height": 120, "fps": 10,
    "background": {"kind": "cluttered", "shapes": 10},
    "segments": [
      {"no_hand": true, "duration_s": 0.5},
      {"pose": "OPEN_PALM", "duration_s": 1.0, "transition_s": 0},
      {"pose": "CALL", "duration_s": 1.0, "transition_s": 0.4},
      {"pose": "FIST", "duration_s": 1.0, "transition_s": 0.2, "exit": "left"},
      {"pose": "VICTORY", "duration_s": 0.5, "transition_s": 0.1, "occlusion": {"side": "top"}}
    ]})"));
}

TEST(FixtureRenderer, LabelsFollowTheSegments) {
  FixtureRenderer r(small_recipe(1));
  ASSERT_EQ(r.frame_count(), 40);
  const auto f0 = r.label(0);
  EXPECT_EQ(f0.pose, "NO_HAND");
  EXPECT_FALSE(f0.hand_present);
  EXPECT_FALSE(f0.landmarks.has_value());

  const auto f5 = r.label(5);
  EXPECT_EQ(f5.pose, "OPEN_PALM");
  EXPECT_TRUE(f5.deliberate);
  EXPECT_EQ(f5.gesture, contracts::GestureType::kOpenPalm);
  EXPECT_TRUE(f5.fully_visible);
  EXPECT_FALSE(f5.in_transition);

  const auto f15 = r.label(15);  // 0.0 s into CALL: blending from OPEN_PALM
  EXPECT_EQ(f15.pose, "CALL");
  EXPECT_TRUE(f15.in_transition);
  EXPECT_FALSE(f15.deliberate);
  EXPECT_EQ(f15.gesture, contracts::GestureType::kNone);
  EXPECT_FALSE(r.label(19).in_transition);

  // FIST leaves the frame to the left: visible at first, gone at the end.
  EXPECT_TRUE(r.label(27).fully_visible);
  const auto gone = r.label(34);
  EXPECT_FALSE(gone.fully_visible);
  EXPECT_LT(gone.landmarks->points[0].x, 0.1);

  // The occluded VICTORY is never fully visible, and some landmarks are hidden.
  const auto occluded = r.label(37);
  EXPECT_FALSE(occluded.fully_visible);
  int hidden = 0;
  for (bool v : occluded.visible) hidden += v ? 0 : 1;
  EXPECT_GT(hidden, 0);

  ASSERT_EQ(r.timings().size(), 5u);
  EXPECT_EQ(r.timings()[2].first_frame, 15);
  EXPECT_EQ(r.timings()[2].onset_frame, 19);
}

TEST(FixtureRenderer, SameSeedSameLabelsAndPixels) {
  FixtureRenderer a(small_recipe(7));
  FixtureRenderer b(small_recipe(7));
  FixtureRenderer c(small_recipe(8));
  std::vector<FrameLabel> la, lb, lc;
  for (std::int64_t i = 0; i < a.frame_count(); i += 3) {
    la.push_back(a.label(i));
    lb.push_back(b.label(i));
    lc.push_back(c.label(i));
  }
  EXPECT_EQ(a.labels_json(la).dump(), b.labels_json(lb).dump());
  EXPECT_NE(a.labels_json(la).dump(), c.labels_json(lc).dump());
  // Frames in any order: frame 12 is the same whether rendered first or after others.
  const cv::Mat first = a.frame(12).bgr;
  b.frame(3);
  b.frame(30);
  const cv::Mat later = b.frame(12).bgr;
  ASSERT_EQ(first.size(), cv::Size(160, 120));
  EXPECT_EQ(cv::norm(first, later, cv::NORM_INF), 0);
  // The hand is drawn where its landmarks say: the palm centre differs from the background.
  const auto label = a.frame(8).label;
  ASSERT_TRUE(label.landmarks);
}

// A segment with its own seed draws the same pose variant wherever it sits in the recipe.
TEST(FixtureRenderer, SegmentSeedKeepsItsVariant) {
  const auto a = recipe_from_json(json::parse(R"({"fps": 10, "segments": [
      {"no_hand": true, "duration_s": 1.0},
      {"pose": "FIST", "duration_s": 0.5, "seed": 42, "transition_s": 0}]})"));
  const auto b = recipe_from_json(json::parse(R"({"fps": 10, "seed": 9, "segments": [
      {"pose": "CALL", "duration_s": 1.0}, {"pose": "FIST", "duration_s": 0.5, "seed": 42,
       "transition_s": 0}]})"));
  FixtureRenderer ra(a);
  FixtureRenderer rb(b);
  const auto la = ra.label(12);
  const auto lb = rb.label(12);
  ASSERT_TRUE(la.landmarks && lb.landmarks);
  for (std::size_t i = 0; i < contracts::kLandmarkCount; ++i) {
    EXPECT_NEAR(la.landmarks->points[i].x, lb.landmarks->points[i].x, 1e-9);
    EXPECT_NEAR(la.landmarks->points[i].y, lb.landmarks->points[i].y, 1e-9);
  }
}

TEST(FixtureRenderer, LabelsJsonHasTheDocumentedShape) {
  FixtureRenderer r(small_recipe(2));
  std::vector<FrameLabel> labels;
  for (std::int64_t i = 0; i < r.frame_count(); ++i) labels.push_back(r.label(i));
  const json doc = r.labels_json(labels);
  EXPECT_EQ(doc["format"], "gbdcs-fixture-labels/1");
  EXPECT_EQ(doc["frame_count"], 40);
  EXPECT_EQ(doc["frames"].size(), 40u);
  EXPECT_EQ(doc["segments"].size(), 5u);
  EXPECT_EQ(doc["segments"][2]["onset_s"], 1.9);
  EXPECT_TRUE(doc["frames"][0]["landmarks"].is_null());
  EXPECT_EQ(doc["frames"][5]["landmarks"].size(), 21u);
  EXPECT_EQ(doc["frames"][5]["landmarks"][0].size(), 4u);  // x, y, z, visible
  EXPECT_EQ(doc["recipe"]["segments"][1]["pose"], "OPEN_PALM");
}

}  // namespace
}  // namespace gbdcs::sim
