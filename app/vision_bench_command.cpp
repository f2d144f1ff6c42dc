// `gbdcs bench vision`: model load time, model invoke times, a tracking-mode frame, CPU of a
// live 30 FPS run through the whole pipeline, peak memory. Figures have their unit in the name.
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <thread>

#include "commands.hpp"
#include "gbdcs/gesture/gesture_engine.hpp"
#include "gbdcs/vision/hand_landmarker.hpp"
#include "gbdcs/vision/inference_runner.hpp"
#include "gbdcs/vision/vision_pipeline.hpp"
#include "vision_support.hpp"

namespace gbdcs::app {
namespace {

using nlohmann::json;
using vision::ModelKind;
using WallClock = std::chrono::steady_clock;  // app/ may read the OS clock

struct BenchOptions {
  bool json = false;
  int iterations = 100;
  std::string image;
  double live_s = 5;
  std::string model_dir;
};

double ms_since(WallClock::time_point t0) {
  return std::chrono::duration<double, std::milli>(WallClock::now() - t0).count();
}

// Nearest-rank percentile.
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size())));
  return v[std::clamp<std::size_t>(rank, 1, v.size()) - 1];
}

void add_stats(json& out, const std::string& name, const std::vector<double>& ms) {
  out[name + "_ms_p50"] = percentile(ms, 0.5);
  out[name + "_ms_p95"] = percentile(ms, 0.95);
}

std::string model_dir(const BenchOptions& o) {
  return o.model_dir.empty() ? vision::default_model_dir() : o.model_dir;
}

// The model alone: one thread, random input in [0, 1], a few warm-up runs.
std::vector<double> time_invoke(ModelKind kind, const BenchOptions& o) {
  auto model = vision::TfliteModel::from_file(vision::verified_model_path(kind, model_dir(o)));
  auto runner = vision::InferenceRunner::create(model, {1});
  std::mt19937 rng(1);
  for (std::size_t i = 0; i < runner->inputs().size(); ++i) {
    std::size_t n = 1;
    for (int d : runner->inputs()[i].shape) n *= static_cast<std::size_t>(d);
    float* data = runner->input_data(i);
    for (std::size_t k = 0; k < n; ++k) data[k] = static_cast<float>(rng() % 256) / 255.0f;
  }
  for (int i = 0; i < 5; ++i) runner->invoke();
  std::vector<double> ms;
  for (int i = 0; i < o.iterations; ++i) {
    const auto t0 = WallClock::now();
    runner->invoke();
    ms.push_back(ms_since(t0));
  }
  return ms;
}

// 640x480 BGR, as a camera would give it: the --image scaled, or seeded noise.
cv::Mat bench_frame(const BenchOptions& o) {
  if (!o.image.empty()) {
    cv::Mat img = cv::imread(o.image, cv::IMREAD_COLOR);
    if (img.empty()) throw std::runtime_error(o.image + ": cannot decode the image");
    cv::Mat out;
    cv::resize(img, out, cv::Size(640, 480), 0, 0, cv::INTER_AREA);
    return out;
  }
  cv::Mat noise(480, 640, CV_8UC3);
  cv::randu(noise, cv::Scalar::all(0), cv::Scalar::all(255));  // cv::theRNG: fixed seed
  return noise;
}

vision::TrackerOptions full_tracking(const BenchOptions& o) {
  ModelChoice m;
  m.model_dir = o.model_dir;
  return tracker_options(m, false);
}

// BGR -> RGB -> landmarks -> recogniser -> engine, the work of one tracked frame. With a hand
// in the frame the real tracker runs (detection once, then tracking); without one there is
// nothing to track, so the landmark model runs on a fixed ROI plus the next-ROI step, which
// is the same work the tracker does for a tracked hand.
void bench_tracking(const BenchOptions& o, const cv::Mat& bgr, json& out) {
  contracts::SteadyClock clock;
  vision::HandClassifier classifier;
  classifier.set_frame_size(bgr.cols, bgr.rows);
  gesture::GestureEngine engine(clock, std::make_unique<gesture::RuleBasedRecognizer>());
  vision::HandTracker tracker(full_tracking(o), clock);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  const bool has_hand = !tracker.process(rgb).empty();
  vision::HandLandmarker landmarker(
      vision::verified_model_path(ModelKind::kHandLandmarkFull, model_dir(o)), {1});
  const vision::RotatedRect roi{0.5, 0.5, 0.5 * 480 / 640, 0.5, 0};
  std::vector<double> ms;
  int detections = 0;
  for (int i = 0; i < o.iterations + 5; ++i) {
    const auto t0 = WallClock::now();
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    std::vector<contracts::Landmarks> hands;
    if (has_hand) {
      for (auto& h : tracker.process(rgb)) hands.push_back(h.landmarks);
      detections += tracker.last_timings().ran_detection ? 1 : 0;
    } else {
      hands.push_back(landmarker.run(rgb, roi).landmarks);
      (void)vision::landmarks_to_roi(hands.back().points, rgb.cols, rgb.rows);
    }
    const auto results = classifier.classify(hands);
    engine.process(hands.empty() ? std::nullopt : std::optional(hands.front()), i);
    if (i >= 5) ms.push_back(ms_since(t0));  // the first few warm up
  }
  add_stats(out, "tracking_frame", ms);
  out["tracking_frame_mode"] = has_hand ? "tracker" : "fixed_roi";
  out["tracking_frame_detections"] = detections;
}

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e6;
}

