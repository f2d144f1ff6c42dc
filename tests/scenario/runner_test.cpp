// The runner end to end on the twin, the dummy and the emulator drones: a flight that must
// pass, the same flight judged by a wrong expectation that must fail, two emulator runs that
// must agree, and the artifacts of a run.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "gbdcs/sim/scenario.hpp"
#include "gbdcs/sim/scenario_report.hpp"
#include "gbdcs/sim/scenario_runner.hpp"

namespace gbdcs::sim {
namespace {

namespace fs = std::filesystem;

nlohmann::json flight(const std::string& drone) {
  auto doc = nlohmann::json::parse(R"({
    "name": "hop", "description": "take off, hover, land", "timeout_s": 10,
    "camera": {"timeline": {"seed": 3, "segments": [
      {"pose": "NO_HAND", "duration_s": 0.5}, {"pose": "THUMB_UP", "duration_s": 1.5},
      {"pose": "OPEN_PALM", "duration_s": 2.0}, {"pose": "FIST", "duration_s": 1.5},
      {"pose": "NO_HAND", "duration_s": 1.0}]}},
    "criteria": [
      {"name": "order", "type": "command_sequence", "in_order": ["TAKEOFF:THUMB_UP", "LAND:FIST"]},
      {"name": "landed", "type": "final_state", "flight_state": ["READY"], "altitude_m": [0, 0.05]},
      {"name": "recognised", "type": "recognition_accuracy", "min": 1.0}
    ]})");
  doc["drone"] = drone;
  return doc;
}

TEST(ScenarioRunner, TwinFlightPasses) {
  RunOptions o;
  o.keep_record = true;
  const auto r = run_scenario(Scenario::from_json(flight("twin")), o);
  ASSERT_TRUE(r.error.empty()) << r.error;
  for (const auto& c : r.criteria) EXPECT_NE(c.verdict, Verdict::kFailure) << c.name << ": " << c.actual;
  EXPECT_TRUE(r.passed);
  EXPECT_NEAR(r.sim_s, 10.0, 1e-6);
  EXPECT_FALSE(r.record.telemetry.empty());
  ASSERT_TRUE(r.record.collisions.has_value());
}

TEST(ScenarioRunner, AWrongExpectationFails) {
  auto doc = flight("twin");
  // The flight lands; a criterion that wants it still flying must fail, and say so.
  doc["criteria"].push_back({{"name", "still flying"}, {"type", "final_state"},
                             {"flight_state", {"FLYING"}}});
  doc["criteria"].push_back({{"name", "link loss"}, {"type", "failsafe"}, {"alert", "LINK_LOSS"},
                             {"from_s", 1}, {"within_ms", 2500}});
  const auto r = run_scenario(Scenario::from_json(doc));
  EXPECT_FALSE(r.passed);
  ASSERT_EQ(r.criteria.size(), 5u);
  EXPECT_EQ(r.criteria[3].verdict, Verdict::kFailure);
  EXPECT_NE(r.criteria[3].actual.find("READY"), std::string::npos) << r.criteria[3].actual;
  EXPECT_EQ(r.criteria[4].verdict, Verdict::kFailure);
  EXPECT_NE(r.criteria[4].actual.find("never raised"), std::string::npos);
  // The JUnit report carries the failure with its reason.
  const auto junit = report_junit({r}, 1.0);
  EXPECT_NE(junit.find("<failure message=\"still flying: expected FLYING, actual READY"),
            std::string::npos)
      << junit;
}

TEST(ScenarioRunner, DummyFlightAndItsLimits) {
  auto doc = flight("dummy");
  doc["criteria"].push_back({{"name", "collisions"}, {"type", "no_collision"}});
  const auto r = run_scenario(Scenario::from_json(doc));
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.criteria[0].verdict, Verdict::kSuccess) << r.criteria[0].actual;
  // The dummy cannot report collisions: not evaluated is a failure, never a pass.
  EXPECT_EQ(r.criteria[3].verdict, Verdict::kFailure);
  EXPECT_FALSE(r.passed);

  doc = flight("dummy");
  doc["events"] = {{{"at_s", 1}, {"type", "wind_gust"}, {"duration_s", 1}, {"force_n", {0.1, 0, 0}}}};
  const auto bad = run_scenario_file("/nonexistent.json");
  EXPECT_FALSE(bad.passed);
  EXPECT_FALSE(bad.error.empty());
  EXPECT_THROW((void)run_scenario(Scenario::from_json(doc)), std::invalid_argument);
}

