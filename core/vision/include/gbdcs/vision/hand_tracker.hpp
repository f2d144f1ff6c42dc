// HandTracker: MediaPipe Hands (hand_landmark_tracking_cpu.pbtxt) on a stream of images:
// palm detection → hand ROI → 21 landmarks → the next frame's ROI.
//
// Inputs   process(rgb) once per frame: a CV_8UC3 RGB image (any size; frames of a stream may
//          change size, ROIs are normalised).
// Outputs  up to max_hands HandObservations, hands tracked from the previous frame first, then
//          new ones in decreasing detection score:
//            landmarks   21 points normalised to the image (hand_landmarker.hpp: z scale,
//                        handedness labelled as MediaPipe labels it), score = presence.
//            roi         the ROI the landmarks were computed in (normalised, rotated).
//            from_detection  true when that ROI came from this frame's palm detection, false
//                        when it came from the previous frame's landmarks.
//          last_timings(): this frame's detection and landmark time on the injected clock.
// Policy   static_images: every frame is detected afresh (MediaPipe's static_image_mode): the
//          top max_hands palms (score >= min_detection_confidence), landmarks on each, hands
//          with presence >= min_presence kept.
//          Video (default): a hand seen in frame t is tracked in frame t+1 from its landmarks'
//          ROI (scale 2.0, shift -0.1) without detection. Palm detection runs only when no hand
//          is tracked, or when a tracked hand's presence dropped below min_presence in this
//          frame (it is dropped and detection runs in the same frame, so one bad frame costs
//          no output). MediaPipe instead detects whenever fewer than max_hands are tracked;
//          we do not, so that one tracked hand costs one landmark run a frame: with
//          max_hands 2 and one hand tracked, a second hand entering the view is found once
//          tracking of the first is lost (or after reset()).
//          Coasting: a tracked hand whose presence falls below min_presence is not reported,
//          but for up to coast_frames further frames the landmark model is still run where its
//          landmarks put it (the ROI follows them, as in tracking); when the presence is back
//          at min_presence or more the hand is reported again (from_detection false), and
//          detection runs in every frame meanwhile as for a lost hand. So a hand the palm
//          detector cannot find (a dark hand against clutter, seen from the back) is not lost
//          for good by one or two frames of low presence in a transition. Nothing below
//          min_presence is ever reported. coast_frames 0 is MediaPipe's behaviour.
//          Overlap: a detected ROI whose axis-aligned IoU with an accepted hand's ROI is > 0.5
//          is the same hand (AssociationNormRectCalculator's 0.5) and is skipped; two tracked
//          hands whose next ROIs overlap by > 0.5 have converged on one hand: the one with the
//          lower presence is dropped.
// Options  TrackerOptions below. full_model picks palm_detection_full + hand_landmark_full
//          (else the lite pair); models come from model_dir (verified against their pinned
//          SHA-256, model_files.hpp).
// Errors   constructor: std::invalid_argument for bad options (max_hands < 1, a confidence
//          outside [0, 1], threads < 1, coast_frames outside [0, 30]); ModelError for a
//          missing, altered or unusable model.
//          process(): std::invalid_argument for an empty image or one that is not CV_8UC3.
// Threads  one process() at a time; the clock must outlive the tracker.
#pragma once

#include <string>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/vision/hand_landmarker.hpp"
#include "gbdcs/vision/palm_detector.hpp"
#include "gbdcs/vision/roi.hpp"

namespace gbdcs::vision {

struct TrackerOptions {
  bool full_model = true;
  int max_hands = 2;
  double min_detection_confidence = 0.5;  // palm score threshold
  double min_presence = 0.5;              // hand presence threshold (MediaPipe: 0.5)
  bool static_images = false;             // true: detect every frame, no tracking
  std::string model_dir;                  // empty = default_model_dir()
  int threads = 1;                        // inference threads per model
  int coast_frames = 5;                   // frames a lost hand is still looked for (0 = none)
};

struct HandObservation {
  contracts::Landmarks landmarks;  // normalised image coordinates; score = presence
  RotatedRect roi;
  bool from_detection = false;
};

struct TrackerTimings {
  double detection_ms = 0;  // palm detection, 0 when it did not run
  double landmarks_ms = 0;  // all landmark runs of the frame
  bool ran_detection = false;
};

class HandTracker {
 public:
  HandTracker(TrackerOptions options, const contracts::Clock& clock);

  std::vector<HandObservation> process(const cv::Mat& rgb);
  void reset();  // forget tracked hands: the next frame runs detection
  TrackerTimings last_timings() const { return timings_; }
  const TrackerOptions& options() const { return options_; }

 private:
  double elapsed_ms(contracts::Duration since) const;
  void detect_new_hands(const cv::Mat& rgb, std::vector<HandObservation>& hands);

  TrackerOptions options_;
  const contracts::Clock& clock_;
  PalmDetector detector_;
  HandLandmarker landmarker_;
  struct Coasting {
    RotatedRect roi;      // where the lost hand's last landmarks put it
    int frames_left = 0;  // landmark runs left before it is given up
  };
  std::vector<RotatedRect> tracked_;  // ROIs for the next frame, from this frame's landmarks
  std::vector<Coasting> coasting_;    // lost hands still looked for (not reported)
  TrackerTimings timings_;
};

}  // namespace gbdcs::vision
