#include "gbdcs/sim/video_recorder.hpp"

#include <cctype>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "option_reader.hpp"

namespace gbdcs::sim {
namespace {

// VideoWriter::open reports nothing useful when the folder is missing or read-only, so check
// that the file can be created first and say so in terms a user can act on.
void check_writable(const std::filesystem::path& path, const char* what) {
  if (path.empty()) {
    throw std::runtime_error(std::string(what) + ": the output path is empty");
  }
  const std::filesystem::path folder =
      path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) {
    throw std::runtime_error(std::string(what) + ": cannot write " + path.string() +
                             ": the folder " + folder.string() + " does not exist");
  }
  const bool existed = std::filesystem::exists(path, error);
  std::ofstream probe(path, std::ios::binary | std::ios::app);
  if (!probe) {
    throw std::runtime_error(std::string(what) + ": cannot write " + path.string() +
                             " (permission denied, or it is a folder)");
  }
  probe.close();
  if (!existed) {
    std::filesystem::remove(path, error);
  }
}

int fourcc_of(const std::string& codec) {
  return cv::VideoWriter::fourcc(codec[0], codec[1], codec[2], codec[3]);
}

}  // namespace

VideoRecorderOptions VideoRecorderOptions::from_json(const nlohmann::json& doc) {
  VideoRecorderOptions options;
  detail::OptionReader reader(doc, "VideoRecorderOptions");
  reader.read("fps", options.fps);
  reader.read("codec", options.codec);
  reader.finish();
  return options;
}

struct VideoRecorder::Writer {
  cv::VideoWriter video;
};

VideoRecorder::VideoRecorder(std::filesystem::path path, cv::Size frame_size,
                             VideoRecorderOptions options)
    : path_(std::move(path)),
      size_(frame_size),
      options_(std::move(options)),
      writer_(std::make_unique<Writer>()) {
  if (!(options_.fps >= 1 && options_.fps <= 240)) {
    throw std::invalid_argument("VideoRecorder: fps must be 1 ... 240, got " +
                                std::to_string(options_.fps));
  }
  if (size_.width < 2 || size_.height < 2 || size_.width % 2 != 0 || size_.height % 2 != 0) {
    // H.264 with 4:2:0 chroma needs even sides; keep one rule for both codecs.
    throw std::invalid_argument(
        "VideoRecorder: the frame size must be even and at least 2x2, got " +
        std::to_string(size_.width) + "x" + std::to_string(size_.height));
  }
  std::string extension = path_.extension().string();
  for (char& c : extension) {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  if (extension != ".mp4") {
    throw std::invalid_argument("VideoRecorder: the output must be an .mp4 file, got " +
                                path_.string());
  }
  std::vector<std::string> candidates;
  if (options_.codec == "auto") {
    candidates = {"avc1", "mp4v"};
  } else if (options_.codec == "avc1" || options_.codec == "mp4v") {
    candidates = {options_.codec};
  } else {
    throw std::invalid_argument(
        "VideoRecorder: codec must be \"auto\", \"avc1\" or \"mp4v\", got \"" + options_.codec +
        "\"");
  }
  check_writable(path_, "VideoRecorder");
  for (const auto& codec : candidates) {
    if (writer_->video.open(path_.string(), cv::CAP_FFMPEG, fourcc_of(codec), options_.fps, size_,
                            true)) {
      codec_ = codec;
      break;
    }
  }
  if (codec_.empty()) {
    throw std::runtime_error("VideoRecorder: OpenCV's FFmpeg backend could not open " +
                             path_.string() + " with codec " + candidates.front() +
                             (candidates.size() > 1 ? " nor mp4v" : "") +
                             "; is OpenCV built with FFmpeg (libopencv-videoio406)?");
  }
  if (codec_ != candidates.front()) {
    std::clog << "VideoRecorder: H.264 (avc1) is not available in this OpenCV/FFmpeg build; "
                 "writing MPEG-4 Part 2 (mp4v) to "
              << path_.string() << " (plays in VLC/ffplay, not in browsers)\n";
  }
}

VideoRecorder::~VideoRecorder() {
  close();
}

void VideoRecorder::write(const cv::Mat& frame) {
  if (!writer_->video.isOpened()) {
    throw std::logic_error("VideoRecorder: write() after close() on " + path_.string());
  }
  if (frame.type() != CV_8UC3 || frame.size() != size_) {
    throw std::invalid_argument("VideoRecorder: frames must be CV_8UC3 " +
                                std::to_string(size_.width) + "x" + std::to_string(size_.height) +
                                ", got type " + std::to_string(frame.type()) + " " +
                                std::to_string(frame.cols) + "x" + std::to_string(frame.rows));
  }
  writer_->video.write(frame);
  ++frames_written_;
}

void VideoRecorder::close() {
  if (writer_ && writer_->video.isOpened()) {
    writer_->video.release();
  }
}

void save_png(const std::filesystem::path& path, const cv::Mat& image) {
  if (image.empty()) {
    throw std::invalid_argument("save_png: the image is empty (" + path.string() + ")");
  }
  check_writable(path, "save_png");
  bool written = false;
  try {
    written = cv::imwrite(path.string(), image);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("save_png: cannot write " + path.string() + ": " + e.what());
  }
  if (!written) {
    throw std::runtime_error("save_png: cannot write " + path.string());
  }
}

}  // namespace gbdcs::sim
