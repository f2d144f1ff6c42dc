// The production core wired by ControlLoop, on the dummy drone, with a simulated clock.
#include <gtest/gtest.h>

#include <filesystem>

#include "gbdcs/adapters/dummy_adapter.hpp"
#include "gbdcs/gesture/rule_based_recognizer.hpp"
#include "gbdcs/runtime/control_loop.hpp"
#include "gbdcs/runtime/listeners.hpp"
#include "gbdcs/sim/gesture_timeline.hpp"

namespace gbdcs::runtime {
namespace {

using contracts::CommandSource;
using contracts::CommandType;
using contracts::FlightState;

struct Recorder final : EventListener {
  void on_gesture(const contracts::GestureEvent& e) override {
    std::lock_guard lock(m);
    gestures.push_back(e);
  }
  void on_command(const contracts::DroneCommand& c, const std::string& outcome) override {
    std::lock_guard lock(m);
    commands.emplace_back(c, outcome);
  }
  void on_alert(const contracts::Alert& a) override {
    std::lock_guard lock(m);
    alerts.push_back(a);
  }
  std::vector<std::string> executed() {
    std::lock_guard lock(m);
    std::vector<std::string> out;
    for (const auto& [c, o] : commands) {
      if (o == "OK") out.push_back(std::string(contracts::to_string(c.type)) + ":" + c.source_id);
    }
    return out;
  }
  bool has_alert(const std::string& code) {
    std::lock_guard lock(m);
    return std::any_of(alerts.begin(), alerts.end(), [&](const auto& a) { return a.code == code; });
  }
  std::mutex m;
  std::vector<contracts::GestureEvent> gestures;
  std::vector<std::pair<contracts::DroneCommand, std::string>> commands;
  std::vector<contracts::Alert> alerts;
};

sim::GestureTimeline timeline(const std::string& segments_json, unsigned seed = 3) {
  return sim::GestureTimeline::from_json(nlohmann::json::parse(
      R"({"name":"t","seed":)" + std::to_string(seed) + R"(,"fps":30,"segments":)" +
      segments_json + "}"));
}

class LoopTest : public ::testing::Test {
 protected:
  LoopTest() { loop.add_listener(recorder); }
  // Feeds the timeline at its fps; then `extra_s` of frames without a hand.
  void play(sim::GestureTimeline t, double extra_s = 0) {
    const auto period = contracts::from_seconds(1.0 / t.fps());
    const auto n = t.frame_count() + static_cast<std::size_t>(extra_s * t.fps());
    const auto frames = t.frame_count();
    for (std::size_t i = 0; i < n; ++i) {
      clock.advance(period);
      std::optional<contracts::Landmarks> hand;
      if (i < frames) hand = t.next_frame().hand;
      loop.on_frame(hand, frame_id++);
      loop.tick();
    }
  }
  void run_without_camera(double seconds) {
    for (int i = 0; i < static_cast<int>(seconds * 50); ++i) {
      clock.advance(contracts::from_seconds(0.02));
      loop.tick();
    }
  }

