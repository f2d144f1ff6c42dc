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

// A library pose of that gesture aimed exactly up, without the library's aim noise.
sim::HandPose upright(PoseName name, std::mt19937& rng) {
  sim::HandPose pose = sim::pose_for(name, rng);
  pose.orientation.aim_deg = 0;
  return pose;
}

// Halfway between the thumb's "folded" and "extended" limits of lateral position.
double between_the_limits(const RuleBasedOptions& o) {
  return (o.thumb_folded_max_lateral + o.thumb_extended_min_lateral) / 2;
}

// The hand with its thumb (CMC to tip) moved across the palm, its shape unchanged, so that its
// tip lies `lateral` palm sizes toward the index side (HandFeatures::thumb_lateral).
Landmarks with_thumb_at(Landmarks hand, double lateral) {
  namespace lm = contracts;
  const auto lateral_of = [](const Landmarks& h) {
    return extract_features(h, RuleBasedOptions{}.aspect_ratio, 1.0).thumb_lateral;
  };
  const lm::Point3 across{hand.points[lm::kIndexMcp].x - hand.points[lm::kPinkyMcp].x,
                          hand.points[lm::kIndexMcp].y - hand.points[lm::kPinkyMcp].y,
                          hand.points[lm::kIndexMcp].z - hand.points[lm::kPinkyMcp].z};
  auto shifted = [&](double t) {
    Landmarks h = hand;
    for (auto k : {lm::kThumbCmc, lm::kThumbMcp, lm::kThumbIp, lm::kThumbTip}) {
      h.points[k].x += t * across.x;
      h.points[k].y += t * across.y;
      h.points[k].z += t * across.z;
    }
    return h;
  };
  const double now = lateral_of(hand), per_unit = lateral_of(shifted(1)) - now;  // linear in t
  return shifted((lateral - now) / per_unit);
}

// The hand with its thumb straightened: IP and tip carried on along CMC -> MCP, bones kept.
Landmarks with_straight_thumb(Landmarks hand) {
  namespace lm = contracts;
  auto& p = hand.points;
  const auto sub = [](lm::Point3 a, lm::Point3 b) { return lm::Point3{a.x - b.x, a.y - b.y, a.z - b.z}; };
  const auto len = [](lm::Point3 a) { return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z); };
  const lm::Point3 d = sub(p[lm::kThumbMcp], p[lm::kThumbCmc]);
  const double unit = len(d);
  const double to_ip = len(sub(p[lm::kThumbIp], p[lm::kThumbMcp]));
  const double to_tip = to_ip + len(sub(p[lm::kThumbTip], p[lm::kThumbIp]));
  for (auto [k, along] : {std::pair{lm::kThumbIp, to_ip}, std::pair{lm::kThumbTip, to_tip}}) {
    p[k] = {p[lm::kThumbMcp].x + d.x * along / unit, p[lm::kThumbMcp].y + d.y * along / unit,
            p[lm::kThumbMcp].z + d.z * along / unit};
  }
  return hand;
}

