#include "gbdcs/sim/twin_camera_source.hpp"

#include <memory>
#include <stdexcept>
#include <utility>

namespace gbdcs::sim {

TwinCameraSource::TwinCameraSource(Producer produce, std::string name, std::int64_t max_frames)
    : produce_(std::move(produce)), name_(std::move(name)), max_frames_(max_frames) {
  if (!produce_) {
    throw std::invalid_argument("TwinCameraSource: the producer is empty");
  }
}

std::optional<TwinFrame> TwinCameraSource::next() {
  if (ended_ || (max_frames_ >= 0 && next_id_ >= max_frames_)) {
    ended_ = true;
    return std::nullopt;
  }
  cv::Mat image = produce_();
  if (image.empty()) {
    ended_ = true;
    return std::nullopt;
  }
  if (image.type() != CV_8UC3) {
    throw std::runtime_error("TwinCameraSource " + name_ +
                             ": the producer returned a frame of "
                             "type " +
                             std::to_string(image.type()) + ", not CV_8UC3");
  }
  return TwinFrame{std::move(image), next_id_++};
}

std::optional<cv::Mat> TwinCameraSource::generate(std::int64_t frame_id) {
  if (frame_id != next_id_ && !ended_) {
    throw std::logic_error("TwinCameraSource " + name_ + ": asked for frame " +
                           std::to_string(frame_id) + ", the next one is " +
                           std::to_string(next_id_));
  }
  auto frame = next();
  if (!frame) {
    return std::nullopt;
  }
  return std::move(frame->bgr);
}

TwinCameraSource::Producer make_render_producer(const mjModel* model,
                                                std::function<const mjData*()> read_state,
                                                std::string camera, RendererOptions options) {
  if (model == nullptr || !read_state) {
    throw std::invalid_argument(
        "make_render_producer: the model and the state reader are required");
  }
  // shared_ptr: std::function needs a copyable callable.
  auto renderer = std::make_shared<std::unique_ptr<Renderer>>();
  return [model, read_state = std::move(read_state), camera = std::move(camera), options,
          renderer]() -> cv::Mat {
    const mjData* data = read_state();
    if (data == nullptr) {
      return {};
    }
    if (!*renderer) {
      *renderer = std::make_unique<Renderer>(model, options);
    }
    return (*renderer)->render(data, camera);
  };
}

}  // namespace gbdcs::sim
