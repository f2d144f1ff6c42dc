// The hand tracker end to end, with the real MediaPipe models (ci/fetch-models puts them in
// default_model_dir(); a missing model fails with ModelError saying so). Every image is made
// here: a blank frame, and an open hand drawn with OpenCV (shaded limbs on a plain
// background) that the real palm detector and landmark model recognise as a hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/vision/hand_landmarker.hpp"
#include "gbdcs/vision/hand_tracker.hpp"
#include "gbdcs/vision/model_files.hpp"
#include "gbdcs/vision/palm_detector.hpp"

namespace gbdcs::vision {
namespace {

using contracts::Point3;

// ---- the synthetic hand ---------------------------------------------------------------
struct DrawnHand {
  cv::Mat rgb;
  cv::Mat mask;                   // 255 where the hand (and forearm) was drawn
  std::vector<cv::Point2d> tips;  // thumb, index, middle, ring, pinky tip centres, pixels
  cv::Point2d wrist;              // middle of the palm's bottom edge, pixels
};

cv::Scalar scaled(const cv::Scalar& c, double f) {
  return {c[0] * f, c[1] * f, c[2] * f};
}

// A limb as concentric strokes, dark at the rim and light at the axis: a lit cylinder.
void draw_limb(DrawnHand& h, cv::Point2d a, cv::Point2d b, double width, const cv::Scalar& skin) {
  for (int k = 0; k <= 6; ++k) {
    const double t = k / 6.0;
    const int w = std::max(2, static_cast<int>(width * (1.0 - 0.75 * t)));
    cv::line(h.rgb, a, b, scaled(skin, 0.72 + 0.33 * t), w, cv::LINE_AA);
  }
  cv::line(h.mask, a, b, cv::Scalar(255), static_cast<int>(width), cv::LINE_8);
}

// An open hand, fingers up, thumb to the image's left; `scale` 1 is
// about 300 px from wrist to middle fingertip; `centre` is the palm's centre.
void draw_hand(DrawnHand& h, double scale, cv::Point2d centre) {
  const cv::Scalar skin(235, 180, 150);
  auto at = [&](double x, double y) {
    return cv::Point2d(centre.x + scale * (x - 320), centre.y + scale * (y - 330));
  };
  auto poly = [&](std::initializer_list<cv::Point2d> pts) {
    std::vector<cv::Point> out;
    for (const auto& p : pts) out.emplace_back(cvRound(p.x), cvRound(p.y));
    return out;
  };
  draw_limb(h, at(320, 560), at(320, 410), 95 * scale, skin);  // forearm
  const auto palm =
      poly({at(272, 405), at(258, 300), at(268, 255), at(384, 255), at(392, 300), at(368, 405)});
  cv::fillConvexPoly(h.rgb, palm, scaled(skin, 0.8), cv::LINE_AA);
  cv::fillConvexPoly(h.mask, palm, cv::Scalar(255));
  cv::fillConvexPoly(
      h.rgb,
      poly({at(282, 395), at(270, 300), at(280, 265), at(372, 265), at(380, 300), at(358, 395)}),
      scaled(skin, 0.95), cv::LINE_AA);
  h.wrist = at(320, 405);

  // Thumb: three segments out to the left.
  draw_limb(h, at(280, 380), at(238, 330), 34 * scale, skin);
  draw_limb(h, at(238, 330), at(212, 290), 29 * scale, skin);
  draw_limb(h, at(212, 290), at(198, 258), 25 * scale, skin);
  h.tips.push_back(at(198, 258));
  // Index .. pinky: three phalanges each, slightly spread.
  struct Finger {
    double x, y, angle_deg, length, width;
  };
  for (const Finger& f : {Finger{286, 262, -10, 115, 26}, Finger{316, 255, -1, 135, 28},
                          Finger{346, 258, 7, 125, 27}, Finger{374, 272, 17, 95, 23}}) {
    const double a = f.angle_deg * std::numbers::pi / 180;
    double x = f.x, y = f.y;
    const double share[3] = {0.45, 0.32, 0.23};
    for (int s = 0; s < 3; ++s) {
      const double nx = x + std::sin(a) * f.length * share[s];
      const double ny = y - std::cos(a) * f.length * share[s];
      draw_limb(h, at(x, y), at(nx, ny), f.width * (1 - 0.08 * s) * scale, skin);
      x = nx;
      y = ny;
    }
    h.tips.push_back(at(x, y));
  }
}

cv::Mat background(cv::Size size) {
  return cv::Mat(size, CV_8UC3, cv::Scalar(60, 90, 120));
}

// Blurred and with seeded sensor noise, like a camera frame.
void finish(cv::Mat& rgb) {
  cv::GaussianBlur(rgb, rgb, cv::Size(5, 5), 0);
  cv::Mat noise(rgb.size(), CV_8UC3);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar::all(6));
  rgb += noise;
}

DrawnHand synthetic_hand(double scale = 1.0, cv::Point2d centre = {320, 300}) {
  DrawnHand h;
  h.rgb = background({640, 480});
  h.mask = cv::Mat::zeros(480, 640, CV_8UC1);
  draw_hand(h, scale, centre);
  finish(h.rgb);
  return h;
}

cv::Mat blank_frame() {
  cv::Mat rgb = background({640, 480});
  finish(rgb);
  return rgb;
}

// Pixel distance from p to the nearest drawn hand pixel (0 inside).
double distance_to_mask(const cv::Mat& mask, cv::Point2d p) {
  cv::Mat outside;
  cv::bitwise_not(mask, outside);
  cv::Mat dist;
  cv::distanceTransform(outside, dist, cv::DIST_L2, 3);
  const int x = std::clamp(cvRound(p.x), 0, mask.cols - 1);
  const int y = std::clamp(cvRound(p.y), 0, mask.rows - 1);
  return dist.at<float>(y, x);
}

cv::Point2d pixel(const Point3& p, const cv::Mat& img) {
  return {p.x * img.cols, p.y * img.rows};
}

// ---- clocks ---------------------------------------------------------------------------
// Moves 1 ms every time it is read, so each measured span is exactly 1 ms.
class TickingClock final : public contracts::Clock {
 public:
  contracts::Duration now() const override { return std::chrono::milliseconds(++ticks_); }
  contracts::UtcTime utc_now() const override { return contracts::UtcTime{}; }