// The hand with one finger (0 = index .. 3 = little) turned about its knuckle, in the plane of
// the palm's axis and its knuckle -> tip chord, until its curl (HandFeatures) is `curl_deg`.
Landmarks with_finger_curl(Landmarks hand, int finger, double curl_deg) {
  namespace lm = contracts;
  const double a = RuleBasedOptions{}.aspect_ratio;  // the features' frame: x and z times a
  struct V { double x, y, z; };
  const auto to = [a](lm::Point3 q) { return V{q.x * a, q.y, q.z * a}; };
  const auto sub = [](V p, V q) { return V{p.x - q.x, p.y - q.y, p.z - q.z}; };
  const auto dot = [](V p, V q) { return p.x * q.x + p.y * q.y + p.z * q.z; };
  const auto cross = [](V p, V q) {
    return V{p.y * q.z - p.z * q.y, p.z * q.x - p.x * q.z, p.x * q.y - p.y * q.x};
  };
  const std::size_t mcp = lm::kIndexMcp + 4 * static_cast<std::size_t>(finger);
  auto& p = hand.points;
  const V knuckle = to(p[mcp]);
  V n = cross(sub(knuckle, to(p[lm::kWrist])), sub(to(p[mcp + 3]), knuckle));
  const double n_len = std::sqrt(dot(n, n));
  n = {n.x / n_len, n.y / n_len, n.z / n_len};
  const double now = extract_features(hand, a, 1.0).finger_curl_deg[finger];
  const double t = (curl_deg - now) * std::acos(-1.0) / 180;  // about n: the curl grows
  for (std::size_t k = mcp + 1; k <= mcp + 3; ++k) {
    const V v = sub(to(p[k]), knuckle);
    const V c = cross(n, v);
    const double along = dot(n, v) * (1 - std::cos(t));
    const V r{v.x * std::cos(t) + c.x * std::sin(t) + n.x * along,
              v.y * std::cos(t) + c.y * std::sin(t) + n.y * along,
              v.z * std::cos(t) + c.z * std::sin(t) + n.z * along};
    p[k] = {(knuckle.x + r.x) / a, knuckle.y + r.y, (knuckle.z + r.z) / a};
  }
  return hand;
}

// A finger is folded once its knuckle -> tip chord has turned past a right angle from the
// palm's axis (finger_folded_min_curl_deg 90): the tracker reads real folded fingers at
// 99-168 deg (MediaPipe's own victory sample: ring and little finger at 99 and 100 deg).
// Short of 90 deg it is a half-closed finger, neither folded nor extended.
TEST(RuleBasedRecognizer, AFingerTurnedPastARightAngleIsFolded) {
  const RuleBasedRecognizer recognizer;
  const RuleBasedOptions o;
  ASSERT_EQ(o.finger_folded_min_curl_deg, 90);
  std::mt19937 rng(34);
  for (int i = 0; i < 10; ++i) {
    const Landmarks point = place(upright(PoseName::kPointUp, rng));
    ASSERT_EQ(recognizer.recognize(point).gesture, GestureType::kPointUp);
    const Landmarks at95 = with_finger_curl(point, 1, 95);
    ASSERT_NEAR(extract_features(at95, o.aspect_ratio, 1).finger_curl_deg[1], 95, 1e-6);
    const Recognition r = recognizer.recognize(at95);
    EXPECT_EQ(r.gesture, GestureType::kPointUp);
    EXPECT_NEAR(r.confidence, 0.6, 1e-6);  // 5 deg past the limit: a third of the transition
    EXPECT_EQ(recognizer.recognize(with_finger_curl(point, 1, 85)).gesture, GestureType::kNone);

    const Landmarks victory = place(sim::pose_for(PoseName::kVictory, rng));
    ASSERT_EQ(recognizer.recognize(victory).gesture, GestureType::kVictory);
    const Landmarks loose = with_finger_curl(with_finger_curl(victory, 2, 99), 3, 100);
    EXPECT_EQ(recognizer.recognize(loose).gesture, GestureType::kVictory);
    EXPECT_EQ(recognizer.recognize(with_finger_curl(victory, 3, 80)).gesture, GestureType::kNone);

    const Landmarks fist = place(sim::pose_for(PoseName::kFist, rng));
    ASSERT_EQ(recognizer.recognize(fist).gesture, GestureType::kFist);
    EXPECT_EQ(recognizer.recognize(with_finger_curl(with_finger_curl(fist, 0, 94), 1, 94)).gesture,
              GestureType::kFist);
    Landmarks half_closed = fist;
    for (int f = 0; f < 4; ++f) half_closed = with_finger_curl(half_closed, f, 85);
    EXPECT_EQ(recognizer.recognize(half_closed).gesture, GestureType::kNone);
  }
}