  contracts::ManualClock clock;
  adapters::DummyDroneAdapter drone{clock};
  gesture::GestureEngine engine{clock, std::make_unique<gesture::RuleBasedRecognizer>()};
  control::CommandTranslator translator{control::GestureProfile::builtin_default()};
  ControlLoop loop{clock, drone, engine, translator};
  std::shared_ptr<Recorder> recorder = std::make_shared<Recorder>();
  std::int64_t frame_id = 0;
};

TEST_F(LoopTest, GesturesFlyTheDroneAndFourFingersDoNothing) {
  ASSERT_EQ(loop.start(), control::Result::kOk);
  play(timeline(R"([{"pose":"NO_HAND","duration_s":0.5},
                    {"pose":"THUMB_UP","duration_s":1.0},
                    {"pose":"OPEN_PALM","duration_s":2.5},
                    {"pose":"POINT_RIGHT","duration_s":1.5},
                    {"pose":"FOUR_FINGERS","duration_s":1.5},
                    {"pose":"FIST","duration_s":1.0},
                    {"pose":"NO_HAND","duration_s":3.0}])"));
  auto done = recorder->executed();
  ASSERT_GE(done.size(), 4u);
  EXPECT_EQ(done.front(), "TAKEOFF:THUMB_UP");
  EXPECT_EQ(done.back(), "LAND:FIST");
  EXPECT_NE(std::find(done.begin(), done.end(), "MOVE:POINT_RIGHT"), done.end());
  for (const auto& g : recorder->gestures) EXPECT_NE(g.gesture, contracts::GestureType::kNone);
  EXPECT_EQ(drone.state(), FlightState::kReady);
  EXPECT_GT(drone.snapshot().y_m, 0.3);  // slid right
}

TEST_F(LoopTest, NoTakeoffBeforeVisionIsReady) {
  loop.start();
  auto d = loop.submit([] {
    contracts::DroneCommand c;
    c.type = CommandType::kTakeoff;
    c.source = CommandSource::kKeyboard;
    return c;
  }());
  EXPECT_FALSE(d.accepted);
  EXPECT_NE(d.reason.find("vision is not ready"), std::string::npos);
  EXPECT_EQ(drone.state(), FlightState::kReady);
  ASSERT_EQ(recorder->commands.size(), 1u);
  EXPECT_EQ(recorder->commands[0].second.rfind("REFUSED", 0), 0u);  // the refusal is logged
}

TEST_F(LoopTest, EmergencyStopPreemptsAndLatches) {
  loop.start();
  play(timeline(R"([{"pose":"NO_HAND","duration_s":0.3},{"pose":"THUMB_UP","duration_s":3.0}])"));
  ASSERT_EQ(drone.state(), FlightState::kFlying);
  contracts::DroneCommand move;
  move.type = CommandType::kMove;
  move.source = CommandSource::kKeyboard;
  move.payload = contracts::MotionPayload{1, 0, 0, 0, 2};
  ASSERT_TRUE(loop.submit(move).accepted);  // pending until the next tick
  auto d = loop.emergency_stop(CommandSource::kApi, "dashboard");
  EXPECT_TRUE(d.accepted);
  EXPECT_EQ(d.dropped, 1u);
  std::lock_guard lock(recorder->m);
  auto last = recorder->commands.back();
  EXPECT_EQ(last.first.type, CommandType::kEmergencyStop);
  EXPECT_EQ(last.second, "OK");
  bool move_dropped = std::any_of(recorder->commands.begin(), recorder->commands.end(),
                                  [](const auto& p) {
                                    return p.first.type == CommandType::kMove &&
                                           p.second.rfind("DROPPED", 0) == 0;
                                  });
  EXPECT_TRUE(move_dropped);
  EXPECT_TRUE(loop.arbiter().emergency_latched());
}

TEST_F(LoopTest, IdleHoverAfterThreeSecondsWithoutGesture) {
  loop.start();
  play(timeline(R"([{"pose":"NO_HAND","duration_s":0.3},{"pose":"THUMB_UP","duration_s":1.0},
                    {"pose":"NO_HAND","duration_s":6.0}])"));
  EXPECT_TRUE(recorder->has_alert("IDLE_HOVER"));
  auto done = recorder->executed();
  EXPECT_NE(std::find(done.begin(), done.end(), "HOVER:IDLE_HOVER"), done.end());
  EXPECT_EQ(drone.state(), FlightState::kFlying);
}

TEST_F(LoopTest, LinkLossAlertsWithinTheTimeout) {
  loop.start();
  play(timeline(R"([{"pose":"NO_HAND","duration_s":0.3},{"pose":"THUMB_UP","duration_s":3.0}])"));
  drone.set_link_lost(true);
  const auto lost_utc = clock.utc_now();
  play(timeline(R"([{"pose":"OPEN_PALM","duration_s":3.0}])"));
  ASSERT_TRUE(recorder->has_alert("LINK_LOSS"));
  std::lock_guard lock(recorder->m);
  auto it = std::find_if(recorder->alerts.begin(), recorder->alerts.end(),
                         [](const auto& a) { return a.code == "LINK_LOSS"; });
  // The last frame came at most one telemetry period (0.1 s) before the loss; the alert comes
  // once the 2 s timeout has passed, at the next tick (1/30 s).
  const double after_s = std::chrono::duration<double>(it->timestamp - lost_utc).count();
  EXPECT_GE(after_s, 1.9);
  EXPECT_LE(after_s, 2.1);
}

TEST_F(LoopTest, CameraSilenceMakesVisionUnhealthyAndHovers) {
  loop.start();
  play(timeline(R"([{"pose":"NO_HAND","duration_s":0.3},{"pose":"THUMB_UP","duration_s":3.0}])"));
  ASSERT_TRUE(loop.vision_ready());
  run_without_camera(1.0);
  EXPECT_FALSE(loop.vision_ready());
  EXPECT_TRUE(recorder->has_alert("VISION_UNHEALTHY"));
  auto done = recorder->executed();
  EXPECT_EQ(done.back(), "HOVER:VISION_UNHEALTHY");
}

TEST_F(LoopTest, BatteryCriticalLandsAndBlocksTakeoff) {
  loop.start();
  play(timeline(R"([{"pose":"NO_HAND","duration_s":0.3},{"pose":"THUMB_UP","duration_s":3.0}])"));
  drone.set_battery_pct(14);
  play(timeline(R"([{"pose":"OPEN_PALM","duration_s":4.0}])"));
  EXPECT_TRUE(recorder->has_alert("BATTERY_CRITICAL"));
  EXPECT_EQ(drone.state(), FlightState::kReady);
  play(timeline(R"([{"pose":"THUMB_UP","duration_s":1.0}])"));
  EXPECT_EQ(drone.state(), FlightState::kReady);  // take-off refused
}

TEST_F(LoopTest, StorageRecordsEverything) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("gbdcs_loop_" + std::to_string(::getpid()) + ".db");
  // Removes the database with its WAL and shared-memory files, before the test and (declared
  // before the storage, so destroyed after it has closed them) after.
  struct Cleanup {
    std::filesystem::path db;
    void remove() const {
      for (const char* suffix : {"", "-wal", "-shm"}) std::filesystem::remove(db.string() + suffix);
    }
    ~Cleanup() { remove(); }
  } cleanup{path};
  cleanup.remove();
  storage::StorageOptions so;
  so.path = path.string();
  storage::StorageManager storage(so, clock);
  const auto session = storage.begin_session(std::nullopt, "dummy", "default");
  loop.add_listener(std::make_shared<StorageListener>(storage, session));
  loop.start();
  play(timeline(R"([{"pose":"NO_HAND","duration_s":0.3},{"pose":"THUMB_UP","duration_s":3.0},
                    {"pose":"FIST","duration_s":1.0},{"pose":"NO_HAND","duration_s":3.0}])"));
  loop.telemetry().drain(std::chrono::seconds(5));
  EXPECT_EQ(storage.gestures(session).size(), recorder->gestures.size());
  EXPECT_EQ(storage.commands(session).size(), recorder->commands.size());
  EXPECT_GT(storage.telemetry(session).size(), 50u);
  EXPECT_EQ(storage.alerts(session).size(), recorder->alerts.size());
}

}  // namespace
}  // namespace gbdcs::runtime
