// Capture sources: OpenCV camera and video file, a sorted folder of images, a generator.
#include "gbdcs/vision/capture.hpp"
#include "gbdcs/vision/source_option.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <thread>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

namespace gbdcs::vision {

std::optional<double> number_option(std::string_view option, std::string_view name) {
  if (option.size() <= name.size() || option.substr(0, name.size()) != name ||
      option[name.size()] != '=') {
    return std::nullopt;
  }
  const std::string value(option.substr(name.size() + 1));
  try {
    std::size_t used = 0;
    const double v = std::stod(value, &used);
    if (used != value.size()) return std::nullopt;
    return v;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}
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

// A video file as a camera: frame k (counting over every loop) is due at start + k/fps; a
// frame whose time has passed is grabbed (decoded, not converted) and skipped; the end of the
// file reopens it. The frame count is the file's own figure, corrected by the first short read.
class LiveVideoSource final : public CaptureSource {
 public:
  LiveVideoSource(const fs::path& path, const contracts::Clock& clock, double fps,
                  std::string name)
      : clock_(clock),
        name_(name.empty() ? "video:" + path.string() + "?live=1" : std::move(name)),
        path_(path.string()) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      throw CaptureError(name_ + ": no such file (check the path; it is relative to " +
                         fs::current_path(ec).string() + ")");
    }
    open();
    fps_ = fps > 0 ? fps : capture_.get(cv::CAP_PROP_FPS);
    if (!(fps_ > 0 && fps_ <= 1000)) {
      throw CaptureError(name_ + ": the file does not say its frame rate; give it as " +
                         "video:PATH?live=1&fps=30");
    }
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    count_ = count >= 1 ? static_cast<std::int64_t>(count) : 0;
  }
  std::optional<Frame> next() override {
    if (!started_) {
      started_ = true;
      start_ = clock_.now();
    }
    std::int64_t want = last_ + 1;
    const auto due = start_ + contracts::from_seconds(static_cast<double>(want) / fps_);
    const auto now = clock_.now();
    if (due > now) {
      std::this_thread::sleep_for(due - now);
    } else {
      const auto behind =
          static_cast<std::int64_t>(std::floor(contracts::to_seconds(now - start_) * fps_));
      want = std::max(want, behind);
    }
    last_ = want;
    cv::Mat pixels = read_at(want);
    check_pixels(pixels, name_);
    return stamp(std::move(pixels), next_id_++, clock_, name_, PixelOrder::kBgr);
  }
  bool live() const override { return true; }
  std::string describe() const override { return name_; }

 private:
  void open() {
    capture_.release();
    if (!capture_.open(path_, video_file_api()) || !capture_.isOpened()) {
      throw CaptureError(name_ + ": OpenCV cannot decode this file (is it a video? convert it " +
                         "with `ffmpeg -i " + path_ + " out.mp4`)");
    }
    position_ = 0;
  }
  // The frame at loop position `index % count`, reading forward from where the file is.
  cv::Mat read_at(std::int64_t index) {
    for (int attempt = 0; attempt < 3; ++attempt) {
      const std::int64_t local = count_ > 0 ? index % count_ : index;
      if (local < position_) open();
      bool ok = true;
      while (ok && position_ < local) {
        ok = capture_.grab();
        if (ok) ++position_;
      }
      cv::Mat pixels;
      if (ok && capture_.read(pixels) && !pixels.empty()) {
        ++position_;
        return pixels;
      }
      // The file is shorter than it said (or than `index`): that is its length.
      if (position_ == 0) break;
      count_ = position_;
      open();
    }
    throw CaptureError(name_ + ": no frame could be read (an empty or damaged video?)");
  }

  const contracts::Clock& clock_;
  std::string name_;
  std::string path_;
  cv::VideoCapture capture_;
  double fps_ = 0;
  std::int64_t count_ = 0;     // frames in the file; 0 = not known yet
  std::int64_t position_ = 0;  // index of the next frame the decoder gives
  bool started_ = false;
  contracts::Duration start_{};
  std::int64_t last_ = -1;  // the frame index (over all loops) delivered last
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

// video:PATH or video:PATH?live=1[&fps=N]. A path that exists as given wins over options.
std::unique_ptr<CaptureSource> open_video_spec(const std::string& rest, const std::string& spec,
                                               const contracts::Clock& clock) {
  std::error_code ec;
  const auto q = rest.rfind('?');
  if (q == std::string::npos || fs::exists(rest, ec)) return open_video(rest, clock);
  bool live = false;
  double fps = 0;
  std::string query = rest.substr(q + 1);
  for (std::size_t start = 0; start <= query.size();) {
    const auto amp = std::min(query.find('&', start), query.size());
    const std::string option = query.substr(start, amp - start);
    start = amp + 1;
    if (option == "live=1" || option == "live=true") {
      live = true;
    } else if (option.rfind("fps=", 0) == 0) {
      fps = number_option(option, "fps").value_or(-1);
      if (!(fps > 0 && fps <= 1000)) {
        throw CaptureError("source '" + spec + "': fps must be a number from 0 to 1000, as in fps=30");
      }
    } else if (option != "live=0" && option != "live=false") {
      throw CaptureError("source '" + spec + "': unknown option \"" + option +
                         "\"; the options are live=1 and fps=N (with live=1)");
    }
  }
  const fs::path path = rest.substr(0, q);
  if (!live) {
    if (fps > 0) throw CaptureError("source '" + spec + "': fps=N needs live=1");
    return open_video(path, clock);
  }
  return open_live_video(path, clock, fps, spec);
}

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

std::unique_ptr<CaptureSource> open_live_video(const fs::path& path, const contracts::Clock& clock,
                                               double fps, std::string name) {
  return std::make_unique<LiveVideoSource>(path, clock, fps, std::move(name));
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
  if (scheme == "video") return open_video_spec(std::string(rest), std::string(spec), clock);
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