// The whole pipeline on a live source paced at 30 FPS; CPU = (user + sys) / wall.
void bench_live(const BenchOptions& o, const cv::Mat& bgr, json& out) {
  contracts::SteadyClock clock;
  const auto period = std::chrono::microseconds(33'333);
  WallClock::time_point start;
  auto source = std::make_unique<vision::GeneratorSource>(
      [&](std::int64_t id) -> std::optional<cv::Mat> {
        std::this_thread::sleep_until(start + period * id);
        return bgr.clone();  // a camera hands over a new buffer every frame
      },
      clock, "bench:30fps", /*live=*/true, vision::PixelOrder::kBgr);
  std::atomic<int> hands_seen{0};
  vision::VisionPipeline pipeline(std::move(source),
                                  vision::make_tracker_finder(full_tracking(o), clock), clock,
                                  [&](const vision::FrameResult& r) {
                                    if (!r.hands.empty()) ++hands_seen;
                                  });
  const double cpu0 = cpu_seconds();
  start = WallClock::now();
  pipeline.start();
  std::this_thread::sleep_for(std::chrono::duration<double>(o.live_s));
  const auto m = pipeline.metrics();
  const double wall_s = ms_since(start) / 1000;
  const double cpu_s = cpu_seconds() - cpu0;
  pipeline.stop();
  out["live_30fps_cpu_pct"] = 100 * cpu_s / wall_s;
  out["live_30fps_fps"] = m.fps;
  out["live_30fps_frames_done"] = m.frames_done;
  out["live_30fps_frames_dropped"] = m.frames_dropped;
  out["live_30fps_frames_with_hand"] = hands_seen.load();
  out["live_30fps_latency_ms_p95"] = m.latency.p95_ms;
  out["live_30fps_landmarks_ms_p95"] =
      m.stages[static_cast<std::size_t>(vision::Stage::kLandmarks)].p95_ms;
  out["live_seconds"] = wall_s;
  if (!m.healthy) out["live_30fps_unhealthy_reason"] = m.reason;
}

int run_bench_vision(const BenchOptions& o) {
  json out;
  out["iterations"] = o.iterations;
  out["threads"] = 1;
  out["frame"] = o.image.empty() ? "640x480 noise (no hand)" : "640x480 from " + o.image;
  {
    contracts::SteadyClock clock;
    const auto t0 = WallClock::now();
    vision::HandTracker tracker(full_tracking(o), clock);  // both full models: read, verify, plan
    out["model_load_ms"] = ms_since(t0);
  }
  add_stats(out, "palm_detection_full", time_invoke(ModelKind::kPalmDetectionFull, o));
  add_stats(out, "hand_landmark_full", time_invoke(ModelKind::kHandLandmarkFull, o));
  add_stats(out, "palm_detection_lite", time_invoke(ModelKind::kPalmDetectionLite, o));
  add_stats(out, "hand_landmark_lite", time_invoke(ModelKind::kHandLandmarkLite, o));
  const cv::Mat frame = bench_frame(o);
  bench_tracking(o, frame, out);
  if (o.live_s > 0) bench_live(o, frame, out);
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  out["max_rss_mb"] = static_cast<double>(u.ru_maxrss) / 1024.0;  // Linux: KiB
  if (o.json) {
    std::cout << out.dump() << "\n";
  } else {
    for (const auto& [key, value] : out.items()) {
      std::cout << std::left << std::setw(34) << key << std::right << " ";
      if (value.is_number_float()) {
        std::cout << std::fixed << std::setprecision(2) << value.get<double>() << "\n";
      } else {
        std::cout << (value.is_string() ? value.get<std::string>() : value.dump()) << "\n";
      }
    }
  }
  return 0;
}

}  // namespace

void add_bench_vision_command(CLI::App& bench) {
  static BenchOptions o;
  auto* cmd = bench.add_subcommand(
      "vision",
      "Time the hand models (1 thread), a tracking-mode frame, and a live 30 FPS pipeline run; "
      "report model load time, CPU use and peak memory");
  cmd->add_flag("--json", o.json, "One JSON object, units in the names");
  cmd->add_option("--iterations", o.iterations, "Timed runs per model and for the frame")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--image", o.image,
                  "A photo with a hand, scaled to 640x480, so the tracker really tracks "
                  "(default: noise, and the landmark model runs on a fixed ROI)");
  cmd->add_option("--live-seconds", o.live_s, "Length of the live 30 FPS run (0 = skip)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 600.0));
  cmd->add_option("--model-dir", o.model_dir, "Folder of the .tflite models");
  cmd->callback([] {
    try {
      g_exit_code = run_bench_vision(o);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs bench vision: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

}  // namespace gbdcs::app
