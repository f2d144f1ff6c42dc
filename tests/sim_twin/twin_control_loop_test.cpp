// The production core (runtime::ControlLoop) flying the twin from a gesture timeline, wired
// exactly as with the dummy in tests/runtime/control_loop_test.cpp: the twin is just another
// adapter.
#include <gtest/gtest.h>

#include <algorithm>

#include "gbdcs/gesture/rule_based_recognizer.hpp"
#include "gbdcs/runtime/control_loop.hpp"
#include "gbdcs/sim/gesture_timeline.hpp"
#include "twin_test_support.hpp"

namespace gbdcs::sim {
namespace {

using contracts::FlightState;

struct Recorder final : runtime::EventListener {
  void on_command(const contracts::DroneCommand& c, const std::string& outcome) override {
    std::lock_guard lock(m);
    commands.emplace_back(c, outcome);
  }
  void on_alert(const contracts::Alert& a) override {
    std::lock_guard lock(m);
    alerts.push_back(a.code);
  }
  void on_telemetry(const contracts::TelemetryFrame& f) override {
    std::lock_guard lock(m);
    telemetry.push_back(f);
  }
  std::vector<std::string> executed() {
    std::lock_guard lock(m);
    std::vector<std::string> out;
    for (const auto& [c, o] : commands) {
      if (o == "OK") out.push_back(std::string(contracts::to_string(c.type)) + ":" + c.source_id);
    }
    return out;
  }
  std::mutex m;
  std::vector<std::pair<contracts::DroneCommand, std::string>> commands;
  std::vector<std::string> alerts;
  std::vector<contracts::TelemetryFrame> telemetry;
};

TEST(TwinControlLoop, GesturesTakeOffMoveAndLandTheTwin) {
  contracts::ManualClock clock;
  TwinAdapter twin(clock, testing::shared_model());
  gesture::GestureEngine engine(clock, std::make_unique<gesture::RuleBasedRecognizer>());
  control::CommandTranslator translator(control::GestureProfile::builtin_default());
  runtime::ControlLoop loop(clock, twin, engine, translator);
  auto recorder = std::make_shared<Recorder>();
  loop.add_listener(recorder);
  ASSERT_EQ(loop.start(), control::Result::kOk);
  EXPECT_EQ(twin.state(), FlightState::kReady);

  // Thumb up (take off), open palm (hover while it climbs), victory (forward 0.4 m/s, repeated
  // while held), fist (land), then no hand while it comes down.
  auto timeline = GestureTimeline::from_json(nlohmann::json::parse(R"({
      "name": "twin", "seed": 5, "fps": 30,
      "segments": [{"pose": "NO_HAND", "duration_s": 0.5}, {"pose": "THUMB_UP", "duration_s": 1.0},
                   {"pose": "OPEN_PALM", "duration_s": 3.0}, {"pose": "VICTORY", "duration_s": 2.5},
                   {"pose": "FIST", "duration_s": 1.0}, {"pose": "NO_HAND", "duration_s": 4.0}]})"));
  const auto period = contracts::from_seconds(1.0 / timeline.fps());
  const auto frames = timeline.frame_count();
  bool saw_flying = false;
  double max_altitude_m = 0;
  for (std::size_t i = 0; i < frames; ++i) {
    clock.advance(period);
    loop.on_frame(timeline.next_frame().hand, static_cast<std::int64_t>(i));
    loop.tick();
    saw_flying = saw_flying || twin.state() == FlightState::kFlying;
    max_altitude_m = std::max(max_altitude_m, twin.snapshot().altitude_m);
  }
  loop.telemetry().drain(std::chrono::seconds(5));

  const auto done = recorder->executed();
  ASSERT_GE(done.size(), 3u);
  EXPECT_EQ(done.front(), "TAKEOFF:THUMB_UP");
  EXPECT_EQ(done.back(), "LAND:FIST");
  EXPECT_NE(std::find(done.begin(), done.end(), "MOVE:VICTORY"), done.end());
  EXPECT_TRUE(saw_flying);
  EXPECT_NEAR(max_altitude_m, 1.0, 0.2);
  EXPECT_EQ(twin.state(), FlightState::kReady);
  const auto end = twin.snapshot();
  EXPECT_GT(end.x_m, 0.5);  // went forward
  EXPECT_LT(end.altitude_m, 0.03);

  std::lock_guard lock(recorder->m);
  EXPECT_TRUE(std::none_of(recorder->alerts.begin(), recorder->alerts.end(),
                           [](const auto& code) { return code == "LINK_LOSS"; }));
  // The core saw the twin's telemetry at >= 20 Hz of simulated time.
  const double span_s = std::chrono::duration<double>(recorder->telemetry.back().timestamp -
                                                      recorder->telemetry.front().timestamp)
                            .count();
  EXPECT_GE(static_cast<double>(recorder->telemetry.size() - 1) / span_s, 20.0);
  EXPECT_EQ(recorder->telemetry.back().flight_state, FlightState::kReady);
}

}  // namespace
}  // namespace gbdcs::sim
