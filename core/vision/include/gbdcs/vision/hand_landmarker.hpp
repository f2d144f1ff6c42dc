// HandLandmarker: MediaPipe's hand landmark model (hand_landmark_{lite,full}.tflite) on one ROI.
//
// Inputs   run(rgb, roi): a CV_8UC3 RGB image and a hand ROI normalised to it (roi.hpp), e.g.
//          palm_detection_to_roi() or the previous frame's landmarks_to_roi().
// Outputs  LandmarkResult:
//            landmarks.points  21 points (MediaPipe order), x / y normalised to the image,
//                              z relative to the wrist-ish model origin, in image widths:
//                              z_model / 224 / 0.4 (TensorsToLandmarks normalize_z) * roi width
//                              (LandmarkProjection), so z has about the scale of x.
//            landmarks.score   hand presence in [0, 1] (the model's sigmoid "hand flag";
//                              MediaPipe thresholds it at 0.5).
//            landmarks.handedness, handedness_score   the label and its probability.
// Handedness  as MediaPipe labels it: the model was trained on mirrored (selfie) images, so
//          the label is right for a mirrored image; on a non-mirrored camera image "Left" is
//          the person's right hand. We report MediaPipe's label unchanged, so our output
//          matches MediaPipe's on the same image (handedness.txt: index 0 "Left", 1 "Right";
//          binary classification: P(Left) = the model's handedness output).
// Steps    (hand_landmark_cpu.pbtxt) the ROI, padded to square if it is not, warped to 224x224
//          (bilinear, replicated border), RGB floats in [0, 1]; the model; landmarks / 224;
//          letterbox removed; projected from the ROI to the image.
// Errors   constructor: ModelError when the model's input is not 1x224x224x3 or its outputs are
//          not [63, 1, 1, 63] values. run(): std::invalid_argument for an empty or non-CV_8UC3
//          image or a ROI with a non-positive or non-finite size.
// Threads  one run() at a time per landmarker.
#pragma once

#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>

#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/vision/inference_runner.hpp"
#include "gbdcs/vision/roi.hpp"
#include "gbdcs/vision/tflite_model.hpp"

namespace gbdcs::vision {

struct LandmarkResult {
  contracts::Landmarks landmarks;  // normalised image coordinates; score = presence
  double handedness_score = 0;     // probability of landmarks.handedness, [0.5, 1]
};

class HandLandmarker {
 public:
  static constexpr int kInputSize = 224;
  static constexpr double kNormalizeZ = 0.4;

  // The model may be destroyed once the landmarker is built.
  explicit HandLandmarker(const TfliteModel& model, RunnerOptions runner = {});
  explicit HandLandmarker(const std::string& model_path, RunnerOptions runner = {});
  ~HandLandmarker();
  HandLandmarker(HandLandmarker&&) noexcept;
  HandLandmarker& operator=(HandLandmarker&&) noexcept;

  LandmarkResult run(const cv::Mat& rgb, const RotatedRect& roi);

 private:
  std::unique_ptr<InferenceRunner> runner_;
};

}  // namespace gbdcs::vision