// A thumb tucked beside the index or hidden behind the hand reads neither folded nor out; the
// pointing and victory shapes need it only not out. Clearly out, it is the "L" (not a gesture).
TEST(RuleBasedRecognizer, PointingAndVictoryNeedTheThumbOnlyNotOut) {
  const RuleBasedRecognizer recognizer;
  const RuleBasedOptions o;
  const double between = between_the_limits(o);
  std::mt19937 rng(31);
  for (int i = 0; i < 10; ++i) {
    const Landmarks folded = with_straight_thumb(place(upright(PoseName::kPointUp, rng)));
    const Recognition sure = recognizer.recognize(with_thumb_at(folded, 0));
    ASSERT_EQ(sure.gesture, GestureType::kPointUp);
    const Landmarks tucked = with_thumb_at(folded, between);
    ASSERT_NEAR(extract_features(tucked, o.aspect_ratio, 1).thumb_lateral, between, 1e-6);
    ASSERT_LT(extract_features(tucked, o.aspect_ratio, 1).thumb_bend_deg, 1);
    const Recognition r = recognizer.recognize(tucked);
    EXPECT_EQ(r.gesture, GestureType::kPointUp);
    EXPECT_LT(r.confidence, sure.confidence);  // the thumb's doubt shows
    EXPECT_EQ(recognizer.recognize(with_thumb_at(folded, 1.0)).gesture, GestureType::kNone);

    const Landmarks victory = with_straight_thumb(place(sim::pose_for(PoseName::kVictory, rng)));
    ASSERT_EQ(recognizer.recognize(with_thumb_at(victory, 0)).gesture, GestureType::kVictory);
    EXPECT_EQ(recognizer.recognize(with_thumb_at(victory, between)).gesture, GestureType::kVictory);
    EXPECT_EQ(recognizer.recognize(with_thumb_at(victory, 1.0)).gesture, GestureType::kNone);
  }
}

// "Not out" is judged against the extended limit: the further in the thumb lies, the surer
// the pointing and the victory, across the folded limit too (a thumb just inside it must not
// read less sure than one just outside).
TEST(RuleBasedRecognizer, AThumbFurtherInNeverLowersPointingConfidence) {
  const RuleBasedRecognizer recognizer;
  const RuleBasedOptions o;
  std::mt19937 rng(47);
  for (int i = 0; i < 5; ++i) {
    const Landmarks point = with_straight_thumb(place(upright(PoseName::kPointUp, rng)));
    const Landmarks victory = with_straight_thumb(place(sim::pose_for(PoseName::kVictory, rng)));
    for (const auto& [hand, gesture] :
         {std::pair{point, GestureType::kPointUp}, std::pair{victory, GestureType::kVictory}}) {
      double before = 0;
      for (double lateral = o.thumb_extended_min_lateral - 0.01; lateral > -0.3; lateral -= 0.02) {
        const Recognition r = recognizer.recognize(with_thumb_at(hand, lateral));
        ASSERT_EQ(r.gesture, gesture) << "thumb at " << lateral;
        EXPECT_GE(r.confidence, before - 1e-9) << "thumb at " << lateral;
        before = r.confidence;
      }
      // Just inside the folded limit: as sure as halfway between the limits, or surer.
      const double inside =
          recognizer.recognize(with_thumb_at(hand, o.thumb_folded_max_lateral - 0.01)).confidence;
      const double between =
          recognizer.recognize(with_thumb_at(hand, between_the_limits(o))).confidence;
      EXPECT_GE(inside, between);
    }
  }
}

