// `gbdcs fly`: a flight driven by a scripted gesture timeline through the production core
// (GestureEngine, CommandTranslator, CommandArbiter, FailsafeMonitor) on an adapter, printing
// every gesture, command, alert and telemetry line, and recording the session in SQLite.
#include <filesystem>
#include <iostream>
#include <memory>
#include <thread>

#include "commands.hpp"
#include "drone_factory.hpp"
#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/gesture/gesture_engine.hpp"
#include "gbdcs/gesture/rule_based_recognizer.hpp"
#include "gbdcs/runtime/control_loop.hpp"
#include "gbdcs/runtime/listeners.hpp"
#include "gbdcs/sim/gesture_timeline.hpp"
#include "gbdcs/storage/storage_manager.hpp"

namespace gbdcs::app {
namespace {

struct FlyOptions {
  std::string timeline = "fixtures/timelines/demo_flight.json";
  std::string adapter = "dummy";
  std::string adapter_options;  // JSON object text (docs/ADAPTERS.md)
  std::string profile;
  std::string db = "var/gbdcs.db";
  bool no_db = false;
  bool realtime = false;
  bool json = false;
  bool require_landed = false;
  double settle_s = 0;
  int telemetry_every = 1;
};

// Prints every Nth telemetry frame, everything else as is.
class ThinningConsole final : public runtime::EventListener {
 public:
  ThinningConsole(runtime::ConsoleOptions options, int every)
      : console_(std::cout, options), every_(std::max(every, 1)) {}
  void on_gesture(const contracts::GestureEvent& e) override { console_.on_gesture(e); }
  void on_command(const contracts::DroneCommand& c, const std::string& o) override {
    console_.on_command(c, o);
  }
  void on_alert(const contracts::Alert& a) override { console_.on_alert(a); }
  void on_telemetry(const contracts::TelemetryFrame& f) override {
    if (count_++ % every_ == 0) console_.on_telemetry(f);
  }

 private:
  runtime::ConsoleListener console_;
  int every_;
  long count_ = 0;
};

// Counts what happened, for the summary line.
class Tally final : public runtime::EventListener {
 public:
  void on_gesture(const contracts::GestureEvent& e) override {
    if (!e.repeat) ++gestures;
  }
  void on_command(const contracts::DroneCommand&, const std::string& outcome) override {
    ++commands;
    if (outcome != "OK") ++not_ok;
  }
  void on_alert(const contracts::Alert&) override { ++alerts; }
  std::atomic<int> gestures{0}, commands{0}, not_ok{0}, alerts{0};
};

int run_fly(const FlyOptions& o) {
  auto timeline = sim::GestureTimeline::load_file(o.timeline);
  auto profile = o.profile.empty() ? control::GestureProfile::builtin_default()
                                   : control::GestureProfile::load_file(o.profile);

  // Simulated time starts at the real UTC now, so a recorded session carries today's date.
  contracts::ManualClock manual_clock(
      std::chrono::time_point_cast<std::chrono::milliseconds>(std::chrono::system_clock::now()));
  contracts::SteadyClock steady_clock;
  const contracts::Clock& clock =
      o.realtime ? static_cast<const contracts::Clock&>(steady_clock) : manual_clock;

  nlohmann::json adapter_options;
  if (!o.adapter_options.empty()) {
    adapter_options = nlohmann::json::parse(o.adapter_options, nullptr, false);
    if (adapter_options.is_discarded() || !adapter_options.is_object()) {
      throw std::invalid_argument("--adapter-options must be a JSON object, e.g. "
                                  "'{\"address\": \"192.168.10.1\"}'");
    }
  }
  auto adapter = make_drone(o.adapter, clock, adapter_options);
  gesture::GestureEngine engine(clock, std::make_unique<gesture::RuleBasedRecognizer>());
  control::CommandTranslator translator(profile);
  runtime::ControlLoop loop(clock, *adapter, engine, translator);

  std::unique_ptr<storage::StorageManager> storage;
  std::int64_t session_id = 0;
  if (!o.no_db) {
    storage::StorageOptions so;
    so.path = o.db;
    storage = std::make_unique<storage::StorageManager>(so, clock);
    storage->end_open_sessions();
    const auto retention = storage->apply_retention();
    if (retention.sessions_deleted > 0 || retention.telemetry_rows_deleted > 0) {
      std::cout << "gbdcs fly: retention removed " << retention.sessions_deleted
                << " old sessions and " << retention.telemetry_rows_deleted
                << " old telemetry rows from " << o.db << "\n";
    }
    session_id = storage->begin_session(std::nullopt, o.adapter, profile.name);
    loop.add_listener(std::make_shared<runtime::StorageListener>(
        *storage, session_id, [](const std::string& e) { std::cerr << e << "\n"; }));
  }
  runtime::ConsoleOptions console;
  console.json = o.json;
  loop.add_listener(std::make_shared<ThinningConsole>(console, o.telemetry_every));
  auto tally = std::make_shared<Tally>();
  loop.add_listener(tally);

  if (!o.json) {
    std::cout << "gbdcs fly: timeline '" << timeline.name() << "' (" << timeline.duration_s()
              << " s at " << timeline.fps() << " fps) on the " << adapter->name() << " drone, "
              << (o.realtime ? "real time" : "simulated time") << "\n";
  }
  if (auto r = loop.start(); r != control::Result::kOk) {
    std::cerr << "gbdcs fly: cannot connect to the " << o.adapter
              << " drone: " << control::to_string(r) << " " << adapter->last_error() << "\n";
    return 1;
  }

  const auto frame_period = contracts::from_seconds(1.0 / timeline.fps());
  const auto frames = timeline.frame_count();
  const auto settle_frames = static_cast<std::size_t>(o.settle_s * timeline.fps());
  const auto wall_start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < frames + settle_frames; ++i) {
    if (o.realtime) {
      std::this_thread::sleep_until(wall_start + frame_period * static_cast<long>(i + 1));
    } else {
      manual_clock.advance(frame_period);
    }
    std::optional<contracts::Landmarks> hand;
    if (i < frames) hand = timeline.next_frame().hand;
    loop.on_frame(hand, static_cast<std::int64_t>(i));
    loop.tick();
    // In simulated time the console must not fall behind and drop lines.
    if (!o.realtime) loop.telemetry().drain(std::chrono::seconds(2));
  }
  loop.telemetry().drain(std::chrono::seconds(2));
  const auto last = loop.latest_telemetry();
  loop.stop();
  if (storage) storage->end_session(session_id);

