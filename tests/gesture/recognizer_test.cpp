// RuleBasedRecognizer: invariances, direction rules, presence, degenerate input, options.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "gbdcs/gesture/rule_based_recognizer.hpp"
#include "synthetic_hands.hpp"

namespace gbdcs::gesture {
namespace {

using contracts::GestureType;
using contracts::Landmarks;
using sim::PoseName;

Landmarks place(const sim::HandPose& pose, double roll_deg = 0, double size = 0.4,
                contracts::Handedness hand = contracts::Handedness::kRight, double cx = 0.5,
                double cy = 0.5) {
  sim::Placement p;
  p.roll_deg = roll_deg;
  p.size = size;
  p.handedness = hand;
  p.center_x = cx;
  p.center_y = cy;
  return sim::synthesize(pose, p);
}

// The same hand, scaled, moved, mirrored and (for shapes) turned in the image, must read the
// same with the same confidence: the features are ratios and angles.
TEST(RuleBasedRecognizer, InvariantToScaleTranslationHandednessAndShapeRoll) {
  const RuleBasedRecognizer recognizer;
  std::mt19937 rng(5);
  for (PoseName name : sim::kAllPoses) {
    for (int i = 0; i < 20; ++i) {
      const sim::HandPose pose = sim::pose_for(name, rng);
      const Recognition base = recognizer.recognize(place(pose));
      ASSERT_EQ(base.gesture, testing::expected_gesture(name)) << sim::to_string(name);
      std::vector<Landmarks> variants = {
          place(pose, 0, 0.15), place(pose, 0, 0.6, contracts::Handedness::kRight, 0.3, 0.6),
          place(pose, 0, 0.4, contracts::Handedness::kLeft)};
      if (!sim::is_direction_pose(name)) {
        for (double roll : {-150.0, -90.0, 45.0, 120.0, 180.0}) variants.push_back(place(pose, roll));
      }
      for (const Landmarks& v : variants) {
        const Recognition r = recognizer.recognize(v);
        EXPECT_EQ(r.gesture, base.gesture) << sim::to_string(name);
        EXPECT_NEAR(r.confidence, base.confidence, 1e-6) << sim::to_string(name);
      }
    }
  }
}

TEST(RuleBasedRecognizer, DirectionGesturesFollowTheImageDirection) {
  const RuleBasedRecognizer recognizer;
  std::mt19937 rng(9);
  for (int i = 0; i < 20; ++i) {
    sim::HandPose up = sim::pose_for(PoseName::kPointUp, rng);
    up.orientation.aim_deg = 0;  // exactly up, without the library's aim noise
    EXPECT_EQ(recognizer.recognize(place(up)).gesture, GestureType::kPointUp);
    EXPECT_EQ(recognizer.recognize(place(up, 90)).gesture, GestureType::kPointRight);
    EXPECT_EQ(recognizer.recognize(place(up, -90)).gesture, GestureType::kPointLeft);
    EXPECT_EQ(recognizer.recognize(place(up, 180)).gesture, GestureType::kNone);  // down
    EXPECT_EQ(recognizer.recognize(place(up, 45)).gesture, GestureType::kNone);  // diagonal
    EXPECT_EQ(recognizer.recognize(place(up, 65)).gesture, GestureType::kPointRight);

    sim::HandPose thumb = sim::pose_for(PoseName::kThumbUp, rng);
    thumb.orientation.aim_deg = 0;
    EXPECT_EQ(recognizer.recognize(place(thumb)).gesture, GestureType::kThumbUp);
    EXPECT_EQ(recognizer.recognize(place(thumb, 180)).gesture, GestureType::kThumbDown);
    EXPECT_EQ(recognizer.recognize(place(thumb, 90)).gesture, GestureType::kNone);
    EXPECT_EQ(recognizer.recognize(place(thumb, -60)).gesture, GestureType::kNone);
  }
}

TEST(RuleBasedRecognizer, ConfidenceFallsTowardTheToleranceEdge) {
  const RuleBasedRecognizer recognizer;
  std::mt19937 rng(21);
  sim::HandPose up = sim::pose_for(PoseName::kPointUp, rng);
  up.orientation.aim_deg = 0;  // exactly up
  const double straight = recognizer.recognize(place(up)).confidence;
  const Recognition tilted = recognizer.recognize(place(up, 32));
  EXPECT_EQ(tilted.gesture, GestureType::kPointUp);
  EXPECT_LT(tilted.confidence, 0.6);
  EXPECT_GT(straight, tilted.confidence);
}

TEST(RuleBasedRecognizer, LowPresenceLowersConfidence) {
  const RuleBasedRecognizer recognizer;
  std::mt19937 rng(3);
  Landmarks hand = place(sim::pose_for(PoseName::kOpenPalm, rng));
  hand.score = 0.95;
  const Recognition sure = recognizer.recognize(hand);
  hand.score = 0.5;
  const Recognition unsure = recognizer.recognize(hand);
  EXPECT_EQ(unsure.gesture, GestureType::kOpenPalm);
  EXPECT_LT(unsure.confidence, 0.6);
  EXPECT_LT(unsure.confidence, sure.confidence);
  hand.score = 0.1;
  const Recognition absent = recognizer.recognize(hand);
  EXPECT_EQ(absent.gesture, GestureType::kNone);
  EXPECT_EQ(absent.confidence, 0);
}

TEST(RuleBasedRecognizer, DegenerateInputIsNoneWithZeroConfidence) {
  const RuleBasedRecognizer recognizer;
  std::mt19937 rng(4);
  const Landmarks good = place(sim::pose_for(PoseName::kOpenPalm, rng));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  std::vector<Landmarks> bad;
  Landmarks same = good;
  for (auto& p : same.points) p = {0.4, 0.4, 0};
  bad.push_back(same);
  Landmarks zeros;
  zeros.score = 1;
  bad.push_back(zeros);
  for (double v : {nan, inf, -inf}) {
    for (std::size_t i : {std::size_t{0}, std::size_t{4}, std::size_t{20}}) {
      Landmarks h = good;
      h.points[i].z = v;
      bad.push_back(h);
      h = good;
      h.points[i].x = v;
      bad.push_back(h);
    }
    Landmarks s = good;
    s.score = v;
    bad.push_back(s);
  }
  Landmarks line = good;  // every point on one line: no palm width
  for (std::size_t i = 0; i < line.points.size(); ++i) line.points[i] = {0.5, 0.1 + 0.03 * i, 0};
  bad.push_back(line);
  Landmarks huge = good;
  for (auto& p : huge.points) p.x *= 1e300;
  bad.push_back(huge);

  for (std::size_t i = 0; i < bad.size(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    const Recognition r = recognizer.recognize(bad[i]);
    EXPECT_EQ(r.gesture, GestureType::kNone);
    EXPECT_EQ(r.confidence, 0);
  }
}

TEST(RuleBasedOptions, DefaultsFromAnEmptyObjectAndOverrides) {
  const RuleBasedOptions d = rule_based_options_from_json(nlohmann::json::object());
  EXPECT_EQ(to_json(d), to_json(RuleBasedOptions{}));
  const RuleBasedOptions o = rule_based_options_from_json(
      {{"direction_tolerance_deg", 30}, {"aspect_ratio", 1.7777}, {"depth_weight", 0}});
  EXPECT_EQ(o.direction_tolerance_deg, 30);
  EXPECT_NEAR(o.aspect_ratio, 1.7777, 1e-12);
  EXPECT_EQ(o.depth_weight, 0);
  EXPECT_EQ(rule_based_options_from_json(to_json(o)).direction_tolerance_deg, 30);
}

void expect_rejected(const nlohmann::json& doc, const std::string& key) {
  try {
    rule_based_options_from_json(doc);
    ADD_FAILURE() << "accepted " << doc.dump();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'" + key + "'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("RuleBasedOptions"), std::string::npos) << e.what();
  }
}

TEST(RuleBasedOptions, RejectsUnknownKeysWrongTypesAndBadValues) {
  expect_rejected({{"direction_tolerence_deg", 30}}, "direction_tolerence_deg");  // typo
  expect_rejected({{"min_presence", "0.2"}}, "min_presence");
  expect_rejected({{"depth_weight", true}}, "depth_weight");
  expect_rejected({{"aspect_ratio", nullptr}}, "aspect_ratio");
  expect_rejected({{"direction_tolerance_deg", 50}}, "direction_tolerance_deg");
  expect_rejected({{"finger_folded_min_curl_deg", 30}}, "finger_folded_min_curl_deg");
  expect_rejected({{"aspect_ratio", -1}}, "aspect_ratio");
  expect_rejected({{"min_presence", 0.9}}, "min_presence");
  EXPECT_THROW(rule_based_options_from_json(nlohmann::json::array()), std::invalid_argument);
  RuleBasedOptions bad;
  bad.angle_transition_deg = 0;
  EXPECT_THROW(RuleBasedRecognizer{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::gesture