// Seen end-on, a raised thumb's tip is placed over the folded fingers by the tracker: a
// straight thumb aimed up or down over four folded fingers is the thumb gesture, unless its
// tip lies past the palm's middle (a thumb across a fist) or it points sideways.
TEST(RuleBasedRecognizer, AStraightThumbAimedUpOverFoldedFingersIsAThumbGesture) {
  const RuleBasedRecognizer recognizer;
  const RuleBasedOptions o;
  std::mt19937 rng(32);
  for (int i = 0; i < 10; ++i) {
    const sim::HandPose thumb = upright(PoseName::kThumbUp, rng);
    const Landmarks out = place(thumb);
    ASSERT_EQ(recognizer.recognize(out).gesture, GestureType::kThumbUp);
    ASSERT_LT(extract_features(out, o.aspect_ratio, 1).thumb_bend_deg, o.thumb_aimed_max_bend_deg);
    const double over = o.thumb_folded_max_lateral / 2;  // read "folded" by its tip
    EXPECT_EQ(recognizer.recognize(with_thumb_at(out, over)).gesture, GestureType::kThumbUp);
    EXPECT_EQ(recognizer.recognize(place(thumb, 180)).gesture, GestureType::kThumbDown);
    EXPECT_EQ(recognizer.recognize(with_thumb_at(place(thumb, 180), over)).gesture,
              GestureType::kThumbDown);
    // Across the palm, or lying sideways: a fist.
    EXPECT_EQ(recognizer.recognize(with_thumb_at(out, -0.2)).gesture, GestureType::kFist);
    EXPECT_EQ(recognizer.recognize(with_thumb_at(place(thumb, 90), over)).gesture,
              GestureType::kFist);
    RuleBasedOptions off;
    off.thumb_aimed_max_bend_deg = 0;
    EXPECT_EQ(RuleBasedRecognizer(off).recognize(with_thumb_at(out, over)).gesture,
              GestureType::kFist);
  }
  // The library's fists (thumb bent across the fingers) stay fists at every roll.
  for (int i = 0; i < 20; ++i) {
    const sim::HandPose fist = sim::pose_for(PoseName::kFist, rng);
    for (double roll : {0.0, 90.0, 180.0, -90.0}) {
      EXPECT_EQ(recognizer.recognize(place(fist, roll)).gesture, GestureType::kFist) << roll;
    }
  }
}

// A fist's thumb is bent: lying beside the index (tip between the limits) it still makes a
// fist. Straight there and not aimed, or read out, it stays unclear (FIST is LAND).
TEST(RuleBasedRecognizer, AFistWithItsBentThumbBesideTheIndexIsAFist) {
  const RuleBasedRecognizer recognizer;
  const RuleBasedOptions o;
  const double between = between_the_limits(o);
  std::mt19937 rng(33);
  int bent_cases = 0;
  for (int i = 0; i < 40; ++i) {
    const Landmarks fist = place(sim::pose_for(PoseName::kFist, rng));
    ASSERT_EQ(recognizer.recognize(fist).gesture, GestureType::kFist);
    if (extract_features(fist, o.aspect_ratio, 1).thumb_bend_deg < o.thumb_extended_max_bend_deg + 5)
      continue;
    ++bent_cases;
    const Recognition beside = recognizer.recognize(with_thumb_at(fist, between));
    EXPECT_EQ(beside.gesture, GestureType::kFist);
    EXPECT_GT(beside.confidence, 0);
    EXPECT_EQ(recognizer.recognize(with_thumb_at(fist, 1.0)).gesture, GestureType::kNone);
    // Straightened and turned sideways (not aimed up or down): unclear.
    const Landmarks sideways = with_thumb_at(with_straight_thumb(place(sim::pose_for(PoseName::kFist, rng), 90)), between);
    EXPECT_EQ(recognizer.recognize(sideways).gesture, GestureType::kNone);
  }
  EXPECT_GE(bent_cases, 10);
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
  expect_rejected({{"thumb_aimed_max_bend_deg", 60}}, "thumb_aimed_max_bend_deg");
  expect_rejected({{"thumb_aimed_min_lateral", 0.5}}, "thumb_aimed_min_lateral");
  EXPECT_THROW(rule_based_options_from_json(nlohmann::json::array()), std::invalid_argument);
  RuleBasedOptions bad;
  bad.angle_transition_deg = 0;
  EXPECT_THROW(RuleBasedRecognizer{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::gesture
