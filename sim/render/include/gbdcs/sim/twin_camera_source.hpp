// TwinCameraSource: the twin's on-board camera as a stream of video frames, for the vision
// pipeline (the app adapts it to vision::CaptureSource; sim never includes core/vision).
//
// Inputs   a producer called once per frame, on the thread that calls next(): it returns the
//          frame (CV_8UC3 BGR, e.g. Renderer::render(data, "onboard")) or an empty Mat at the
//          end of the stream. It may throw; next() lets the exception through.
// Output   next() -> TwinFrame {bgr, frame_id 0, 1, 2, ...} or nullopt at the end (the
//          producer returned an empty Mat, max_frames were produced, or close() was called);
//          after the end, next() keeps returning nullopt without calling the producer.
//          generate(frame_id) is the same stream in vision::GeneratorSource's shape
//          (std::optional<cv::Mat>(std::int64_t)), with the frame ids checked.
// Threading: one consumer thread. A producer that renders must use a Renderer created on that
//          thread (make_render_producer does so lazily on the first call).
#pragma once

#include <mujoco/mujoco.h>

#include <cstdint>
#include <functional>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>

#include "gbdcs/sim/renderer.hpp"

namespace gbdcs::sim {

struct TwinFrame {
  cv::Mat bgr;
  std::int64_t frame_id = 0;
};

class TwinCameraSource {
 public:
  using Producer = std::function<cv::Mat()>;

  // max_frames < 0: no limit. name: what describe() reports, e.g. "twin:onboard".
  explicit TwinCameraSource(Producer produce, std::string name = "twin:onboard",
                            std::int64_t max_frames = -1);

  std::optional<TwinFrame> next();
  // Throws std::logic_error when frame_id is not the next id in sequence.
  std::optional<cv::Mat> generate(std::int64_t frame_id);
  void close() { ended_ = true; }

  bool ended() const { return ended_; }
  std::int64_t frames_produced() const { return next_id_; }
  const std::string& describe() const { return name_; }

 private:
  Producer produce_;
  std::string name_;
  std::int64_t max_frames_;
  std::int64_t next_id_ = 0;
  bool ended_ = false;
};

// A producer that renders `camera` of the state `read_state()` returns (nullptr ends the
// stream). The Renderer is built on the first call, so on the consumer's thread; the model
// must outlive the producer, and the state must not be stepped while it is being rendered.
TwinCameraSource::Producer make_render_producer(const mjModel* model,
                                                std::function<const mjData*()> read_state,
                                                std::string camera = "onboard",
                                                RendererOptions options = {});

}  // namespace gbdcs::sim
