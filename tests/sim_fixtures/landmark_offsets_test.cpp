#include "gbdcs/sim/landmark_offsets.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "gbdcs/sim/hand_pose.hpp"

namespace gbdcs::sim {
namespace {

using contracts::Landmarks;

constexpr int kWidth = 640;
constexpr int kHeight = 480;

// Hands of three poses, turned all the way round in the image, right and left.
std::vector<Landmarks> hands() {
  std::vector<Landmarks> out;
  std::mt19937 rng(7);
  for (const auto pose : {PoseName::kOpenPalm, PoseName::kFist, PoseName::kPointUp}) {
    for (const auto side : {contracts::Handedness::kRight, contracts::Handedness::kLeft}) {
      for (int roll = -165; roll <= 180; roll += 15) {
        Placement at;
        at.roll_deg = roll;
        at.handedness = side;
        out.push_back(synthesize(pose_for(pose, rng), at));
      }
    }
  }
  return out;
}

// The hand's size in pixels, as eval passes it (the accumulator takes any positive size; the
// offsets are in % of it).
constexpr double kSizePx = 150.0;

// The tracker of this test: every landmark moved by `along` and `across` (% of the hand's
// size) in its bone's axes as the contract defines them.
Landmarks shifted(const Landmarks& truth, double along, double across) {
  using namespace contracts;
  auto px = [&](std::size_t k) {
    return std::array<double, 2>{truth.points[k].x * kWidth, truth.points[k].y * kHeight};
  };
  auto unit = [](double x, double y) {
    const double n = std::hypot(x, y);
    return std::array<double, 2>{x / n, y / n};
  };
  const auto w = px(kWrist), m = px(kMiddleMcp), i = px(kIndexMcp), l = px(kPinkyMcp);
  const auto palm = unit(m[0] - w[0], m[1] - w[1]);
  const double side = (-palm[1] * (i[0] - l[0]) + palm[0] * (i[1] - l[1])) >= 0 ? 1 : -1;
  Landmarks out = truth;
  for (std::size_t k = 0; k < kLandmarkCount; ++k) {
    const bool from_wrist =
        k == kThumbCmc || k == kIndexMcp || k == kMiddleMcp || k == kRingMcp || k == kPinkyMcp;
    const auto a = k == kWrist  ? palm
                   : from_wrist ? unit(px(k)[0] - w[0], px(k)[1] - w[1])
                                : unit(px(k)[0] - px(k - 1)[0], px(k)[1] - px(k - 1)[1]);
    const std::array<double, 2> c{-a[1] * side, a[0] * side};
    out.points[k].x += (along * a[0] + across * c[0]) * kSizePx / 100 / kWidth;
    out.points[k].y += (along * a[1] + across * c[1]) * kSizePx / 100 / kHeight;
  }
  return out;
}

TEST(LandmarkOffsets, AShiftAlongEachBoneIsFoundAtEveryTurnOfEitherHandAndTakenAway) {
  // Measured in image axes, these shifts would cancel out over the turns and the two hands.
  LandmarkOffsets offsets;
  for (const auto& truth : hands())
    offsets.add(truth, shifted(truth, -4.0, 1.5), kWidth, kHeight, kSizePx);
  const auto mean = offsets.mean_offsets();
  ASSERT_TRUE(mean.has_value());
  for (std::size_t k = 0; k < contracts::kLandmarkCount; ++k) {
    EXPECT_NEAR((*mean)[k].along_pct, -4.0, 1e-6) << "landmark " << k;
    EXPECT_NEAR((*mean)[k].across_pct, 1.5, 1e-6) << "landmark " << k;
  }
  EXPECT_NEAR(*offsets.error_pct(), std::hypot(4.0, 1.5), 1e-6);
  EXPECT_NEAR(*offsets.error_pct_without_offsets(), 0.0, 1e-6);
}

TEST(LandmarkOffsets, EachLandmarksErrorIsItsMeanDistance) {
  LandmarkOffsets offsets;
  for (const auto& truth : hands())
    offsets.add(truth, shifted(truth, 3.0, -4.0), kWidth, kHeight, kSizePx);
  const auto by_point = offsets.error_pct_by_point();
  ASSERT_TRUE(by_point.has_value());
  for (std::size_t k = 0; k < contracts::kLandmarkCount; ++k)
    EXPECT_NEAR((*by_point)[k], 5.0, 1e-6) << "landmark " << k;
  EXPECT_FALSE(LandmarkOffsets().error_pct_by_point().has_value());
}

TEST(LandmarkOffsets, ScatterAroundTheTruthStaysInTheError) {
  LandmarkOffsets offsets;
  std::mt19937 rng(11);
  for (const auto& truth : hands()) {
    // Each jitter once and once mirrored: no systematic offset, only scatter.
    Landmarks plus = truth, minus = truth;
    for (std::size_t k = 0; k < contracts::kLandmarkCount; ++k) {
      const double dx = gaussian(rng, 0.004), dy = gaussian(rng, 0.004);
      plus.points[k].x += dx;
      plus.points[k].y += dy;
      minus.points[k].x -= dx;
      minus.points[k].y -= dy;
    }
    offsets.add(truth, plus, kWidth, kHeight, kSizePx);
    offsets.add(truth, minus, kWidth, kHeight, kSizePx);
  }
  const auto mean = offsets.mean_offsets();
  ASSERT_TRUE(mean.has_value());
  for (const auto& m : *mean) {
    EXPECT_NEAR(m.along_pct, 0.0, 1e-9);
    EXPECT_NEAR(m.across_pct, 0.0, 1e-9);
  }
  EXPECT_GT(*offsets.error_pct(), 0.5);
  EXPECT_NEAR(*offsets.error_pct_without_offsets(), *offsets.error_pct(), 1e-9);
}

TEST(LandmarkOffsets, TalliesMergeAsOne) {
  const auto all = hands();
  LandmarkOffsets one, first, second;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Landmarks tracked = shifted(all[i], i % 2 == 0 ? -3.0 : 1.0, 0.5);
    one.add(all[i], tracked, kWidth, kHeight, kSizePx);
    (i < all.size() / 3 ? first : second).add(all[i], tracked, kWidth, kHeight, kSizePx);
  }
  first.add(second);
  EXPECT_EQ(first.hands(), one.hands());
  EXPECT_NEAR(*first.error_pct(), *one.error_pct(), 1e-9);
  EXPECT_NEAR(*first.error_pct_without_offsets(), *one.error_pct_without_offsets(), 1e-9);
  EXPECT_NEAR((*first.mean_offsets())[8].along_pct, -1.0, 1e-6);
}

TEST(LandmarkOffsets, NothingMeasuredIsNoFigure) {
  const LandmarkOffsets none;
  EXPECT_EQ(none.hands(), 0u);
  EXPECT_FALSE(none.mean_offsets().has_value());
  EXPECT_FALSE(none.error_pct().has_value());
  EXPECT_FALSE(none.error_pct_without_offsets().has_value());
}

TEST(LandmarkOffsets, ABadHandIsRejectedAndAddsNothing) {
  const Landmarks truth = hands().front();
  LandmarkOffsets offsets;
  EXPECT_THROW(offsets.add(truth, truth, kWidth, kHeight, 0.0), std::invalid_argument);
  Landmarks broken = truth;
  broken.points[3].x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(offsets.add(truth, broken, kWidth, kHeight, 100.0), std::invalid_argument);
  EXPECT_EQ(offsets.hands(), 0u);
  EXPECT_FALSE(offsets.error_pct().has_value());
}

}  // namespace
}  // namespace gbdcs::sim