  const bool landed = last && (last->flight_state == contracts::FlightState::kReady ||
                               last->flight_state == contracts::FlightState::kInit);
  if (!o.json) {
    std::cout << "gbdcs fly: done: " << tally->gestures << " gestures, " << tally->commands
              << " commands (" << tally->not_ok << " not executed), " << tally->alerts
              << " alerts; drone " << (last ? contracts::to_string(last->flight_state) : "?")
              << (storage ? "; session " + std::to_string(session_id) + " in " + o.db : "")
              << "\n";
  }
  if (o.require_landed && !landed) {
    std::cerr << "gbdcs fly: the drone did not end on the ground (--require-landed)\n";
    return 3;
  }
  return 0;
}

}  // namespace

void add_fly_command(CLI::App& app) {
  static FlyOptions o;
  auto* cmd = app.add_subcommand(
      "fly",
      "Fly a drone from a scripted gesture timeline through the real engine, translator, "
      "arbiter and failsafes; prints every command and telemetry line");
  cmd->add_option("--timeline", o.timeline, "Gesture timeline JSON (docs/TIMELINES.md)")
      ->capture_default_str();
  cmd->add_option("--adapter", o.adapter, "Drone adapter")->capture_default_str();
  cmd->add_option("--adapter-options", o.adapter_options,
                  "The adapter's options as a JSON object (docs/ADAPTERS.md), e.g. "
                  "'{\"address\": \"127.0.0.1\"}' for a Tello emulated by `gbdcs twin --tello`");
  cmd->add_option("--profile", o.profile, "Gesture profile JSON (default: the built-in one)");
  cmd->add_option("--db", o.db, "SQLite database for the session log")->capture_default_str();
  cmd->add_flag("--no-db", o.no_db, "Do not record the session");
  cmd->add_flag("--realtime", o.realtime, "Pace the flight with the wall clock");
  cmd->add_flag("--json", o.json, "Print one JSON document per line");
  cmd->add_option("--settle", o.settle_s, "Seconds to keep running after the timeline ends")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 600.0));
  cmd->add_option("--telemetry-every", o.telemetry_every, "Print every Nth telemetry frame")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_flag("--require-landed", o.require_landed,
                "Exit 3 unless the drone is on the ground at the end");
  cmd->callback([] {
    try {
      g_exit_code = run_fly(o);
    } catch (const std::exception& e) {
      std::cerr << "gbdcs fly: " << e.what() << "\n";
      g_exit_code = 2;
    }
  });
}

}  // namespace gbdcs::app
