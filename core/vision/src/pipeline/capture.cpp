// Capture sources: OpenCV camera and video file, a sorted folder of images, a generator.
#include "gbdcs/vision/capture.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

namespace gbdcs::vision {
namespace fs = std::filesystem;

namespace {

// V4L2 straight away on Linux: CAP_ANY would try GStreamer first and print its warnings.
#ifdef __linux__
constexpr int kCameraApi = cv::CAP_V4L2;
#else
constexpr int kCameraApi = cv::CAP_ANY;
#endif

int video_file_api() {
  return cv::videoio_registry::hasBackend(cv::CAP_FFMPEG) ? cv::CAP_FFMPEG : cv::CAP_ANY;
}

constexpr std::string_view kSpecHelp =
    "use camera:N (a camera index, e.g. camera:0), video:PATH (a video file) or images:DIR "
    "(a folder of .jpg/.png images)";

Frame stamp(cv::Mat pixels, std::int64_t id, const contracts::Clock& clock, std::string source,
            PixelOrder order) {
  Frame f;
  f.rgb = std::move(pixels);
  f.frame_id = id;
  f.capture_time = clock.now();
  f.capture_utc = clock.utc_now();
  f.source = std::move(source);
  f.order = order;
  return f;
}

void check_pixels(const cv::Mat& m, const std::string& where) {
  if (m.empty() || m.type() != CV_8UC3) {
    throw CaptureError(where + ": frame is " +
                       (m.empty() ? std::string("empty") : "not 8-bit 3-channel") +
                       " (a source must deliver CV_8UC3 images)");
  }
}

class CameraSource final : public CaptureSource {
 public:
  CameraSource(int index, const contracts::Clock& clock)
      : clock_(clock), name_("camera:" + std::to_string(index)) {
    if (!capture_.open(index, kCameraApi) || !capture_.isOpened()) {
      throw CaptureError(name_ + ": cannot open camera " + std::to_string(index) +
                         " (is it connected and not in use by another program? check that "
                         "/dev/video" +
                         std::to_string(index) +
                         " exists and that you may read it (group 'video'), or try another "
                         "index)");
    }
  }
  std::optional<Frame> next() override {
    cv::Mat pixels;  // a fresh Mat each time: the previous frame may still be in a queue
    if (!capture_.read(pixels) || pixels.empty()) {
      throw CaptureError(name_ + ": the camera stopped delivering frames after " +
                         std::to_string(next_id_) + " (unplugged, or taken by another program?)");
    }
    check_pixels(pixels, name_);
    return stamp(std::move(pixels), next_id_++, clock_, name_, PixelOrder::kBgr);
  }
  bool live() const override { return true; }
  std::string describe() const override { return name_; }

 private:
  const contracts::Clock& clock_;
  std::string name_;
  cv::VideoCapture capture_;
  std::int64_t next_id_ = 0;
};

class VideoSource final : public CaptureSource {
 public:
  VideoSource(const fs::path& path, const contracts::Clock& clock)
      : clock_(clock), name_("video:" + path.string()), path_(path.string()) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      throw CaptureError(name_ + ": no such file (check the path; it is relative to " +
                         fs::current_path(ec).string() + ")");
    }
    if (!capture_.open(path_, video_file_api()) || !capture_.isOpened()) {
      throw CaptureError(name_ +
                         ": OpenCV cannot decode this file (is it a video? "
                         "convert it with `ffmpeg -i " +
                         path_ + " out.mp4`)");
    }
  }
  std::optional<Frame> next() override {
    cv::Mat pixels;
    if (!capture_.read(pixels) || pixels.empty()) return std::nullopt;
    check_pixels(pixels, name_);
    return stamp(std::move(pixels), next_id_++, clock_, path_, PixelOrder::kBgr);
  }
  bool live() const override { return false; }
  std::string describe() const override { return name_; }

 private:
  const contracts::Clock& clock_;
  std::string name_;
  std::string path_;
  cv::VideoCapture capture_;
  std::int64_t next_id_ = 0;
};