 private:
  mutable long ticks_ = 0;
};

TrackerOptions video_options() {
  TrackerOptions o;
  o.max_hands = 2;
  return o;
}

// ---- tests ----------------------------------------------------------------------------
TEST(TrackerModels, BlankImageHasNoHand) {
  const cv::Mat blank = blank_frame();
  PalmDetector detector(verified_model_path(ModelKind::kPalmDetectionFull));
  EXPECT_TRUE(detector.detect(blank).empty());

  contracts::ManualClock clock;
  HandTracker tracker(video_options(), clock);
  for (int frame = 0; frame < 2; ++frame) {
    EXPECT_TRUE(tracker.process(blank).empty());
    EXPECT_TRUE(tracker.last_timings().ran_detection);  // nothing tracked: detect every frame
  }
}

TEST(TrackerModels, DrawnHandIsFoundAndLandmarksLandOnIt) {
  for (const bool full : {true, false}) {
    SCOPED_TRACE(full ? "full models" : "lite models");
    const DrawnHand hand = synthetic_hand();
    contracts::ManualClock clock;
    TrackerOptions o = video_options();
    o.full_model = full;
    HandTracker tracker(o, clock);
    const std::vector<HandObservation> found = tracker.process(hand.rgb);
    ASSERT_EQ(found.size(), 1u);
    const HandObservation& h = found[0];
    EXPECT_TRUE(h.from_detection);
    EXPECT_GE(h.landmarks.score, 0.8);

    for (std::size_t i = 0; i < contracts::kLandmarkCount; ++i) {
      EXPECT_LE(distance_to_mask(hand.mask, pixel(h.landmarks.points[i], hand.rgb)), 3.0)
          << "landmark " << i << " is off the drawn hand";
    }
    // Each fingertip landmark is near the tip that was drawn (fingers are ~26 px wide).
    const std::size_t tip_index[5] = {contracts::kThumbTip, contracts::kIndexTip,
                                      contracts::kMiddleTip, contracts::kRingTip,
                                      contracts::kPinkyTip};
    for (int f = 0; f < 5; ++f) {
      const cv::Point2d p = pixel(h.landmarks.points[tip_index[f]], hand.rgb);
      EXPECT_LE(cv::norm(p - hand.tips[f]), 15.0) << "finger " << f;
    }
    // The wrist is at the bottom of the palm, below every finger's MCP.
    const cv::Point2d wrist = pixel(h.landmarks.points[contracts::kWrist], hand.rgb);
    EXPECT_LE(cv::norm(wrist - hand.wrist), 40.0);
    for (std::size_t mcp :
         {contracts::kIndexMcp, contracts::kMiddleMcp, contracts::kRingMcp, contracts::kPinkyMcp}) {
      EXPECT_LT(h.landmarks.points[mcp].y, h.landmarks.points[contracts::kWrist].y);
    }
    // The ROI was turned so the fingers point up in the crop: near zero rotation here.
    EXPECT_LT(std::abs(h.roi.rotation_rad), 0.35);
  }
}

TEST(TrackerModels, SecondFrameTracksFromLandmarksWithoutDetection) {
  const DrawnHand hand = synthetic_hand();
  TickingClock clock;
  HandTracker tracker(video_options(), clock);

  const auto first = tracker.process(hand.rgb);
  ASSERT_EQ(first.size(), 1u);
  TrackerTimings t = tracker.last_timings();
  EXPECT_TRUE(t.ran_detection);
  EXPECT_DOUBLE_EQ(t.detection_ms, 1.0);  // measured on the injected clock, one tick
  EXPECT_DOUBLE_EQ(t.landmarks_ms, 1.0);

  for (int frame = 0; frame < 3; ++frame) {
    const auto next = tracker.process(hand.rgb);
    ASSERT_EQ(next.size(), 1u);
    t = tracker.last_timings();
    EXPECT_FALSE(t.ran_detection);
    EXPECT_DOUBLE_EQ(t.detection_ms, 0.0);
    EXPECT_DOUBLE_EQ(t.landmarks_ms, 1.0);
    EXPECT_FALSE(next[0].from_detection);
    EXPECT_GE(next[0].landmarks.score, 0.8);
    EXPECT_EQ(next[0].landmarks.handedness, first[0].landmarks.handedness);
    for (std::size_t i = 0; i < contracts::kLandmarkCount; ++i) {
      const cv::Point2d a = pixel(first[0].landmarks.points[i], hand.rgb);
      const cv::Point2d b = pixel(next[0].landmarks.points[i], hand.rgb);
      EXPECT_LE(cv::norm(a - b), 8.0) << "landmark " << i;
    }
  }

  tracker.reset();
  ASSERT_EQ(tracker.process(hand.rgb).size(), 1u);
  EXPECT_TRUE(tracker.last_timings().ran_detection);
}

TEST(TrackerModels, LosingTheHandTriggersDetectionInTheSameFrame) {
  const DrawnHand hand = synthetic_hand();
  contracts::ManualClock clock;
  TrackerOptions o = video_options();
  o.coast_frames = 0;  // MediaPipe's behaviour: a lost hand is given up at once
  HandTracker tracker(o, clock);
  ASSERT_EQ(tracker.process(hand.rgb).size(), 1u);
  EXPECT_TRUE(tracker.process(blank_frame()).empty());  // tracked ROI shows no hand
  EXPECT_TRUE(tracker.last_timings().ran_detection);
  // The hand comes back: found again by detection.
  const auto back = tracker.process(hand.rgb);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_TRUE(back[0].from_detection);
}

// A lost hand is still looked for where it was for coast_frames frames, never reported while
// its presence is low; back within them it is tracked again without the detector, later it
// has been given up and only detection finds it.
TEST(TrackerModels, ALostHandIsLookedForWhereItWasForCoastFrames) {
  const DrawnHand hand = synthetic_hand();
  TickingClock clock;
  TrackerOptions o = video_options();
  o.coast_frames = 2;
  HandTracker tracker(o, clock);
  ASSERT_EQ(tracker.process(hand.rgb).size(), 1u);
  for (int gone = 1; gone <= o.coast_frames; ++gone) {
    EXPECT_TRUE(tracker.process(blank_frame()).empty()) << gone;
    const TrackerTimings t = tracker.last_timings();
    EXPECT_TRUE(t.ran_detection) << gone;       // nothing reported: detection runs as well
    EXPECT_DOUBLE_EQ(t.landmarks_ms, 1.0) << gone;  // and one landmark run where it was
  }
  auto back = tracker.process(hand.rgb);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_FALSE(back[0].from_detection);  // found where it was lost
  EXPECT_GE(back[0].landmarks.score, 0.8);

  // Gone for one frame more than coast_frames: given up, found again by detection only.
  for (int gone = 1; gone <= o.coast_frames + 1; ++gone) {
    EXPECT_TRUE(tracker.process(blank_frame()).empty());
  }
  EXPECT_DOUBLE_EQ(tracker.last_timings().landmarks_ms, 1.0);  // the last look
  EXPECT_TRUE(tracker.process(blank_frame()).empty());
  EXPECT_DOUBLE_EQ(tracker.last_timings().landmarks_ms, 0.0);  // nothing left to look for
  back = tracker.process(hand.rgb);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_TRUE(back[0].from_detection);

  // reset() forgets lost hands too.
  ASSERT_TRUE(tracker.process(blank_frame()).empty());
  tracker.reset();
  EXPECT_TRUE(tracker.process(blank_frame()).empty());
  EXPECT_DOUBLE_EQ(tracker.last_timings().landmarks_ms, 0.0);

  o.coast_frames = 31;
  EXPECT_THROW((void)HandTracker(o, clock), std::invalid_argument);
  o.coast_frames = -1;
  EXPECT_THROW((void)HandTracker(o, clock), std::invalid_argument);
}

TEST(TrackerModels, StaticImagesDetectEveryFrame) {
  const DrawnHand hand = synthetic_hand();
  contracts::ManualClock clock;
  TrackerOptions o = video_options();
  o.static_images = true;
  HandTracker tracker(o, clock);
  for (int frame = 0; frame < 2; ++frame) {
    const auto found = tracker.process(hand.rgb);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_TRUE(found[0].from_detection);
    EXPECT_TRUE(tracker.last_timings().ran_detection);
  }
}

TEST(TrackerModels, TwoHandsUpToMaxHands) {
  DrawnHand two;
  two.rgb = background({640, 480});
  two.mask = cv::Mat::zeros(480, 640, CV_8UC1);
  draw_hand(two, 0.55, {170, 280});
  draw_hand(two, 0.55, {470, 280});
  finish(two.rgb);

  contracts::ManualClock clock;
  HandTracker both(video_options(), clock);
  auto found = both.process(two.rgb);
  ASSERT_EQ(found.size(), 2u);
  std::sort(found.begin(), found.end(), [](const HandObservation& a, const HandObservation& b) {
    return a.landmarks.points[0].x < b.landmarks.points[0].x;
  });
  EXPECT_NEAR(found[0].landmarks.points[contracts::kMiddleMcp].x, 170.0 / 640, 0.05);
  EXPECT_NEAR(found[1].landmarks.points[contracts::kMiddleMcp].x, 470.0 / 640, 0.05);
  // Both tracked on the next frame, without detection.
  EXPECT_EQ(both.process(two.rgb).size(), 2u);
  EXPECT_FALSE(both.last_timings().ran_detection);

  TrackerOptions one_only = video_options();
  one_only.max_hands = 1;
  HandTracker one(one_only, clock);
  EXPECT_EQ(one.process(two.rgb).size(), 1u);
}

TEST(TrackerModels, MirroredImageSwapsHandedness) {
  const DrawnHand hand = synthetic_hand();
  cv::Mat mirrored;
  cv::flip(hand.rgb, mirrored, 1);
  PalmDetector detector(verified_model_path(ModelKind::kPalmDetectionFull));
  HandLandmarker landmarker(verified_model_path(ModelKind::kHandLandmarkFull));
  auto label = [&](const cv::Mat& rgb) {
    const auto palms = detector.detect(rgb);
    EXPECT_EQ(palms.size(), 1u);
    const LandmarkResult r =
        landmarker.run(rgb, palm_detection_to_roi(palms.at(0), rgb.cols, rgb.rows));
    EXPECT_GE(r.handedness_score, 0.5);
    return r.landmarks.handedness;
  };
  // The drawing does not say whether it shows a palm or a back, so which label it gets is
  // the model's call; a mirror image of the same hand must get the other one.
  EXPECT_NE(label(mirrored), label(hand.rgb));
}

// Turning the image and the ROI by 90° gives the model the same pixels, so the landmarks must
// turn with them: a check of the crop, the projection and the rotation conventions together.
TEST(TrackerModels, LandmarksTurnWithTheImage) {
  const DrawnHand hand = synthetic_hand(0.8);
  const cv::Mat& img = hand.rgb;
  PalmDetector detector(verified_model_path(ModelKind::kPalmDetectionFull));
  HandLandmarker landmarker(verified_model_path(ModelKind::kHandLandmarkFull));
  const auto palms = detector.detect(img);
  ASSERT_EQ(palms.size(), 1u);
  const RotatedRect roi = palm_detection_to_roi(palms[0], img.cols, img.rows);
  const LandmarkResult upright = landmarker.run(img, roi);

  cv::Mat turned;  // 90° clockwise: (x, y) → (H - y, x) in continuous pixels
  cv::rotate(img, turned, cv::ROTATE_90_CLOCKWISE);
  const double w = img.cols, h = img.rows;
  RotatedRect turned_roi;
  turned_roi.center_x = 1.0 - roi.center_y;
  turned_roi.center_y = roi.center_x;
  turned_roi.width = roi.width * w / h;
  turned_roi.height = roi.height * h / w;
  turned_roi.rotation_rad = roi.rotation_rad + std::numbers::pi / 2;
  const LandmarkResult sideways = landmarker.run(turned, turned_roi);

  EXPECT_NEAR(sideways.landmarks.score, upright.landmarks.score, 1e-3);
  for (std::size_t i = 0; i < contracts::kLandmarkCount; ++i) {
    const Point3& p = upright.landmarks.points[i];
    const Point3& q = sideways.landmarks.points[i];
    EXPECT_NEAR(q.x, 1.0 - p.y, 1e-3) << i;
    EXPECT_NEAR(q.y, p.x, 1e-3) << i;
    EXPECT_NEAR(q.z, p.z * w / h, 1e-3) << i;  // z is in image widths
  }
}

TEST(TrackerModels, BadImagesAndOptionsAreRejectedClearly) {
  contracts::ManualClock clock;
  HandTracker tracker(video_options(), clock);
  auto rejects = [&](const cv::Mat& m, const std::string& needle) {
    try {
      tracker.process(m);
      ADD_FAILURE() << "accepted " << needle;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  rejects(cv::Mat(), "empty");
  rejects(cv::Mat(48, 64, CV_8UC1, cv::Scalar(0)), "CV_8UC3");
  rejects(cv::Mat(48, 64, CV_8UC4, cv::Scalar::all(0)), "CV_8UC3");
  rejects(cv::Mat(48, 64, CV_32FC3, cv::Scalar::all(0)), "CV_8UC3");

  auto bad = [&](auto change) {
    TrackerOptions o = video_options();
    change(o);
    EXPECT_THROW({ HandTracker t(o, clock); }, std::invalid_argument);
  };
  bad([](TrackerOptions& o) { o.max_hands = 0; });
  bad([](TrackerOptions& o) { o.threads = 0; });
  bad([](TrackerOptions& o) { o.min_presence = 1.5; });
  bad([](TrackerOptions& o) { o.min_detection_confidence = -0.1; });

  TrackerOptions missing = video_options();
  missing.model_dir = "/nonexistent/gbdcs-models";
  try {
    HandTracker t(missing, clock);
    ADD_FAILURE() << "built a tracker without models";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("ci/fetch-models"), std::string::npos) << e.what();
  }

  // A tiny image is fine (letterboxed), it just has no hand.
  EXPECT_TRUE(tracker.process(cv::Mat(3, 5, CV_8UC3, cv::Scalar::all(90))).empty());
}

}  // namespace
}  // namespace gbdcs::vision
