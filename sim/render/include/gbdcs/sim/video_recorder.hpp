// VideoRecorder: writes the frames of a run to an MP4 file at a fixed frame rate, through
// OpenCV's VideoWriter (FFmpeg backend). save_png() writes a still.
//
// Inputs   write(frame): CV_8UC3 BGR frames, all of the size given at construction.
// Output   an MP4 at `path`, `fps` frames per second (the frames' timestamps are i / fps;
//          frames are never dropped or duplicated, so a run recorded at simulated time plays
//          back at real speed when frames are written every 1 / fps simulated seconds).
// Codec    H.264 ("avc1", playable in browsers) when the FFmpeg build can encode it, else
//          MPEG-4 Part 2 ("mp4v"); the fallback is reported once on std::clog with the reason.
//          codec() says which one is in use. Options (VideoRecorderOptions, JSON: the same keys):
//            fps    frames per second, default 30; 1 ... 240
//            codec  "auto" (default: avc1, then mp4v), "avc1" or "mp4v" (no fallback)
// Errors   a path that cannot be written (missing folder, no permission) or a codec that will
//          not open -> std::runtime_error naming the path; a frame of the wrong size or type,
//          or write() after close() -> std::invalid_argument / std::logic_error.
// Threading: one thread at a time.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>
#include <string>

namespace gbdcs::sim {

struct VideoRecorderOptions {
  double fps = 30;
  std::string codec = "auto";

  static VideoRecorderOptions from_json(const nlohmann::json& doc);
};

class VideoRecorder {
 public:
  VideoRecorder(std::filesystem::path path, cv::Size frame_size, VideoRecorderOptions options = {});
  ~VideoRecorder();  // closes the file
  VideoRecorder(const VideoRecorder&) = delete;
  VideoRecorder& operator=(const VideoRecorder&) = delete;

  void write(const cv::Mat& frame);
  void close();  // finishes the file; idempotent

  const std::string& codec() const { return codec_; }  // "avc1" or "mp4v"
  std::int64_t frames_written() const { return frames_written_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  struct Writer;
  std::filesystem::path path_;
  cv::Size size_;
  VideoRecorderOptions options_;
  std::string codec_;
  std::unique_ptr<Writer> writer_;
  std::int64_t frames_written_ = 0;
};

// Writes `image` (CV_8UC1, CV_8UC3 BGR or CV_8UC4 BGRA) as a PNG; throws std::runtime_error
// naming the path when it cannot be written, std::invalid_argument for an empty image.
void save_png(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace gbdcs::sim
