// Vision subcommands: `vision` (the worker: pipeline -> JSON lines), `recognize` (hands and
// gestures in images or videos), `eval landmarks` (ours against the MediaPipe reference).
// `bench vision` is in vision_bench_command.cpp.
#include <atomic>
#include <csignal>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "command_registry.hpp"
#include "commands.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/contracts/json_file.hpp"
#include "fixture_support.hpp"
#include "gbdcs/vision/feed_tap.hpp"
#include "gbdcs/vision/model_files.hpp"
#include "gbdcs/vision/vision_messages.hpp"
#include "gbdcs/vision/vision_pipeline.hpp"
#include "source_factory.hpp"
#include "vision_publish.hpp"
#include "vision_support.hpp"
#include "ws_publisher.hpp"

namespace gbdcs::app {
namespace {

using nlohmann::json;

std::atomic<bool> g_interrupted{false};
void on_signal(int) {
  g_interrupted = true;
}

// OpenCV's own warnings (backends it tried) would bury our one clear message.
void quiet_opencv() {
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
}

// ---- gbdcs vision -----------------------------------------------------------------------
struct VisionOptions {
  std::string source;
  ModelChoice models;
  std::string publish;
  std::string options_file;
  double heartbeat_s = 1.0;
  bool publish_jpeg = false;
  int jpeg_width = 480;
};

int run_vision(const VisionOptions& o) {
  // --publish: the same messages as WebSocket text messages to the server (INTERFACES.md 2).
  std::unique_ptr<WsPublisher> publisher;
  if (!o.publish.empty()) publisher = std::make_unique<WsPublisher>(o.publish);
  std::mutex out_mutex;
  std::atomic<bool> publish_failed{false};
  auto emit = [&](const json& doc) {
    std::lock_guard lock(out_mutex);
    if (!publisher) {
      std::cout << doc.dump() << '\n' << std::flush;
      return;
    }
    try {
      publisher->send(doc.dump());
    } catch (const std::exception& e) {
      if (!publish_failed.exchange(true)) std::cerr << "gbdcs vision: " << e.what() << "\n";
      g_interrupted = true;
    }
  };
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  if (o.source.rfind("timeline:", 0) == 0) {
    run_timeline_worker(o.source, o.heartbeat_s, emit, g_interrupted);
    return publish_failed ? 1 : 0;
  }
  quiet_opencv();
  contracts::SteadyClock clock;
  vision::PipelineOptions options;
  if (!o.options_file.empty())
    options = vision::pipeline_options_from_json(
        contracts::read_json_file<std::runtime_error>(o.options_file, "pipeline options file"));
  std::unique_ptr<vision::CaptureSource> source;
  std::unique_ptr<vision::HandFinder> finder;
  // While a recipe camera's video is rendered into the cache (once): heartbeats that say so,
  // not healthy (no take-off), so the supervisor knows the worker is alive.
  auto last_note = clock.now() - contracts::from_seconds(o.heartbeat_s);
  auto preparing = [&](std::int64_t done, std::int64_t total) {
    if (clock.now() - last_note < contracts::from_seconds(o.heartbeat_s) && done < total) return;
    last_note = clock.now();
    const auto m = vision::metrics_before_start(
        options, o.source, true,
        "preparing the camera: rendering its video once into " + fixture_cache_dir().string() +
            " (" + std::to_string(done) + " of " + std::to_string(total) + " frames)");
    emit(vision::heartbeat_message(m, clock.utc_now()));
  };
  // The camera or the models cannot be opened: exit 2, and a server is told why in a last
  // heartbeat (it shows that, not only that the worker's socket closed).
  auto cannot_start = [&](const std::exception& e) {
    std::cerr << "gbdcs vision: " << e.what() << "\n";
    if (publisher) {
      emit(vision::heartbeat_message(
          vision::metrics_before_start(options, o.source, true, e.what()), clock.utc_now()));
    }
    return 2;
  };
  try {
    source = o.source.rfind("recipe:", 0) == 0 ? open_recipe_source(o.source, clock, preparing)
                                                : open_any_source(o.source, clock);
    if (o.publish_jpeg) {
      // The picture goes out at the camera's rate, apart from tracking (FeedTap's thread).
      const int width = o.jpeg_width;
      source = std::make_unique<vision::FeedTap>(std::move(source), [&emit, width](const vision::Frame& f) {
        emit(picture_message(f, width, 70));
      });
    }
    // A folder holds unrelated stills: detect in each (MediaPipe's static image mode).
    const bool stills = o.source.rfind("images:", 0) == 0;
    finder = vision::make_tracker_finder(tracker_options(o.models, stills), clock);
  } catch (const vision::CaptureError& e) {
    return cannot_start(e);
  } catch (const vision::ModelError& e) {
    return cannot_start(e);
  }

  vision::VisionPipeline pipeline(
      std::move(source), std::move(finder), clock,
      [&](const vision::FrameResult& r) { emit(vision::frame_message(r)); },
      options);

  pipeline.start();
  const auto period = contracts::from_seconds(o.heartbeat_s);
  auto next_beat = clock.now() + period;
  bool finished = false;
  while (!finished && !g_interrupted) {
    finished = pipeline.wait_for(std::chrono::milliseconds(50));
    if (clock.now() >= next_beat) {
      emit(vision::heartbeat_message(pipeline.metrics(), clock.utc_now()));
      next_beat += period;
    }
  }
  pipeline.stop();
  const auto m = pipeline.metrics();
  emit(vision::heartbeat_message(m, clock.utc_now()));
  if (!m.healthy) {
    std::cerr << "gbdcs vision: " << m.reason << "\n";
    return 1;
  }
  return 0;
}

// ---- gbdcs recognize ----------------------------------------------------------------------
struct RecognizeOptions {
  std::vector<std::string> files;
  bool json = false;
  ModelChoice models;
};

constexpr const char* kLandmarkNames[contracts::kLandmarkCount] = {
    "wrist",     "thumb_cmc", "thumb_mcp",  "thumb_ip",   "thumb_tip",  "index_mcp",  "index_pip",
    "index_dip", "index_tip", "middle_mcp", "middle_pip", "middle_dip", "middle_tip", "ring_mcp",
    "ring_pip",  "ring_dip",  "ring_tip",   "pinky_mcp",  "pinky_pip",  "pinky_dip",  "pinky_tip"};

void print_text(const vision::RecognizedImage& r, bool video) {
  std::cout << r.image;
  if (video) std::cout << " frame " << r.frame;
  std::cout << " (" << r.width << "x" << r.height << "): " << r.hands.size()
            << (r.hands.size() == 1 ? " hand\n" : " hands\n");
  for (std::size_t i = 0; i < r.hands.size(); ++i) {
    const auto& h = r.hands[i];
    std::cout << std::fixed << std::setprecision(3) << "  hand " << i << ": "
              << contracts::to_string(h.landmarks.handedness) << ", presence " << h.landmarks.score
              << ", gesture " << contracts::to_string(h.gesture) << " (" << h.confidence << ")\n";
    for (std::size_t k = 0; k < contracts::kLandmarkCount; ++k) {
      const auto& p = h.landmarks.points[k];
      std::cout << std::setprecision(4) << "    " << std::setw(2) << k << " " << std::left
                << std::setw(11) << kLandmarkNames[k] << std::right << " x " << p.x << "  y " << p.y
                << "  z " << std::showpos << p.z << std::noshowpos << "\n";
    }
  }
  std::cout.unsetf(std::ios::floatfield);
}

vision::RecognizedImage recognize_frame(vision::HandFinder& finder,
                                        vision::HandClassifier& classifier, const cv::Mat& bgr,
                                        const std::string& name, std::int64_t frame) {
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  vision::RecognizedImage r;
  r.image = name;
  r.frame = frame;
  r.width = rgb.cols;
  r.height = rgb.rows;
  classifier.set_frame_size(rgb.cols, rgb.rows);
  r.hands = classifier.classify(finder.find(rgb));
  return r;
}

int run_recognize(const RecognizeOptions& o) {
  quiet_opencv();
  contracts::SteadyClock clock;
  std::unique_ptr<vision::HandFinder> stills;  // static image mode, made when first needed
  std::unique_ptr<vision::HandFinder> video;   // tracking mode, reset for each video
  vision::HandClassifier classifier;
  json all = json::array();
  int failures = 0;
  auto out = [&](const vision::RecognizedImage& r, bool is_video) {
    if (o.json) {
      all.push_back(vision::to_json(r));
    } else {
      print_text(r, is_video);
    }
  };
  for (const auto& file : o.files) {
    try {
      if (is_source_spec(file)) {  // camera:N, video:PATH, images:DIR, recipe:PATH
        auto source = open_any_source(file, clock);
        const bool still_frames = file.rfind("images:", 0) == 0;
        auto finder = vision::make_tracker_finder(tracker_options(o.models, still_frames), clock);
        while (auto frame = source->next()) {
          cv::Mat bgr = frame->rgb;
          if (frame->order == vision::PixelOrder::kRgb) cv::cvtColor(frame->rgb, bgr, cv::COLOR_RGB2BGR);
          out(recognize_frame(*finder, classifier, bgr, file, frame->frame_id), true);
        }
        continue;
      }
      if (std::error_code ec; !std::filesystem::is_regular_file(file, ec)) {
        throw std::runtime_error("no such file (check the path)");
      }
      if (vision::is_image_file(file)) {
        cv::Mat bgr = cv::imread(file, cv::IMREAD_COLOR);
        if (bgr.empty())
          throw vision::CaptureError("cannot decode the image (damaged, or not an image?)");
        if (!stills) stills = vision::make_tracker_finder(tracker_options(o.models, true), clock);
        out(recognize_frame(*stills, classifier, bgr, file, 0), false);
        continue;
      }
      auto source = vision::open_video(file, clock);
      if (!video) video = vision::make_tracker_finder(tracker_options(o.models, false), clock);
      video->reset();
      while (auto frame = source->next()) {
        out(recognize_frame(*video, classifier, frame->rgb, file, frame->frame_id), true);
      }
    } catch (const vision::ModelError& e) {
      std::cerr << "gbdcs recognize: " << e.what() << "\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "gbdcs recognize: " << file << ": " << e.what() << "\n";
      ++failures;
    }
  }
  if (o.json) std::cout << all.dump(1) << "\n";
  return failures == 0 ? 0 : 1;
}

// ---- gbdcs eval landmarks ---------------------------------------------------------------
struct EvalOptions {
  std::string ours;
  std::string ref;
  bool json = false;
  double max_mean_pct = 1.5;
};

std::string pct(const std::optional<double>& v) {
  if (!v) return "-";
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << *v << " %";
  return s.str();
}

int run_eval_landmarks(const EvalOptions& o) {
  const auto ours = vision::recognized_from_json(
      contracts::read_json_file<std::runtime_error>(o.ours, "landmarks file"));
  const auto ref = vision::recognized_from_json(
      contracts::read_json_file<std::runtime_error>(o.ref, "reference landmarks file"));
  const auto c = vision::compare_landmarks(ours, ref);
  const bool detection_ok = c.hands_only_ours == 0 && c.hands_only_ref == 0;
  const bool accuracy_ok = !c.mean_distance_pct || *c.mean_distance_pct <= o.max_mean_pct;
  const bool pass = detection_ok && accuracy_ok && !c.images.empty();
  if (o.json) {
    auto doc = vision::to_json(c);
    doc["max_mean_pct"] = o.max_mean_pct;
    doc["pass"] = pass;
    std::cout << doc.dump(1) << "\n";
  } else {
    for (const auto& i : c.images) {
      std::cout << std::left << std::setw(40) << i.image << std::right << " hands ours "
                << i.hands_ours << " ref " << i.hands_ref << "  mean distance " << std::setw(8)
                << pct(i.mean_distance_pct) << (i.detection_agrees ? "" : "  DETECTION DIFFERS")
                << "\n";
    }
    for (const auto& k : c.only_in_ref) std::cout << k << ": only in " << o.ref << "\n";
    for (const auto& k : c.only_in_ours) std::cout << k << ": only in " << o.ours << "\n";
    std::cout << "images compared " << c.images.size() << ", detection agrees on "
              << c.images_detection_agree << "; hands matched " << c.hands_matched << ", missed "
              << c.hands_only_ref << ", extra " << c.hands_only_ours << "\nmean landmark distance "
              << pct(c.mean_distance_pct) << " (limit " << o.max_mean_pct << " %), worst hand "
              << pct(c.max_distance_pct) << ", worst landmark " << pct(c.max_landmark_distance_pct)
              << " of the hand's "
              << "bounding-box diagonal\n"
              << (pass ? "PASS" : "FAIL") << "\n";
  }
  return pass ? 0 : 1;
}

// Runs `body`, turning an exception into a message and exit code 2.
void guarded(const char* name, const std::function<int()>& body) {
  try {
    g_exit_code = body();
  } catch (const std::exception& e) {
    std::cerr << "gbdcs " << name << ": " << e.what() << "\n";
    g_exit_code = 2;
  }
}

}  // namespace

void add_vision_commands(CLI::App& app) {
  static VisionOptions v;
  auto* vision_cmd = app.add_subcommand(
      "vision",
      "Run the vision pipeline (capture -> landmarks -> gesture) on a camera, video or image "
      "folder; prints JSON lines: a frame message per frame, a heartbeat every second");
  vision_cmd->add_option("--source", v.source, "camera:N, video:PATH[?live=1], images:DIR, recipe:PATH[?live=1] or tello:[ADDRESS][?...] (a Tello's own camera; docs/ADAPTERS.md)")->required();
  add_model_options(vision_cmd, v.models);
  vision_cmd->add_option("--publish", v.publish,
                         "Send the messages to a WebSocket instead of stdout: "
                         "ws://127.0.0.1:PORT/worker?secret=S (what gbdcs serve passes)");
  vision_cmd->add_flag("--publish-jpeg", v.publish_jpeg,
                       "Also send each captured frame for the live feed as a picture message "
                       "(downscaled base64 JPEG), at the camera's rate, apart from tracking");
  vision_cmd->add_option("--jpeg-width", v.jpeg_width, "Width of that JPEG, px")
      ->capture_default_str()
      ->check(CLI::Range(64, 1920));
  vision_cmd->add_option("--options", v.options_file,
                         "PipelineOptions JSON (queue_capacity, policy, resize_width, ...; "
                         "docs/VISION.md)");
  vision_cmd->add_option("--heartbeat", v.heartbeat_s, "Seconds between heartbeats")
      ->capture_default_str()
      ->check(CLI::Range(0.05, 60.0));
  vision_cmd->callback([] { guarded("vision", [] { return run_vision(v); }); });

  static RecognizeOptions r;
  auto* recognize = app.add_subcommand(
      "recognize",
      "Find hands in images (each on its own) or videos (tracked frame to frame): 21 "
      "landmarks, handedness, presence and the recognised gesture");
  recognize->add_option("FILES", r.files, "Images (.jpg .png ...), videos, or source specs (video:PATH, images:DIR, recipe:PATH, camera:N)")->required();
  recognize->add_flag("--json", r.json, "One JSON array, an object per image or video frame");
  add_model_options(recognize, r.models);
  recognize->callback([] { guarded("recognize", [] { return run_recognize(r); }); });

  add_bench_vision_command(*group_command(app, "bench", "Benchmarks"));

  static EvalOptions e;
  auto* eval = group_command(app, "eval", "Compare results against a reference");
  auto* landmarks = eval->add_subcommand(
      "landmarks",
      "Compare two `recognize --json` files (ours, and the MediaPipe reference's): per image "
      "the mean landmark distance as % of the hand's bounding-box diagonal, and whether both "
      "found the same hands. Exit 0 when every hand agrees and the mean is within the limit");
  landmarks->add_option("OURS", e.ours, "Our recognize --json output")->required();
  landmarks->add_option("REF", e.ref, "The reference's output (mediapipe-reference/run)")
      ->required();
  landmarks->add_flag("--json", e.json, "One JSON object");
  landmarks
      ->add_option("--max-mean-pct", e.max_mean_pct,
                   "Limit on the overall mean distance, % of the bbox diagonal")
      ->capture_default_str();
  landmarks->callback([] { guarded("eval landmarks", [] { return run_eval_landmarks(e); }); });
}

}  // namespace gbdcs::app