class ImageFolderSource final : public CaptureSource {
 public:
  ImageFolderSource(const fs::path& dir, const contracts::Clock& clock)
      : clock_(clock), name_("images:" + dir.string()), files_(list_images(dir)) {}
  std::optional<Frame> next() override {
    if (next_index_ >= files_.size()) return std::nullopt;
    const auto& file = files_[next_index_++];
    cv::Mat pixels = cv::imread(file.string(), cv::IMREAD_COLOR);
    if (pixels.empty()) {
      throw CaptureError(name_ + ": cannot decode " + file.string() +
                         " (a damaged or unsupported image; remove it from the folder)");
    }
    return stamp(std::move(pixels), next_id_++, clock_, file.string(), PixelOrder::kBgr);
  }
  bool live() const override { return false; }
  std::string describe() const override { return name_; }

 private:
  const contracts::Clock& clock_;
  std::string name_;
  std::vector<fs::path> files_;
  std::size_t next_index_ = 0;
  std::int64_t next_id_ = 0;
};

}  // namespace

bool is_image_file(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".bmp" || ext == ".webp" ||
         ext == ".tif" || ext == ".tiff";
}

std::vector<fs::path> list_images(const fs::path& dir) {
  const std::string name = "images:" + dir.string();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw CaptureError(name +
                       ": not a folder (check the path; images:DIR takes a folder of "
                       ".jpg/.png files, for one file use `gbdcs recognize FILE`)");
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.is_regular_file() && is_image_file(entry.path())) files.push_back(entry.path());
  }
  if (ec) throw CaptureError(name + ": cannot list the folder: " + ec.message());
  if (files.empty()) {
    throw CaptureError(name +
                       ": no images in the folder (looked for .jpg .jpeg .png .bmp "
                       ".webp .tif .tiff)");
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::unique_ptr<CaptureSource> open_camera(int index, const contracts::Clock& clock) {
  if (index < 0) throw CaptureError("camera:" + std::to_string(index) + ": index must be >= 0");
  return std::make_unique<CameraSource>(index, clock);
}

std::unique_ptr<CaptureSource> open_video(const fs::path& path, const contracts::Clock& clock) {
  return std::make_unique<VideoSource>(path, clock);
}

std::unique_ptr<CaptureSource> open_images(const fs::path& dir, const contracts::Clock& clock) {
  return std::make_unique<ImageFolderSource>(dir, clock);
}

std::unique_ptr<CaptureSource> open_source(std::string_view spec, const contracts::Clock& clock) {
  const auto colon = spec.find(':');
  const std::string quoted = "'" + std::string(spec) + "'";
  if (colon == std::string_view::npos) {
    throw CaptureError("source " + quoted + " has no scheme: " + std::string(kSpecHelp));
  }
  const auto scheme = spec.substr(0, colon);
  const auto rest = spec.substr(colon + 1);
  if (rest.empty()) {
    throw CaptureError("source " + quoted + " names nothing after '" + std::string(scheme) +
                       ":': " + std::string(kSpecHelp));
  }
  if (scheme == "camera") {
    int index = -1;
    const auto* end = rest.data() + rest.size();
    const auto [ptr, ec] = std::from_chars(rest.data(), end, index);
    if (ec != std::errc{} || ptr != end || index < 0) {
      throw CaptureError("source " + quoted +
                         ": the camera index must be a number >= 0, as "
                         "in camera:0");
    }
    return open_camera(index, clock);
  }
  if (scheme == "video") return open_video(fs::path(std::string(rest)), clock);
  if (scheme == "images") return open_images(fs::path(std::string(rest)), clock);
  throw CaptureError("source " + quoted + ": unknown scheme '" + std::string(scheme) +
                     "': " + std::string(kSpecHelp));
}

GeneratorSource::GeneratorSource(Generator generate, const contracts::Clock& clock,
                                 std::string name, bool live, PixelOrder order)
    : generate_(std::move(generate)),
      clock_(clock),
      name_(std::move(name)),
      live_(live),
      order_(order) {
  if (!generate_) throw std::invalid_argument("GeneratorSource '" + name_ + "': no generator");
}

std::optional<Frame> GeneratorSource::next() {
  if (ended_) return std::nullopt;
  std::optional<cv::Mat> pixels;
  try {
    pixels = generate_(next_id_);
  } catch (const CaptureError&) {
    throw;
  } catch (const std::exception& e) {
    throw CaptureError(name_ + ": the generator failed at frame " + std::to_string(next_id_) +
                       ": " + e.what());
  }
  if (!pixels) {
    ended_ = true;
    return std::nullopt;
  }
  check_pixels(*pixels, name_);
  return stamp(std::move(*pixels), next_id_++, clock_, name_, order_);
}

}  // namespace gbdcs::vision
