#include "gbdcs/sim/scenario_runner.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <opencv2/imgcodecs.hpp>

#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/control/command_translator.hpp"
#include "gbdcs/control/keyboard_input.hpp"
#include "gbdcs/gesture/gesture_engine.hpp"
#include "gbdcs/gesture/rule_based_recognizer.hpp"
#include "gbdcs/runtime/control_loop.hpp"
#include "gbdcs/sim/hand_pose.hpp"
#include "runner_parts.hpp"

namespace gbdcs::sim {

using detail::LoggedEvent;
using detail::VideoSnapshot;

namespace {

using WallClock = std::chrono::steady_clock;

// Records what the ControlLoop reports, stamped with simulated time. Gesture, command and
// alert callbacks come synchronously on the runner's thread; telemetry through an inline
// observer (the loop's listeners get it on a queue, which could drop frames).
class Recorder final : public runtime::EventListener {
 public:
  explicit Recorder(const contracts::Clock& clock) : clock_(clock) {}

  void on_gesture(const contracts::GestureEvent& e) override {
    std::lock_guard lock(mutex_);
    record_.gestures.push_back({now_s(), e});
    // The command this event makes is dispatched from this frame: time it from its capture.
    gesture_frame_start_ = frame_start_;
  }
  void on_command(const contracts::DroneCommand& c, const std::string& outcome) override {
    std::lock_guard lock(mutex_);
    RecordedCommand r{now_s(), c, outcome, -1};
    const bool dispatched =
        outcome.rfind("REFUSED", 0) != 0 && outcome.rfind("DROPPED", 0) != 0;
    if (c.source == contracts::CommandSource::kGesture && dispatched && gesture_frame_start_) {
      r.processing_ms =
          std::chrono::duration<double, std::milli>(WallClock::now() - *gesture_frame_start_)
              .count();
    }
    last_command_ = short_form(r) + " @" + std::to_string(r.t_s).substr(0, 5) + "s";
    record_.commands.push_back(std::move(r));
  }
  void on_alert(const contracts::Alert& a) override {
    std::lock_guard lock(mutex_);
    record_.alerts.push_back({now_s(), a});
    last_alert_ = std::string(contracts::to_string(a.severity)) + " " + a.code;
  }
  void on_frame_telemetry(const contracts::TelemetryFrame& f) {
    std::lock_guard lock(mutex_);
    record_.telemetry.push_back({now_s(), f});
    ++frames_taken_;  // the last inline observer: the failsafe has seen this frame too
  }
  std::uint64_t frames_taken() const {
    std::lock_guard lock(mutex_);
    return frames_taken_;
  }
  void frame_started(WallClock::time_point t) {
    std::lock_guard lock(mutex_);
    frame_start_ = t;
  }
  RunRecord take() {
    std::lock_guard lock(mutex_);
    return std::move(record_);
  }
  std::string last_command() const {
    std::lock_guard lock(mutex_);
    return last_command_;
  }
  std::string last_alert() const {
    std::lock_guard lock(mutex_);
    return last_alert_;
  }
  std::optional<contracts::TelemetryFrame> last_telemetry() const {
    std::lock_guard lock(mutex_);
    if (record_.telemetry.empty()) return std::nullopt;
    return record_.telemetry.back().frame;
  }

 private:
  double now_s() const { return contracts::to_seconds(clock_.now()); }

