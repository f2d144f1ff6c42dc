// The pure geometry of the hand tracker, on hand-made numbers.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "gbdcs/vision/roi.hpp"

namespace gbdcs::vision {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(TrackerAnchors, PalmDetectorHas2016AnchorsInMediaPipeOrder) {
  const std::vector<Anchor> a = generate_anchors();
  ASSERT_EQ(a.size(), 2016u);  // 24*24*2 + 12*12*6
  for (const Anchor& x : a) {
    ASSERT_EQ(x.width, 1.0);
    ASSERT_EQ(x.height, 1.0);
  }
  // Stride 8: two anchors per cell of the 24x24 map, row by row.
  EXPECT_DOUBLE_EQ(a[0].x_center, 0.5 / 24);
  EXPECT_DOUBLE_EQ(a[0].y_center, 0.5 / 24);
  EXPECT_DOUBLE_EQ(a[1].x_center, 0.5 / 24);
  EXPECT_DOUBLE_EQ(a[2].x_center, 1.5 / 24);
  EXPECT_DOUBLE_EQ(a[48].y_center, 1.5 / 24);
  EXPECT_DOUBLE_EQ(a[1151].x_center, 23.5 / 24);
  EXPECT_DOUBLE_EQ(a[1151].y_center, 23.5 / 24);
  // Stride 16 (three layers share it): six anchors per cell of the 12x12 map.
  EXPECT_DOUBLE_EQ(a[1152].x_center, 0.5 / 12);
  EXPECT_DOUBLE_EQ(a[1157].x_center, 0.5 / 12);
  EXPECT_DOUBLE_EQ(a[1158].x_center, 1.5 / 12);
  EXPECT_DOUBLE_EQ(a[2015].x_center, 11.5 / 12);
  EXPECT_DOUBLE_EQ(a[2015].y_center, 11.5 / 12);
}

TEST(TrackerAnchors, VariableSizeAnchorsFollowTheScales) {
  AnchorOptions o;
  o.fixed_anchor_size = false;
  o.strides = {8, 16};
  const std::vector<Anchor> a = generate_anchors(o);
  ASSERT_EQ(a.size(), 24u * 24 * 2 + 12u * 12 * 2);
  EXPECT_DOUBLE_EQ(a[0].width, 0.1484375);                    // min_scale
  EXPECT_DOUBLE_EQ(a[1].width, std::sqrt(0.1484375 * 0.75));  // interpolated with the next
  EXPECT_DOUBLE_EQ(a[24 * 24 * 2].width, 0.75);               // max_scale
  EXPECT_DOUBLE_EQ(a[24 * 24 * 2 + 1].width, std::sqrt(0.75));
}

// A raw tensor where only box 5 scores: values in model pixels relative to its anchor.
TEST(TrackerDecode, DecodesBoxKeypointsAndSigmoidScore) {
  const std::vector<Anchor> anchors = generate_anchors();
  std::vector<float> boxes(2016 * 18, 0.0f);
  std::vector<float> scores(2016, -10.0f);
  const std::size_t i = 5;  // anchor centre (2.5/24, 0.5/24)
  scores[i] = 2.0f;
  float* v = &boxes[i * 18];
  v[0] = 19.2f;  // x centre +0.1
  v[1] = -9.6f;  // y centre -0.05
  v[2] = 38.4f;  // width 0.2
  v[3] = 19.2f;  // height 0.1
  for (int k = 0; k < 7; ++k) {
    v[4 + 2 * k] = static_cast<float>(k) * 1.92f;   // +0.01 k
    v[5 + 2 * k] = -static_cast<float>(k) * 3.84f;  // -0.02 k
  }
  const std::vector<PalmDetection> d = decode_palm_tensors(boxes, scores, anchors);
  ASSERT_EQ(d.size(), 1u);
  const double ax = 2.5 / 24, ay = 0.5 / 24;
  EXPECT_NEAR(d[0].score, 1.0 / (1.0 + std::exp(-2.0)), 1e-9);
  EXPECT_NEAR(d[0].box.xmin, ax + 0.1 - 0.1, 1e-6);
  EXPECT_NEAR(d[0].box.ymin, ay - 0.05 - 0.05, 1e-6);
  EXPECT_NEAR(d[0].box.width, 0.2, 1e-6);
  EXPECT_NEAR(d[0].box.height, 0.1, 1e-6);
  for (int k = 0; k < 7; ++k) {
    EXPECT_NEAR(d[0].keypoints[k].x, ax + 0.01 * k, 1e-6);
    EXPECT_NEAR(d[0].keypoints[k].y, ay - 0.02 * k, 1e-6);
  }
}

TEST(TrackerDecode, ThresholdClippingAndNegativeSizes) {
  const std::vector<Anchor> anchors = generate_anchors();
  std::vector<float> boxes(2016 * 18, 0.0f);
  std::vector<float> scores(2016, -1.0f);
  scores[0] = 0.0f;     // sigmoid 0.5: kept (>= threshold)
  scores[1] = 1000.0f;  // clipped to 100 before the sigmoid: 1.0, not NaN
  scores[2] = 3.0f;     // kept but for its negative width
  boxes[2 * 18 + 2] = -5.0f;
  const std::vector<PalmDetection> d = decode_palm_tensors(boxes, scores, anchors);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_DOUBLE_EQ(d[0].score, 0.5);
  EXPECT_DOUBLE_EQ(d[1].score, 1.0);
  EXPECT_THROW(decode_palm_tensors(std::span<const float>(boxes).first(100), scores, anchors),
               std::invalid_argument);
}

PalmDetection box_detection(double score, double xmin, double ymin, double w, double h, double kp) {
  PalmDetection d;
  d.score = score;
  d.box = {xmin, ymin, w, h};
  for (auto& p : d.keypoints) p = {kp, kp};
  return d;
}

TEST(TrackerNms, WeightedMergeOfOverlapsKeepsDistinctHands) {
  std::vector<PalmDetection> in = {
      box_detection(0.6, 0.12, 0.10, 0.2, 0.2, 0.3),  // overlaps the best: IoU ~0.8
      box_detection(0.7, 0.60, 0.60, 0.2, 0.2, 0.7),  // another hand
      box_detection(0.9, 0.10, 0.10, 0.2, 0.2, 0.2),  // the best
  };
  const std::vector<PalmDetection> out = weighted_non_max_suppression(in, 0.3);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_DOUBLE_EQ(out[0].score, 0.9);
  EXPECT_NEAR(out[0].box.xmin, (0.9 * 0.10 + 0.6 * 0.12) / 1.5, 1e-12);
  EXPECT_NEAR(out[0].box.width, 0.2, 1e-12);
  EXPECT_NEAR(out[0].keypoints[3].x, (0.9 * 0.2 + 0.6 * 0.3) / 1.5, 1e-12);
  EXPECT_DOUBLE_EQ(out[1].score, 0.7);
  EXPECT_DOUBLE_EQ(out[1].box.xmin, 0.60);
  EXPECT_TRUE(weighted_non_max_suppression({}, 0.3).empty());
}

TEST(TrackerNms, IntersectionOverUnion) {
  EXPECT_DOUBLE_EQ(intersection_over_union({0, 0, 1, 1}, {0, 0, 1, 1}), 1.0);
  EXPECT_DOUBLE_EQ(intersection_over_union({0, 0, 1, 1}, {0.5, 0, 1, 1}), 0.5 / 1.5);
  EXPECT_DOUBLE_EQ(intersection_over_union({0, 0, 1, 1}, {2, 2, 1, 1}), 0.0);
}

TEST(TrackerLetterbox, LandscapeImagePadsTopAndBottomAndRoundTrips) {
  const LetterboxPadding pad = letterbox_padding(640, 480, 192, 192);
  EXPECT_DOUBLE_EQ(pad.left, 0.0);
  EXPECT_DOUBLE_EQ(pad.top, 0.125);
  EXPECT_DOUBLE_EQ(pad.bottom, 0.125);
  const LetterboxPadding portrait = letterbox_padding(480, 640, 192, 192);
  EXPECT_DOUBLE_EQ(portrait.left, 0.125);
  EXPECT_DOUBLE_EQ(portrait.top, 0.0);
  for (const Point2 p : {Point2{0, 0}, Point2{1, 1}, Point2{0.3, 0.8}}) {
    const Point2 q = remove_letterbox(add_letterbox(p, pad), pad);
    EXPECT_NEAR(q.x, p.x, 1e-12);
    EXPECT_NEAR(q.y, p.y, 1e-12);
  }
  // The image's top-left corner is at (0, 0.125) of the model input.
  EXPECT_DOUBLE_EQ(add_letterbox({0, 0}, pad).y, 0.125);
  // The letterbox rect, cropped to 192x192, puts the image corners where the padding says.
  const RotatedRect r = letterbox_rect(640, 480, 192, 192);
  const Affine2D to_crop = invert(crop_to_image_transform(r, 640, 480, 192, 192));
  const Point2 top_left = apply(to_crop, {0, 0});
  const Point2 bottom_right = apply(to_crop, {640, 480});
  EXPECT_NEAR(top_left.x, 0, 1e-9);
  EXPECT_NEAR(top_left.y, 0.125 * 192, 1e-9);
  EXPECT_NEAR(bottom_right.x, 192, 1e-9);
  EXPECT_NEAR(bottom_right.y, 0.875 * 192, 1e-9);

  PalmDetection d = box_detection(0.8, 0.25, 0.25, 0.5, 0.375, 0.5);
  const PalmDetection out = remove_letterbox(d, pad);
  EXPECT_DOUBLE_EQ(out.box.ymin, (0.25 - 0.125) / 0.75);
  EXPECT_DOUBLE_EQ(out.box.height, 0.5);
  EXPECT_DOUBLE_EQ(out.keypoints[0].y, (0.5 - 0.125) / 0.75);
}

TEST(TrackerRoi, NormalizeRadians) {
  EXPECT_NEAR(normalize_radians(3 * kPi / 2), -kPi / 2, 1e-12);
  EXPECT_NEAR(normalize_radians(-3 * kPi / 2), kPi / 2, 1e-12);
  EXPECT_NEAR(normalize_radians(0.3), 0.3, 1e-12);
  EXPECT_NEAR(normalize_radians(kPi), -kPi, 1e-12);
}

PalmDetection palm(Point2 wrist, Point2 middle_mcp) {
  PalmDetection d = box_detection(0.9, 0.45, 0.45, 0.1, 0.1, 0);
  d.keypoints[kPalmWrist] = wrist;
  d.keypoints[kPalmMiddleMcp] = middle_mcp;
  return d;
}

TEST(TrackerRoi, RotationTurnsWristToMiddleFingerUpright) {
  // Fingers up: no rotation. Fingers right: +90° (clockwise on screen). Fingers down: 180°.
  EXPECT_NEAR(detection_to_rect(palm({0.5, 0.6}, {0.5, 0.4}), 640, 480).rotation_rad, 0, 1e-12);
  EXPECT_NEAR(detection_to_rect(palm({0.4, 0.5}, {0.6, 0.5}), 640, 480).rotation_rad, kPi / 2,
              1e-12);
  EXPECT_NEAR(detection_to_rect(palm({0.6, 0.5}, {0.4, 0.5}), 640, 480).rotation_rad, -kPi / 2,
              1e-12);
  EXPECT_NEAR(std::abs(detection_to_rect(palm({0.5, 0.4}, {0.5, 0.6}), 640, 480).rotation_rad), kPi,
              1e-12);
  // 45° in pixels on a 640x480 image: dx = 48 px = 0.075 of the width, dy = 48 px = 0.1.
  EXPECT_NEAR(detection_to_rect(palm({0.5, 0.5}, {0.575, 0.4}), 640, 480).rotation_rad, kPi / 4,
              1e-12);

  // Whatever the rotation, the crop shows the middle finger straight above the wrist.
  for (double deg : {0.0, 30.0, 100.0, -135.0}) {
    const double t = deg * kPi / 180;
    const Point2 wrist{0.5, 0.5};
    const Point2 mcp{0.5 + 0.1 * std::sin(t) * 480 / 640, 0.5 - 0.1 * std::cos(t)};
    const RotatedRect roi = palm_detection_to_roi(palm(wrist, mcp), 640, 480);
    const Affine2D to_crop = invert(crop_to_image_transform(roi, 640, 480, 224, 224));
    const Point2 w = apply(to_crop, {wrist.x * 640, wrist.y * 480});
    const Point2 m = apply(to_crop, {mcp.x * 640, mcp.y * 480});
    EXPECT_NEAR(w.x, m.x, 1e-9) << deg;
    EXPECT_LT(m.y, w.y) << deg;
  }
}

TEST(TrackerRoi, PalmRoiIsEnlargedSquaredAndShiftedTowardTheFingers) {
  // Box 0.1 x 0.1 on 640x480 = 64 x 48 px; fingers up (rotation 0).
  const RotatedRect roi = palm_detection_to_roi(palm({0.5, 0.55}, {0.5, 0.45}), 640, 480);
  EXPECT_NEAR(roi.center_x, 0.5, 1e-12);
  EXPECT_NEAR(roi.center_y, 0.5 - 0.5 * 0.1, 1e-12);  // shift_y -0.5 of the box height
  EXPECT_NEAR(roi.width * 640, 64 * 2.6, 1e-9);       // square on the long side, x2.6
  EXPECT_NEAR(roi.height * 480, 64 * 2.6, 1e-9);
  // Fingers right: the shift follows the hand, to the right.
  const RotatedRect right = palm_detection_to_roi(palm({0.45, 0.5}, {0.55, 0.5}), 640, 480);
  EXPECT_NEAR(right.center_x, 0.5 + 0.5 * 48.0 / 640, 1e-12);
  EXPECT_NEAR(right.center_y, 0.5, 1e-12);
}

using Pts = std::array<contracts::Point3, contracts::kLandmarkCount>;

// An upright hand: wrist at the bottom, fingers up, in pixel units of a 640x480 image.
Pts upright_hand() {
  Pts p{};
  p[contracts::kWrist] = {320, 400, 0};
  const double base_x[5] = {260, 290, 320, 350, 380};  // thumb .. pinky
  for (int f = 0; f < 5; ++f) {
    for (int j = 0; j < 4; ++j) {
      p[1 + 4 * f + j] = {base_x[f], 340.0 - 30.0 * j, 0};
    }
  }
  for (auto& q : p) {
    q.x /= 640;
    q.y /= 480;
  }
  return p;
}

Pts rotate_about(const Pts& in, double cx_px, double cy_px, double angle) {
  Pts out = in;
  for (auto& q : out) {
    const double x = q.x * 640 - cx_px, y = q.y * 480 - cy_px;
    q.x = (cx_px + std::cos(angle) * x - std::sin(angle) * y) / 640;
    q.y = (cy_px + std::sin(angle) * x + std::cos(angle) * y) / 480;
  }
  return out;
}

TEST(TrackerRoi, LandmarksToRectUsesThePalmSubsetAndTheHandsRotation) {
  const Pts hand = upright_hand();
  const RotatedRect r = landmarks_to_rect(hand, 640, 480);
  EXPECT_NEAR(r.rotation_rad, 0, 1e-9);
  // Subset: wrist, thumb CMC/MCP/IP, and the MCP and PIP of the other four fingers:
  // x 260..380, y 280 (thumb IP) .. 400 (wrist).
  EXPECT_NEAR(r.width * 640, 120, 1e-9);
  EXPECT_NEAR(r.height * 480, 120, 1e-9);
  EXPECT_NEAR(r.center_x * 640, 320, 1e-9);
  EXPECT_NEAR(r.center_y * 480, 340, 1e-9);

  const double angle = 30 * kPi / 180;
  const RotatedRect t = landmarks_to_rect(rotate_about(hand, 320, 340, angle), 640, 480);
  EXPECT_NEAR(t.rotation_rad, angle, 1e-9);
  EXPECT_NEAR(t.width * 640, 120, 1e-6);
  EXPECT_NEAR(t.height * 480, 120, 1e-6);
  EXPECT_NEAR(t.center_x * 640, 320, 1e-6);
  EXPECT_NEAR(t.center_y * 480, 340, 1e-6);

  const RotatedRect next = landmarks_to_roi(hand, 640, 480);
  EXPECT_NEAR(next.width * 640, 240, 1e-9);
  EXPECT_NEAR(next.height * 480, 240, 1e-9);
  EXPECT_NEAR(next.center_y * 480, 340 - 12, 1e-9);  // shift_y -0.1 of 120 px, upward
}

// MediaPipe's HandLandmarksToRectCalculator names its joints "PIP", but its indices 4, 6, 8
// count within the 12-landmark subset, where they are the index, middle and ring MCPs: the
// ROI turns with the palm, not with the fingers. Folding the fingers 90 degrees to the side
// (their PIPs far off the wrist -> knuckle axis) must not turn it.
TEST(TrackerRoi, LandmarksToRectTurnsWithTheKnucklesNotTheFoldedFingers) {
  Pts hand = upright_hand();
  for (int f = 1; f < 5; ++f) {  // index .. pinky: PIP, DIP, tip 30 px apart, to the right
    const contracts::Point3 mcp = hand[1 + 4 * f];
    for (int j = 1; j < 4; ++j) {
      hand[1 + 4 * f + j] = {mcp.x + 30.0 * j / 640, mcp.y, 0};
    }
  }
  const RotatedRect r = landmarks_to_rect(hand, 640, 480);
  // Wrist (320, 400) to ((290 + 350) / 2 + 320) / 2 = 320, y 340: straight up.
  EXPECT_NEAR(r.rotation_rad, 0, 1e-9);

  const double angle = -50 * kPi / 180;
  const RotatedRect t = landmarks_to_rect(rotate_about(hand, 320, 370, angle), 640, 480);
  EXPECT_NEAR(t.rotation_rad, angle, 1e-9);
}

TEST(TrackerRoi, RectIouIgnoresRotation) {
  RotatedRect a{0.5, 0.5, 0.2, 0.2, 0};
  RotatedRect b = a;
  b.rotation_rad = 1.0;
  EXPECT_NEAR(rect_iou(a, b), 1.0, 1e-12);
  b.center_x = 0.6;
  EXPECT_NEAR(rect_iou(a, b), 0.1 * 0.2 / (0.08 - 0.02), 1e-12);
}

TEST(TrackerRoi, ACollapsedOrNonFiniteRoiIsNotUsable) {
  EXPECT_TRUE(roi_is_usable({0.5, 0.5, 0.2, 0.2, 0.3}, 640, 480));
  EXPECT_TRUE(roi_is_usable({0.5, 0.5, 8.0 / 640, 8.0 / 480, 0}, 640, 480));
  EXPECT_FALSE(roi_is_usable({0.5, 0.5, 7.0 / 640, 0.2, 0}, 640, 480));
  EXPECT_FALSE(roi_is_usable({0.5, 0.5, 0.2, 0, 0}, 640, 480));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(roi_is_usable({nan, 0.5, 0.2, 0.2, 0}, 640, 480));
  EXPECT_FALSE(roi_is_usable({0.5, 0.5, 0.2, 0.2, nan}, 640, 480));
  // Landmarks all at one point (a model that barely sees a hand) give no usable ROI.
  std::array<contracts::Point3, contracts::kLandmarkCount> one_point{};
  one_point.fill({0.4, 0.6, 0});
  EXPECT_FALSE(roi_is_usable(landmarks_to_roi(one_point, 640, 480), 640, 480));
}

TEST(TrackerCrop, AffineRoundTripAndProjectionAgree) {
  std::mt19937 rng(20240501);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 200; ++n) {
    const int iw = 320 + static_cast<int>(u(rng) * 960);
    const int ih = 240 + static_cast<int>(u(rng) * 720);
    const double side_px = 20 + u(rng) * 400;
    const RotatedRect rect{u(rng), u(rng), side_px / iw, side_px / ih, (u(rng) - 0.5) * 4 * kPi};
    const Affine2D to_image = crop_to_image_transform(rect, iw, ih, 224, 224);
    const Affine2D to_crop = invert(to_image);
    const Point2 p{u(rng) * iw, u(rng) * ih};
    const Point2 back = apply(to_image, apply(to_crop, p));
    ASSERT_LT(std::hypot(back.x - p.x, back.y - p.y), 1e-6);

    // LandmarkProjection (normalised crop → normalised image) is the same map for square rects.
    const contracts::Point3 in_crop{u(rng), u(rng), u(rng) - 0.5};
    const contracts::Point3 projected = project_from_rect(in_crop, rect);
    const Point2 via_affine = apply(to_image, {in_crop.x * 224, in_crop.y * 224});
    ASSERT_NEAR(projected.x * iw, via_affine.x, 1e-6);
    ASSERT_NEAR(projected.y * ih, via_affine.y, 1e-6);
    ASSERT_NEAR(projected.z, in_crop.z * rect.width, 1e-12);
    const contracts::Point3 again = project_to_rect(projected, rect);
    ASSERT_NEAR(again.x, in_crop.x, 1e-9);
    ASSERT_NEAR(again.y, in_crop.y, 1e-9);
    ASSERT_NEAR(again.z, in_crop.z, 1e-9);
  }
  // The crop's corners are the rect's corners; the crop centre is the rect centre.
  const RotatedRect r{0.5, 0.5, 0.25, 0.25 * 640 / 480, kPi / 2};
  const Affine2D m = crop_to_image_transform(r, 640, 480, 224, 224);
  const Point2 centre = apply(m, {112, 112});
  EXPECT_NEAR(centre.x, 320, 1e-9);
  EXPECT_NEAR(centre.y, 240, 1e-9);
  const Point2 top_left = apply(m, {0, 0});  // rotated 90° clockwise: top-left → top-right
  EXPECT_NEAR(top_left.x, 320 + 80, 1e-9);
  EXPECT_NEAR(top_left.y, 240 - 80, 1e-9);
  EXPECT_THROW(invert(Affine2D{0, 0, 0, 0, 0, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::vision
