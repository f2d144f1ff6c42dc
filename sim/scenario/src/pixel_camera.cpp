// The scenario's pixel cameras: a fixture recipe (rendered once into the fixture cache, the
// folder `gbdcs eval --cache` uses) or a recorded fixture (video.mp4 + labels.json), decoded
// frame by frame and passed through the production vision stages: the capture source
// (vision::open_video), the preprocess stage's BGR -> RGB, the HandTracker (palm detector +
// landmark model, the HandFinder `gbdcs vision` runs) and the strongest-hand choice of the
// pipeline's classify stage and the server (highest presence). One frame per call, on the
// runner's thread: results do not depend on how fast the machine is.
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "gbdcs/contracts/json_file.hpp"
#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/sim/fixture_cache.hpp"
#include "gbdcs/sim/recipe.hpp"
#include "gbdcs/vision/capture.hpp"
#include "gbdcs/vision/hand_tracker.hpp"
#include "gbdcs/vision/vision_pipeline.hpp"
#include "runner_parts.hpp"

namespace gbdcs::sim::detail {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json read_labels(const std::string& path) {
  const json doc = contracts::read_json_file<std::invalid_argument>(path, "camera.labels file");
  const auto bad = [&](const std::string& what) {
    return std::invalid_argument("camera.labels: " + path + ": " + what +
                                 "; check it with `gbdcs fixture check FOLDER` (docs/FIXTURES.md)");
  };
  if (!doc.is_object() || doc.value("format", "") != "gbdcs-fixture-labels/1") {
    throw bad("not a fixture labels file (\"format\" is not \"gbdcs-fixture-labels/1\")");
  }
  if (!doc.contains("segments") || !doc["segments"].is_array() || doc["segments"].empty()) {
    throw bad("no \"segments\"");
  }
  if (!doc.contains("frames") || !doc["frames"].is_array()) throw bad("no \"frames\" array");
  for (std::size_t i = 0; i < doc["segments"].size(); ++i) {
    const auto& s = doc["segments"][i];
    if (!s.is_object() || !s.contains("start_s") || !s.contains("end_s") ||
        !s["start_s"].is_number() || !s["end_s"].is_number() || !s.contains("pose")) {
      throw bad("segments[" + std::to_string(i) + "] needs pose, start_s and end_s");
    }
  }
  return doc;
}

class PixelCamera final : public ScenarioCamera {
 public:
  PixelCamera(const std::string& video, const std::string& labels_path, double fps,
              std::string name, const CameraOptions& options)
      : labels_(read_labels(labels_path)), name_(std::move(name)) {
    const double labelled_fps = labels_.value("fps", 0.0);
    if (fps > 0 && labelled_fps > 0 && std::abs(fps - labelled_fps) > 1e-6) {
      throw std::invalid_argument("camera.fps: is " + std::to_string(fps) + " but " + labels_path +
                                  " says the video has " + std::to_string(labelled_fps) +
                                  " frames per second; remove camera.fps or make them agree");
    }
    fps_ = fps > 0 ? fps : labelled_fps;
    if (fps_ <= 0) {
      throw std::invalid_argument("camera.fps: " + labels_path +
                                  " gives no \"fps\"; set camera.fps to the video's frame rate");
    }
    try {
      source_ = vision::open_video(video, wall_);
    } catch (const std::exception& e) {
      throw std::invalid_argument("camera.video: " + std::string(e.what()));
    }
    vision::TrackerOptions t;
    t.full_model = options.full_model;
    t.model_dir = options.model_dir;
    finder_ = vision::make_tracker_finder(t, wall_);
  }

  double fps() const override { return fps_; }

  CameraFrame next() override {
    CameraFrame f;
    f.label = "NO_HAND";
    const auto& frames = labels_["frames"];
    const auto i = static_cast<std::size_t>(index_++);
    if (i < frames.size() && frames[i].is_object()) f.label = frames[i].value("pose", "NO_HAND");
    if (ended_) return f;
    auto frame = source_->next();
    if (!frame || frame->rgb.empty()) {
      ended_ = true;  // the hand is put down: no hand from here on
      return f;
    }
    cv::Mat rgb;
    if (frame->order == vision::PixelOrder::kBgr) {
      cv::cvtColor(frame->rgb, rgb, cv::COLOR_BGR2RGB);
      f.image = frame->rgb;
    } else {
      rgb = frame->rgb;
      cv::cvtColor(frame->rgb, f.image, cv::COLOR_RGB2BGR);
    }
    f.hand = vision::strongest_hand(finder_->find(rgb));
    return f;
  }

  std::vector<LabelledSegment> segments() const override {
    std::vector<LabelledSegment> out;
    for (const auto& s : labels_["segments"]) {
      LabelledSegment l;
      l.start_s = s["start_s"].get<double>();
      l.end_s = s["end_s"].get<double>();
      l.label = s["pose"].is_string() ? s["pose"].get<std::string>() : "NO_HAND";
      if (s.value("deliberate", false)) {
        l.gesture = contracts::gesture_from_string(s.value("gesture", "NONE"));
        if (l.gesture == contracts::GestureType::kNone) l.gesture.reset();
      }
      out.push_back(l);
    }
    return out;
  }

  std::string describe() const override { return name_; }

 private:
  contracts::SteadyClock wall_;  // the tracker's stage timings only; results never read it
  json labels_;
  std::string name_;
  double fps_ = 0;
  std::unique_ptr<vision::CaptureSource> source_;
  std::unique_ptr<vision::HandFinder> finder_;
  std::int64_t index_ = 0;
  bool ended_ = false;
};

}  // namespace

std::unique_ptr<ScenarioCamera> open_pixel_camera(const CameraSpec& spec,
                                                  const CameraOptions& options) {
  if (spec.kind == CameraKind::kRecipe) {
    const fs::path cache = options.fixture_cache_dir.empty() ? default_fixture_cache_dir()
                                                             : fs::path(options.fixture_cache_dir);
    fs::path dir;
    try {
      dir = cached_fixture(spec.path, cache);
    } catch (const RecipeError& e) {
      throw std::invalid_argument("camera.recipe: " + std::string(e.what()));
    }
    return std::make_unique<PixelCamera>(
        (dir / "video.mp4").string(), (dir / "labels.json").string(), 0,
        "recipe '" + fs::path(spec.path).stem().string() + "'", options);
  }
  return std::make_unique<PixelCamera>(spec.path, spec.labels_path, spec.fps,
                                       "video '" + spec.path + "'", options);
}

}  // namespace gbdcs::sim::detail
