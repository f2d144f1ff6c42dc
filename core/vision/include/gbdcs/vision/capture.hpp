// Capture sources: where the vision pipeline's frames come from.
//
// Contract of every CaptureSource
//   next()      blocks until the next frame and returns it; nullopt = end of stream (a video
//               or a folder that has been read to the end; for a live source that is a
//               failure the pipeline reports). Throws CaptureError when the source fails
//               (a camera that stops delivering, an image that cannot be decoded). Must return
//               within a bounded time (about one frame interval) so the pipeline can stop.
//   live()      true for a source that runs on its own clock (a camera): the pipeline drops
//               the oldest frame when it falls behind. false for offline sources (files),
//               which the pipeline reads at its own pace, losing nothing.
//   describe()  the spec the source was opened with, e.g. "camera:0", "video:clip.mp4".
// Every frame carries capture_time / capture_utc read from the injected Clock when the frame
// was produced, and a frame_id counting from 0. A source is used by one thread at a time.
//
// Specs for open_source()
//   camera:N     OpenCV camera index N (V4L2 /dev/videoN on Linux); live.
//   video:PATH   a video file OpenCV can decode (mp4, avi, mkv, ...); offline.
//   video:PATH?live=1[&fps=N]
//                the same file played as a camera (live): frame k is due k/fps after the
//                first (the file's own rate, or N), looping forever; frames whose time has
//                passed while the reader was busy are skipped, as a camera's are.
//   images:DIR   the images in DIR (.jpg .jpeg .png .bmp .webp .tif .tiff), sorted by file
//                name; offline; not recursive.
// A source that cannot be opened throws CaptureError naming the source and the fix.
//
// GeneratorSource is the interface the fixture renderer (and tests) plug into: a callback
// that makes frame N, or nullopt at the end.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/vision/frame.hpp"

namespace gbdcs::vision {

class CaptureError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CaptureSource {
 public:
  virtual ~CaptureSource() = default;
  virtual std::optional<Frame> next() = 0;
  virtual bool live() const = 0;
  virtual std::string describe() const = 0;
};

// Throws CaptureError for an unknown scheme or a source that cannot be opened. The clock must
// outlive the source.
std::unique_ptr<CaptureSource> open_source(std::string_view spec, const contracts::Clock& clock);

std::unique_ptr<CaptureSource> open_camera(int index, const contracts::Clock& clock);
std::unique_ptr<CaptureSource> open_video(const std::filesystem::path& path,
                                          const contracts::Clock& clock);
// A video file played as a live camera (see video:PATH?live=1). `fps` <= 0: the file's own
// rate (CaptureError if the file has none). `name`: what describe() says (default
// "video:PATH?live=1"). Pacing: next() sleeps (real time) until its frame is due by `clock`.
std::unique_ptr<CaptureSource> open_live_video(const std::filesystem::path& path,
                                               const contracts::Clock& clock, double fps = 0,
                                               std::string name = {});
std::unique_ptr<CaptureSource> open_images(const std::filesystem::path& dir,
                                           const contracts::Clock& clock);

// The image files open_images() would read, sorted; throws CaptureError if none.
std::vector<std::filesystem::path> list_images(const std::filesystem::path& dir);
bool is_image_file(const std::filesystem::path& path);  // by extension, case-insensitive

// A source fed by a callback: generate(frame_id) returns the frame's pixels (CV_8UC3 in
// `order`), or nullopt at the end of the stream; it may throw to report a failure, which
// next() passes on as CaptureError. A live generator paces itself (blocks until its frame
// is due).
class GeneratorSource final : public CaptureSource {
 public:
  using Generator = std::function<std::optional<cv::Mat>(std::int64_t frame_id)>;
  GeneratorSource(Generator generate, const contracts::Clock& clock, std::string name, bool live,
                  PixelOrder order = PixelOrder::kRgb);

  std::optional<Frame> next() override;
  bool live() const override { return live_; }
  std::string describe() const override { return name_; }

 private:
  Generator generate_;
  const contracts::Clock& clock_;
  std::string name_;
  bool live_;
  PixelOrder order_;
  std::int64_t next_id_ = 0;
  bool ended_ = false;
};

}  // namespace gbdcs::vision
