#include "gbdcs/vision/hand_tracker.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "gbdcs/vision/model_files.hpp"
#include "tracker/image_crop.hpp"

namespace gbdcs::vision {

namespace {

constexpr double kSameHandIou = 0.5;  // AssociationNormRectCalculator min_similarity_threshold

const TrackerOptions& validated(const TrackerOptions& o) {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("TrackerOptions: " + what);
  };
  if (o.max_hands < 1) fail("max_hands must be >= 1, got " + std::to_string(o.max_hands));
  if (!(o.min_detection_confidence >= 0 && o.min_detection_confidence <= 1)) {
    fail("min_detection_confidence must be in [0, 1], got " +
         std::to_string(o.min_detection_confidence));
  }
  if (!(o.min_presence >= 0 && o.min_presence <= 1)) {
    fail("min_presence must be in [0, 1], got " + std::to_string(o.min_presence));
  }
  if (o.threads < 1) fail("threads must be >= 1, got " + std::to_string(o.threads));
  if (o.coast_frames < 0 || o.coast_frames > 30) {
    fail("coast_frames must be in [0, 30], got " + std::to_string(o.coast_frames));
  }
  return o;
}

std::string model_path(const TrackerOptions& o, ModelKind kind) {
  return verified_model_path(kind, o.model_dir.empty() ? default_model_dir() : o.model_dir);
}

}  // namespace

HandTracker::HandTracker(TrackerOptions options, const contracts::Clock& clock)
    : options_(validated(options)),
      clock_(clock),
      detector_(model_path(options_, options_.full_model ? ModelKind::kPalmDetectionFull
                                                         : ModelKind::kPalmDetectionLite),
                RunnerOptions{options_.threads},
                PalmDetectorOptions{.min_score = options_.min_detection_confidence}),
      landmarker_(model_path(options_, options_.full_model ? ModelKind::kHandLandmarkFull
                                                           : ModelKind::kHandLandmarkLite),
                  RunnerOptions{options_.threads}) {}

double HandTracker::elapsed_ms(contracts::Duration since) const {
  return contracts::to_seconds(clock_.now() - since) * 1000.0;
}

void HandTracker::reset() {
  tracked_.clear();
  coasting_.clear();
  timings_ = {};
}

std::vector<HandObservation> HandTracker::process(const cv::Mat& rgb) {
  detail::check_rgb_image(rgb, "HandTracker::process");
  timings_ = {};
  std::vector<HandObservation> hands;
  bool lost = false;

  if (!options_.static_images) {
    // Lost hands first looked for where their last landmarks were, then the tracked ones.
    // A hand under min_presence is kept looking for while it has frames left.
    std::vector<Coasting> still_lost;
    auto look = [&](const RotatedRect& roi, int frames_left) {
      const contracts::Duration start = clock_.now();
      LandmarkResult r = landmarker_.run(rgb, roi);
      timings_.landmarks_ms += elapsed_ms(start);
      if (r.landmarks.score >= options_.min_presence) {
        hands.push_back({r.landmarks, roi, false});
        return true;
      }
      if (frames_left > 0) {
        const RotatedRect next = landmarks_to_roi(r.landmarks.points, rgb.cols, rgb.rows);
        if (roi_is_usable(next, rgb.cols, rgb.rows)) still_lost.push_back({next, frames_left});
      }
      return false;
    };
    for (const Coasting& c : coasting_) look(c.roi, c.frames_left - 1);
    for (const RotatedRect& roi : tracked_) {
      if (!look(roi, options_.coast_frames)) lost = true;
    }
    coasting_ = std::move(still_lost);
    // Two tracked ROIs that slid onto the same hand: keep the more confident one.
    std::vector<HandObservation> unique;
    for (HandObservation& h : hands) {
      const RotatedRect next = landmarks_to_roi(h.landmarks.points, rgb.cols, rgb.rows);
      auto same = std::find_if(unique.begin(), unique.end(), [&](const HandObservation& u) {
        return rect_iou(landmarks_to_roi(u.landmarks.points, rgb.cols, rgb.rows), next) >
               kSameHandIou;
      });
      if (same == unique.end()) {
        unique.push_back(std::move(h));
      } else if (h.landmarks.score > same->landmarks.score) {
        *same = std::move(h);
      }
    }
    hands = std::move(unique);
  }

  const bool want_detection = options_.static_images || hands.empty() || lost;
  if (want_detection && hands.size() < static_cast<std::size_t>(options_.max_hands)) {
    detect_new_hands(rgb, hands);
  }

  tracked_.clear();
  if (!options_.static_images) {
    for (const HandObservation& h : hands) {
      const RotatedRect next = landmarks_to_roi(h.landmarks.points, rgb.cols, rgb.rows);
      if (roi_is_usable(next, rgb.cols, rgb.rows)) tracked_.push_back(next);  // else: detect
    }
    // A lost hand found again (by detection or by tracking) is no longer looked for, and no
    // more hands are looked for than max_hands.
    std::erase_if(coasting_, [&](const Coasting& c) {
      return std::any_of(tracked_.begin(), tracked_.end(),
                         [&](const RotatedRect& t) { return rect_iou(t, c.roi) > kSameHandIou; });
    });
    const std::size_t room = static_cast<std::size_t>(options_.max_hands) - tracked_.size();
    if (coasting_.size() > room) coasting_.resize(room);
  }
  return hands;
}

void HandTracker::detect_new_hands(const cv::Mat& rgb, std::vector<HandObservation>& hands) {
  const contracts::Duration start = clock_.now();
  std::vector<PalmDetection> palms = detector_.detect(rgb);
  timings_.detection_ms = elapsed_ms(start);
  timings_.ran_detection = true;

  // ClipDetectionVectorSize: only the best max_hands palms are considered.
  const std::size_t max_hands = static_cast<std::size_t>(options_.max_hands);
  if (palms.size() > max_hands) palms.resize(max_hands);
  for (const PalmDetection& palm : palms) {
    if (hands.size() >= max_hands) break;
    const RotatedRect roi = palm_detection_to_roi(palm, rgb.cols, rgb.rows);
    const bool known = std::any_of(hands.begin(), hands.end(), [&](const HandObservation& h) {
      return rect_iou(h.roi, roi) > kSameHandIou;
    });
    if (known) continue;
    const contracts::Duration t0 = clock_.now();
    LandmarkResult r = landmarker_.run(rgb, roi);
    timings_.landmarks_ms += elapsed_ms(t0);
    if (r.landmarks.score >= options_.min_presence) hands.push_back({r.landmarks, roi, true});
  }
}

}  // namespace gbdcs::vision