// The emulator drones: the real adapter over loopback sockets, lockstep. Two runs of the same
// flight must give the same record (commands with their simulated times and outcomes, the
// telemetry frames) however the threads were scheduled.
TEST(ScenarioRunner, EmulatorFlightsAreDeterministic) {
  for (const char* drone : {"tello-emulator", "airsim-emulator"}) {
    RunOptions o;
    o.keep_record = true;
    const auto first = run_scenario(Scenario::from_json(flight(drone)), o);
    const auto second = run_scenario(Scenario::from_json(flight(drone)), o);
    for (const auto* r : {&first, &second}) {
      ASSERT_TRUE(r->error.empty()) << drone << ": " << r->error;
      for (const auto& c : r->criteria) {
        EXPECT_NE(c.verdict, Verdict::kFailure) << drone << " " << c.name << ": " << c.actual;
      }
    }
    ASSERT_EQ(first.record.commands.size(), second.record.commands.size()) << drone;
    for (std::size_t i = 0; i < first.record.commands.size(); ++i) {
      const auto& a = first.record.commands[i];
      const auto& b = second.record.commands[i];
      EXPECT_EQ(a.t_s, b.t_s) << drone << " command " << i;
      EXPECT_EQ(a.command.type, b.command.type) << drone << " command " << i;
      EXPECT_EQ(a.outcome, b.outcome) << drone << " command " << i;
    }
    ASSERT_EQ(first.record.telemetry.size(), second.record.telemetry.size()) << drone;
    ASSERT_FALSE(first.record.telemetry.empty());
    for (std::size_t i = 0; i < first.record.telemetry.size(); ++i) {
      const auto& a = first.record.telemetry[i];
      const auto& b = second.record.telemetry[i];
      EXPECT_EQ(a.t_s, b.t_s) << drone << " frame " << i;
      EXPECT_EQ(a.frame.altitude_m, b.frame.altitude_m) << drone << " frame " << i;
      EXPECT_EQ(a.frame.x_m, b.frame.x_m) << drone << " frame " << i;
      EXPECT_EQ(a.frame.flight_state, b.frame.flight_state) << drone << " frame " << i;
    }
  }
}

TEST(ScenarioRunner, EmulatorDroneOptionsAndLimitsAreNamed) {
  auto doc = flight("tello-emulator");
  doc["drone"] = {{"type", "tello-emulator"},
                  {"options", {{"adapter", {{"address", "192.168.10.1"}}}}}};
  try {
    (void)run_scenario(Scenario::from_json(doc));
    FAIL() << "an address of its own was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'address' is the runner's"), std::string::npos)
        << e.what();
  }
  doc["drone"] = {{"type", "airsim-emulator"}, {"options", {{"adapters", nlohmann::json::object()}}}};
  try {
    (void)run_scenario(Scenario::from_json(doc));
    FAIL() << "an unknown option key was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key 'adapters'"), std::string::npos) << e.what();
  }
  doc = flight("xfly-emulator");
  doc["events"] = {{{"at_s", 1}, {"type", "telemetry_delay"}, {"duration_s", 1}, {"delay_ms", 200}}};
  try {
    (void)run_scenario(Scenario::from_json(doc));
    FAIL() << "a telemetry delay was accepted by an emulator drone";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fly the twin"), std::string::npos) << e.what();
  }
}

TEST(ScenarioRunner, WritesArtifacts) {
  const fs::path dir = fs::temp_directory_path() /
                       ("gbdcs_scenario_artifacts_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  auto doc = flight("twin");
  doc["timeout_s"] = 4;
  RunOptions o;
  o.artifacts_dir = dir.string();
  o.artifacts_always = true;
  const auto r = run_scenario(Scenario::from_json(doc), o);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.artifacts.size(), 3u);
  for (const auto* name : {"events.jsonl", "trajectory.png", "video.mp4"}) {
    const auto p = dir / "hop" / name;
    EXPECT_TRUE(fs::exists(p)) << p;
    if (fs::exists(p)) {
      EXPECT_GT(fs::file_size(p), 100u) << p;
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gbdcs::sim
