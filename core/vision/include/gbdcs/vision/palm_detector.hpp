// PalmDetector: MediaPipe's palm detection (palm_detection_{lite,full}.tflite) on one image.
//
// Inputs   detect(rgb): a CV_8UC3 RGB image of any size.
// Outputs  the palms found, best first: score in [0, 1], box and 7 keypoints (roi.hpp's
//          PalmKeypoint order) normalised to the image (x / width, y / height). Boxes and
//          keypoints may reach slightly outside [0, 1] for a palm at the border.
// Steps    (palm_detection_cpu.pbtxt) letterbox to 192x192 keeping the aspect ratio, zero
//          border, RGB floats in [0, 1]; the model; decode 2016 anchors (sigmoid score,
//          clipped at ±100); keep score >= min_score; weighted NMS at IoU > 0.3; remove the
//          letterbox.
// Options  PalmDetectorOptions below; RunnerOptions (threads) for the inference runner.
// Errors   constructor: ModelError when the model is not a palm detector (input not 1x192x192x3,
//          or no outputs of 2016x18 boxes and 2016x1 scores). detect(): std::invalid_argument
//          for an empty image or one that is not CV_8UC3.
// Threads  one detect() at a time per detector.
#pragma once

#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "gbdcs/vision/inference_runner.hpp"
#include "gbdcs/vision/roi.hpp"
#include "gbdcs/vision/tflite_model.hpp"

namespace gbdcs::vision {

struct PalmDetectorOptions {
  double min_score = 0.5;  // MediaPipe's min_detection_confidence
  double min_suppression_iou = 0.3;
};

class PalmDetector {
 public:
  // The model may be destroyed once the detector is built.
  explicit PalmDetector(const TfliteModel& model, RunnerOptions runner = {},
                        PalmDetectorOptions options = {});
  explicit PalmDetector(const std::string& model_path, RunnerOptions runner = {},
                        PalmDetectorOptions options = {});
  ~PalmDetector();
  PalmDetector(PalmDetector&&) noexcept;
  PalmDetector& operator=(PalmDetector&&) noexcept;

  std::vector<PalmDetection> detect(const cv::Mat& rgb);

  const PalmDetectorOptions& options() const { return options_; }

 private:
  PalmDetectorOptions options_;
  std::unique_ptr<InferenceRunner> runner_;
  std::vector<Anchor> anchors_;
  std::size_t boxes_output_ = 0;
  std::size_t scores_output_ = 1;
};

}  // namespace gbdcs::vision
