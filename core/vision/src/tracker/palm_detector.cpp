#include "gbdcs/vision/palm_detector.hpp"

#include <span>
#include <string>

#include "tracker/image_crop.hpp"

namespace gbdcs::vision {

namespace {

constexpr int kInputSize = 192;
constexpr std::size_t kNumBoxes = 2016;
constexpr std::size_t kNumCoords = 18;

std::string shape_string(const std::vector<int>& shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? "x" : "") + std::to_string(shape[i]);
  return s + "]";
}

// Element count of the dimensions after the first (the batch).
std::size_t per_item(const std::vector<int>& shape) {
  std::size_t n = 1;
  for (std::size_t i = 1; i < shape.size(); ++i) n *= static_cast<std::size_t>(shape[i]);
  return n;
}

}  // namespace

PalmDetector::PalmDetector(const TfliteModel& model, RunnerOptions runner,
                           PalmDetectorOptions options)
    : options_(options),
      runner_(InferenceRunner::create(model, runner)),
      anchors_(generate_anchors()) {
  const auto& in = runner_->inputs();
  if (in.size() != 1 || in[0].shape != std::vector<int>{1, kInputSize, kInputSize, 3}) {
    throw ModelError("PalmDetector: expected one 1x192x192x3 input, got " +
                     (in.empty() ? std::string("none") : shape_string(in[0].shape)));
  }
  const auto& out = runner_->outputs();
  bool have_boxes = false, have_scores = false;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::size_t n = per_item(out[i].shape);
    if (n == kNumBoxes * kNumCoords && out[i].shape.back() == static_cast<int>(kNumCoords)) {
      boxes_output_ = i;
      have_boxes = true;
    } else if (n == kNumBoxes) {
      scores_output_ = i;
      have_scores = true;
    }
  }
  if (!have_boxes || !have_scores) {
    std::string shapes;
    for (const auto& t : out) shapes += " " + t.name + shape_string(t.shape);
    throw ModelError("PalmDetector: expected outputs of 2016x18 boxes and 2016x1 scores, got" +
                     shapes);
  }
}

PalmDetector::PalmDetector(const std::string& model_path, RunnerOptions runner,
                           PalmDetectorOptions options)
    : PalmDetector(TfliteModel::from_file(model_path), runner, options) {}

PalmDetector::~PalmDetector() = default;
PalmDetector::PalmDetector(PalmDetector&&) noexcept = default;
PalmDetector& PalmDetector::operator=(PalmDetector&&) noexcept = default;

std::vector<PalmDetection> PalmDetector::detect(const cv::Mat& rgb) {
  detail::check_rgb_image(rgb, "PalmDetector::detect");
  const RotatedRect whole = letterbox_rect(rgb.cols, rgb.rows, kInputSize, kInputSize);
  detail::crop_to_tensor(rgb, whole, kInputSize, kInputSize, detail::CropBorder::kZero,
                         runner_->input_data(0));
  runner_->invoke();

  DecodeOptions decode;
  decode.min_score_thresh = options_.min_score;
  const std::span<const float> boxes(runner_->output_data(boxes_output_), kNumBoxes * kNumCoords);
  const std::span<const float> scores(runner_->output_data(scores_output_), kNumBoxes);
  std::vector<PalmDetection> found = weighted_non_max_suppression(
      decode_palm_tensors(boxes, scores, anchors_, decode), options_.min_suppression_iou);

  const LetterboxPadding pad = letterbox_padding(rgb.cols, rgb.rows, kInputSize, kInputSize);
  for (PalmDetection& d : found) d = remove_letterbox(d, pad);
  return found;
}

}  // namespace gbdcs::vision
