#include "gbdcs/vision/hand_landmarker.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "tracker/image_crop.hpp"

namespace gbdcs::vision {

namespace {

constexpr std::size_t kLandmarksOutput = 0;  // output order of hand_landmark_cpu.pbtxt's split
constexpr std::size_t kPresenceOutput = 1;
constexpr std::size_t kHandednessOutput = 2;

std::size_t element_count(const std::vector<int>& shape) {
  std::size_t n = 1;
  for (int d : shape) n *= static_cast<std::size_t>(d);
  return n;
}

std::string shape_string(const std::vector<int>& shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? "x" : "") + std::to_string(shape[i]);
  return s + "]";
}

}  // namespace

HandLandmarker::HandLandmarker(const TfliteModel& model, RunnerOptions runner)
    : runner_(InferenceRunner::create(model, runner)) {
  const auto& in = runner_->inputs();
  if (in.size() != 1 || in[0].shape != std::vector<int>{1, kInputSize, kInputSize, 3}) {
    throw ModelError("HandLandmarker: expected one 1x224x224x3 input, got " +
                     (in.empty() ? std::string("none") : shape_string(in[0].shape)));
  }
  const auto& out = runner_->outputs();
  const std::size_t expected[] = {63, 1, 1, 63};
  bool ok = out.size() == 4;
  for (std::size_t i = 0; ok && i < 4; ++i) ok = element_count(out[i].shape) == expected[i];
  if (!ok) {
    std::string shapes;
    for (const auto& t : out) shapes += " " + t.name + shape_string(t.shape);
    throw ModelError(
        "HandLandmarker: expected outputs of 63, 1, 1, 63 values (landmarks, "
        "presence, handedness, world landmarks), got" +
        shapes);
  }
}

HandLandmarker::HandLandmarker(const std::string& model_path, RunnerOptions runner)
    : HandLandmarker(TfliteModel::from_file(model_path), runner) {}

HandLandmarker::~HandLandmarker() = default;
HandLandmarker::HandLandmarker(HandLandmarker&&) noexcept = default;
HandLandmarker& HandLandmarker::operator=(HandLandmarker&&) noexcept = default;

LandmarkResult HandLandmarker::run(const cv::Mat& rgb, const RotatedRect& roi) {
  detail::check_rgb_image(rgb, "HandLandmarker::run");
  if (!(roi.width > 0) || !(roi.height > 0) || !std::isfinite(roi.width) ||
      !std::isfinite(roi.height) || !std::isfinite(roi.center_x) || !std::isfinite(roi.center_y) ||
      !std::isfinite(roi.rotation_rad)) {
    throw std::invalid_argument("HandLandmarker::run: the ROI needs a finite, positive size");
  }
  // PadRoi (keep_aspect_ratio): a ROI that is not square in pixels is letterboxed.
  const double w_px = roi.width * rgb.cols;
  const double h_px = roi.height * rgb.rows;
  const double side = std::max(w_px, h_px);
  RotatedRect padded = roi;
  padded.width = side / rgb.cols;
  padded.height = side / rgb.rows;
  LetterboxPadding pad;
  pad.left = pad.right = (1.0 - w_px / side) / 2;
  pad.top = pad.bottom = (1.0 - h_px / side) / 2;

  detail::crop_to_tensor(rgb, padded, kInputSize, kInputSize, detail::CropBorder::kReplicate,
                         runner_->input_data(0));
  runner_->invoke();

  const float* raw = runner_->output_data(kLandmarksOutput);
  LandmarkResult result;
  for (std::size_t i = 0; i < contracts::kLandmarkCount; ++i) {
    const Point2 in_roi =
        remove_letterbox(Point2{raw[3 * i] / kInputSize, raw[3 * i + 1] / kInputSize}, pad);
    // LandmarkLetterboxRemoval scales z as x.
    const double z = raw[3 * i + 2] / kInputSize / kNormalizeZ / (1.0 - pad.left - pad.right);
    result.landmarks.points[i] = project_from_rect({in_roi.x, in_roi.y, z}, roi);
  }
  result.landmarks.score =
      std::clamp(static_cast<double>(*runner_->output_data(kPresenceOutput)), 0.0, 1.0);
  const double p_left =
      std::clamp(static_cast<double>(*runner_->output_data(kHandednessOutput)), 0.0, 1.0);
  result.landmarks.handedness =
      p_left > 0.5 ? contracts::Handedness::kLeft : contracts::Handedness::kRight;
  result.handedness_score = p_left > 0.5 ? p_left : 1.0 - p_left;
  return result;
}

}  // namespace gbdcs::vision