  const contracts::Clock& clock_;
  mutable std::mutex mutex_;
  RunRecord record_;
  std::optional<WallClock::time_point> frame_start_;
  std::optional<WallClock::time_point> gesture_frame_start_;
  std::string last_command_;
  std::string last_alert_;
  std::uint64_t frames_taken_ = 0;
};

nlohmann::json merged(nlohmann::json base, const nlohmann::json& over) {
  if (!over.is_object()) return base;
  for (const auto& [k, v] : over.items()) base[k] = v;
  return base;
}

struct Pending {
  double at_s;
  std::size_t event;
  bool starting;
};

}  // namespace

ScenarioResult run_scenario(const Scenario& s, const RunOptions& options) {
  const auto wall_start = WallClock::now();
  ScenarioResult result;
  result.name = s.name;
  result.path = s.path;
  result.description = s.description;
  result.drone = std::string(to_string(s.drone.kind));
  result.camera = std::string(to_string(s.camera.kind));

  contracts::ManualClock clock;
  auto model = detail::shared_twin_model();
  auto drone = detail::make_scenario_drone(s, clock, model);
  detail::CameraOptions camera_options;
  camera_options.fixture_cache_dir = options.fixture_cache_dir;
  camera_options.full_model = options.model != "lite";
  camera_options.model_dir = options.model_dir;
  auto camera = detail::open_scenario_camera(s.camera, camera_options);
  result.camera = camera->describe();

  gesture::GestureEngine engine(clock, std::make_unique<gesture::RuleBasedRecognizer>());
  control::CommandTranslator translator(control::GestureProfile::from_json(s.profile));
  runtime::ControlLoopOptions loop_options;
  loop_options.failsafe =
      telemetry::FailsafeOptions::from_json(merged(s.failsafe, options.failsafe_override));
  runtime::ControlLoop loop(clock, drone->adapter(), engine, translator, loop_options);
  auto recorder = std::make_shared<Recorder>(clock);
  loop.add_listener(recorder);
  loop.telemetry().subscribe(
      telemetry::make_observer("scenario",
                               [recorder](const contracts::TelemetryFrame& f) {
                                 recorder->on_frame_telemetry(f);
                               }),
      telemetry::Delivery::kInline);
  drone->count_frames_taken([recorder] { return recorder->frames_taken(); });

  std::vector<LoggedEvent> logged;
  std::vector<VideoSnapshot> video;
  auto segments = camera->segments();
  const bool want_video = !options.artifacts_dir.empty();
  const double video_period_s = 1.0 / options.video_fps;
  double next_video_s = 0;

  double t_s = 0;
  if (auto r = loop.start(); r != control::Result::kOk) {
    result.error = "cannot connect to the " + drone->describe() + " drone: " +
                   std::string(control::to_string(r)) + " " + drone->adapter().last_error();
    return result;
  }
  // A drone behind sockets: lockstep means nothing in flight whenever the clock moves.
  std::string link_error;
  auto in_step = [&](bool ok) {
    if (!ok && link_error.empty()) {
      link_error = drone->settle_error() + " at " + std::to_string(t_s).substr(0, 6) + " s";
    }
    return ok;
  };
  in_step(drone->settle());

  std::vector<Pending> pending;
  for (std::size_t i = 0; i < s.events.size(); ++i) pending.push_back({s.events[i].at_s, i, true});
  std::size_t next_pending = 0;
  auto add_end = [&](std::size_t i) {
    const auto& e = s.events[i];
    if (e.duration_s == kForever) return;
    Pending p{e.at_s + e.duration_s, i, false};
    auto it = std::upper_bound(pending.begin() + static_cast<long>(next_pending), pending.end(), p,
                               [](const Pending& a, const Pending& b) { return a.at_s < b.at_s; });
    pending.insert(it, p);
  };

  bool vision_down = false;  // a crashed worker: no frames reach the core
  const control::KeyboardInput keyboard;
  const double fps = camera->fps();
  const auto steps = static_cast<std::int64_t>(std::floor(s.timeout_s * fps + 1e-9));
  for (std::int64_t i = 0; i <= steps && link_error.empty(); ++i) {
    t_s = static_cast<double>(i) / fps;
    clock.set(contracts::from_seconds(t_s));
    if (!in_step(drone->advance())) break;

    while (next_pending < pending.size() && pending[next_pending].at_s <= t_s + 1e-9) {
      const auto p = pending[next_pending++];
      const auto& e = s.events[p.event];
      logged.push_back({t_s, (p.starting ? "start " : "end ") + e.describe()});
      drone->on_event(e, p.starting);
      if (p.starting) add_end(p.event);
      switch (e.type) {
        case EventType::kVisionCrash:
          vision_down = p.starting;
          if (e.detected_at_exit) {
            loop.on_vision_health(!p.starting, p.starting ? "the vision worker exited (crash)"
                                                          : std::string());
          }
          break;
        case EventType::kVisionUnhealthy:
          loop.on_vision_health(!p.starting, p.starting ? e.reason : std::string());
          break;
        case EventType::kEmergencyStop:
          if (p.starting) loop.emergency_stop(e.source, "operator");
          break;
        case EventType::kKey:
          if (p.starting) {
            auto command = keyboard.command_for(e.key);
            if (command && command->type == contracts::CommandType::kEmergencyStop) {
              loop.emergency_stop(contracts::CommandSource::kKeyboard, command->source_id);
            } else if (command) {
              command->issued_at = clock.utc_now();
              loop.submit(*command);
            }
          }
          break;
        default: break;
      }
    }

    const auto capture = WallClock::now();
    recorder->frame_started(capture);
    auto frame = camera->next();
    if (!vision_down) {
      loop.on_frame(frame.hand, i);
      for (auto& seg : segments) {
        if (t_s >= seg.start_s && t_s < seg.end_s) ++seg.frames_shown;
      }
    }
    loop.tick();
    if (!in_step(drone->settle())) break;

    if (want_video && t_s + 1e-9 >= next_video_s) {
      next_video_s += video_period_s;
      VideoSnapshot v;
      v.t_s = t_s;
      v.qpos = drone->pose_qpos();
      v.telemetry = recorder->last_telemetry();
      v.hand = frame.hand;
      v.label = frame.label;
      v.last_command = recorder->last_command();
      v.last_alert = recorder->last_alert();
      v.vision_down = vision_down;
      if (!frame.image.empty()) cv::imencode(".jpg", frame.image, v.jpeg);
      video.push_back(std::move(v));
    }
  }
  loop.telemetry().drain(std::chrono::seconds(5));
  auto collisions = drone->collisions();
  loop.stop();

  auto record = recorder->take();
  record.segments = std::move(segments);
  record.collisions = collisions;
  record.end_s = t_s;
  for (const auto& [gesture, mapping] : translator.profile().mappings) {
    record.mapped_gestures.push_back(gesture);
  }
  result.sim_s = t_s;
  result.criteria = evaluate_all(s, record);
  result.passed = std::none_of(result.criteria.begin(), result.criteria.end(),
                               [](const auto& c) { return c.verdict == Verdict::kFailure; });
  if (!link_error.empty()) {  // the run stopped early: its criteria say little
    result.error = link_error;
    result.passed = false;
  }

  if (want_video && (options.artifacts_always || !result.passed)) {
    const auto dir = (std::filesystem::path(options.artifacts_dir) / s.name).string();
    try {
      result.artifacts = detail::write_artifacts(dir, s, record, logged, video,
                                                 options.video_fps, *model);
    } catch (const std::exception& e) {
      result.error = "artifacts: " + std::string(e.what());
    }
  }
  if (options.keep_record) result.record = std::move(record);
  result.wall_s = std::chrono::duration<double>(WallClock::now() - wall_start).count();
  return result;
}

ScenarioResult run_scenario_file(const std::string& path, const RunOptions& options) {
  Scenario s;
  try {
    s = Scenario::load_file(path);
  } catch (const std::exception& e) {
    ScenarioResult r;
    r.name = std::filesystem::path(path).stem().string();
    r.path = path;
    r.error = e.what();
    return r;
  }
  try {
    return run_scenario(s, options);
  } catch (const std::exception& e) {
    ScenarioResult r;
    r.name = s.name;
    r.path = path;
    r.description = s.description;
    r.error = path + ": cannot run: " + e.what();
    return r;
  }
}

}  // namespace gbdcs::sim
