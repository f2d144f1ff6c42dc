// The landmark synthesizer and its pose library (sim/landmarks).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <string>

#include "gbdcs/sim/hand_pose.hpp"

namespace gbdcs::sim {
namespace {

namespace lm = contracts;

double image_direction_deg(const lm::Landmarks& h, std::size_t from, std::size_t to,
                           double aspect) {
  const double dx = (h.points[to].x - h.points[from].x) * aspect;
  const double dy = h.points[to].y - h.points[from].y;
  return std::atan2(dx, -dy) * 180 / std::numbers::pi;  // 0 = up, 90 = right
}

double off_by_deg(double a, double b) { return std::abs(std::remainder(a - b, 360.0)); }

TEST(PoseLibrary, NamesRoundTripAndGesturesMapOnlyForTheVocabulary) {
  std::set<std::string_view> names;
  int deliberate = 0;
  for (PoseName p : kAllPoses) {
    names.insert(to_string(p));
    EXPECT_EQ(pose_from_string(to_string(p)), p);
    if (gesture_of(p)) {
      ++deliberate;
      EXPECT_EQ(lm::to_string(*gesture_of(p)), to_string(p));  // same spelling as contracts
    }
  }
  EXPECT_EQ(names.size(), kAllPoses.size());
  EXPECT_EQ(deliberate, 9);
  EXPECT_EQ(pose_from_string("FOUR_FINGERS"), PoseName::kFourFingers);
  EXPECT_EQ(pose_from_string("CALL"), PoseName::kCall);
  EXPECT_FALSE(pose_from_string("open_palm"));
  EXPECT_FALSE(gesture_of(PoseName::kRock));
}

TEST(PoseLibrary, SameSeedSameHandsOtherSeedOtherHands) {
  auto draw = [](std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<double> xs;
    for (PoseName p : kAllPoses) {
      for (const auto& q : synthesize(pose_for(p, rng), {}).points) xs.push_back(q.x);
    }
    return xs;
  };
  EXPECT_EQ(draw(17), draw(17));
  EXPECT_NE(draw(17), draw(18));
  std::mt19937 rng(1);
  EXPECT_DOUBLE_EQ(uniform(rng, 0, 1), [] {
    std::mt19937 again(1);
    return uniform(again, 0, 1);
  }());
}

TEST(HandModel, AdultProportions) {
  HandPose flat;
  flat.fingers = {};
  const auto p = hand_points_mm(flat);
  auto dist = [&p](std::size_t a, std::size_t b) {
    return std::hypot(p[a].x - p[b].x, p[a].y - p[b].y, p[a].z - p[b].z);
  };
  EXPECT_NEAR(dist(lm::kWrist, lm::kMiddleTip), kHandLengthMm, 3);
  EXPECT_NEAR(dist(lm::kIndexMcp, lm::kPinkyMcp), 58, 6);  // knuckle breadth
  EXPECT_GT(dist(lm::kMiddleMcp, lm::kMiddleTip), dist(lm::kPinkyMcp, lm::kPinkyTip));
  // A fist brings the fingertips back near the palm.
  HandPose fist;
  for (auto& f : fist.fingers) f = {85, 100, 60};
  const auto q = hand_points_mm(fist);
  EXPECT_LT(std::hypot(q[lm::kMiddleTip].x, q[lm::kMiddleTip].y, q[lm::kMiddleTip].z),
            dist(lm::kWrist, lm::kMiddleMcp));
}

TEST(PoseLibrary, OkSignAndPinchCloseTheRing) {
  std::mt19937 rng(31);
  for (PoseName name : {PoseName::kOkSign, PoseName::kPinch}) {
    for (int i = 0; i < 50; ++i) {
      const auto p = hand_points_mm(pose_for(name, rng));
      const double gap_mm = std::hypot(p[lm::kThumbTip].x - p[lm::kIndexTip].x,
                                       p[lm::kThumbTip].y - p[lm::kIndexTip].y,
                                       p[lm::kThumbTip].z - p[lm::kIndexTip].z);
      EXPECT_LT(gap_mm, 8) << to_string(name) << " sample " << i;
    }
  }
}

TEST(Synthesize, PlacementScaleCentreAndDepth) {
  HandPose flat;
  flat.orientation = {};
  Placement place;
  place.size = 0.5;
  place.center_x = 0.4;
  place.center_y = 0.6;
  const lm::Landmarks h = synthesize(flat, place);
  EXPECT_EQ(h.points[lm::kWrist].z, 0);
  EXPECT_EQ(h.score, place.presence);
  // Upright open hand: wrist below, middle fingertip above, hand length = size of the frame.
  EXPECT_NEAR(h.points[lm::kWrist].y - h.points[lm::kMiddleTip].y, 0.5, 0.02);
  EXPECT_NEAR((h.points[lm::kWrist].y + h.points[lm::kMiddleMcp].y) / 2, 0.6, 1e-9);
  // Right hand, palm to the camera, in a mirrored (selfie) image: the thumb is on the right.
  EXPECT_GT(h.points[lm::kThumbTip].x, h.points[lm::kPinkyTip].x);
  place.handedness = lm::Handedness::kLeft;
  const lm::Landmarks left = synthesize(flat, place);
  EXPECT_EQ(left.handedness, lm::Handedness::kLeft);
  for (std::size_t i = 0; i < lm::kLandmarkCount; ++i) {
    EXPECT_NEAR(left.points[i].x - 0.4, -(h.points[i].x - 0.4), 1e-12);
    EXPECT_NEAR(left.points[i].y, h.points[i].y, 1e-12);
  }
}

TEST(Synthesize, RejectsPlacementsOutOfRange) {
  const HandPose pose;
  Placement p;
  p.yaw_deg = 41;
  EXPECT_THROW(synthesize(pose, p), std::invalid_argument);
  p = {};
  p.size = 0;
  EXPECT_THROW(synthesize(pose, p), std::invalid_argument);
  p = {};
  p.center_x = std::nan("");
  EXPECT_THROW(synthesize(pose, p), std::invalid_argument);
  p = {};
  p.presence = 1.5;
  EXPECT_THROW(synthesize(pose, p), std::invalid_argument);
}

// The library aims direction poses in the image, for both hands and any yaw / pitch of the
// placement: the aimed digit's image direction is off by no more than the pose's own aim
// noise (5 deg sigma, clipped) plus what the out-of-plane turns do to a slanted digit.
TEST(PoseLibrary, DirectionPosesPointWhereTheyAreNamed) {
  struct Case {
    PoseName pose;
    std::size_t from, to;
    double direction_deg;
  };
  const Case cases[] = {{PoseName::kPointLeft, lm::kIndexMcp, lm::kIndexTip, -90},
                        {PoseName::kPointRight, lm::kIndexMcp, lm::kIndexTip, 90},
                        {PoseName::kPointUp, lm::kIndexMcp, lm::kIndexTip, 0},
                        {PoseName::kThumbUp, lm::kThumbMcp, lm::kThumbTip, 0},
                        {PoseName::kThumbDown, lm::kThumbMcp, lm::kThumbTip, 180}};
  std::mt19937 rng(77);
  for (const Case& c : cases) {
    for (int i = 0; i < 100; ++i) {
      Placement p;
      p.handedness = i % 2 ? lm::Handedness::kLeft : lm::Handedness::kRight;
      p.yaw_deg = uniform(rng, -30, 30);
      p.pitch_deg = uniform(rng, -15, 15);
      const lm::Landmarks h = synthesize(pose_for(c.pose, rng), p);
      EXPECT_LT(off_by_deg(image_direction_deg(h, c.from, c.to, p.aspect_ratio), c.direction_deg),
                22)
          << to_string(c.pose) << " sample " << i;
    }
  }
}

TEST(Blend, InterpolatesJointsAndTakesTheShortWayRound) {
  std::mt19937 rng(8);
  HandPose a = pose_for(PoseName::kFist, rng);
  HandPose b = pose_for(PoseName::kOpenPalm, rng);
  a.orientation.aim_deg = 170;
  b.orientation.aim_deg = -170;
  const HandPose mid = blend(a, b, 0.5);
  EXPECT_NEAR(mid.fingers[1].pip_deg, (a.fingers[1].pip_deg + b.fingers[1].pip_deg) / 2, 1e-9);
  EXPECT_NEAR(mid.thumb.cmc_flexion_deg, (a.thumb.cmc_flexion_deg + b.thumb.cmc_flexion_deg) / 2,
              1e-9);
  EXPECT_NEAR(std::abs(std::remainder(mid.orientation.aim_deg, 360.0)), 180, 1e-9);
  EXPECT_EQ(blend(a, b, -1).fingers[2].mcp_deg, a.fingers[2].mcp_deg);
  EXPECT_DOUBLE_EQ(blend(a, b, 2).fingers[2].mcp_deg, b.fingers[2].mcp_deg);
}

}  // namespace
}  // namespace gbdcs::sim
