// TwinSim under faults: wind gust, degraded motor, sensor noise, battery jump, the adapter's
// link-loss and delay queries, options from JSON.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "twin_test_support.hpp"

namespace gbdcs::sim {
namespace {

using TwinFaults = TwinTest;

TEST_F(TwinFaults, WindGustIsRejectedWithinTwoSeconds) {
  TwinSim& sim = make_sim();
  // 0.15 N sideways (right) for 1 s: 19 % of the weight, 1.9 m/s^2 on 80 g.
  sim.set_faults(FaultSchedule::from_json_text(
      R"([{"type": "wind_gust", "start_s": 8, "duration_s": 1, "force_n": [0, 0.15, 0]}])"));
  take_off(sim);
  sim.hover();
  sim.step_to(8.0);
  const TwinStatus hold = sim.status();
  double pushed_m = 0;
  each_step_until(sim, 9.0, [&](const TwinStatus& s) {
    pushed_m = std::max(pushed_m, std::hypot(s.x_m - hold.x_m, s.y_m - hold.y_m));
  });
  EXPECT_GT(pushed_m, 0.05) << "the gust should move it before the controller wins";
  const TwinStatus end = sim.status();
  EXPECT_GT(end.y_m - hold.y_m, 0.0);  // pushed right, in the contracts' frame
  sim.step_to(11.0);                   // two seconds after the gust
  const TwinStatus after = sim.status();
  EXPECT_LT(std::hypot(after.x_m - hold.x_m, after.y_m - hold.y_m), 0.10);
  EXPECT_NEAR(after.z_m, hold.z_m, 0.05);
  EXPECT_LT(after.speed_m_s, 0.1);
  EXPECT_EQ(after.mode, TwinMode::kFlying);
}

TEST_F(TwinFaults, DegradedMotorStillHovers) {
  TwinSim& sim = make_sim();
  sim.set_faults(FaultSchedule::from_json_text(
      R"([{"type": "motor_degraded", "start_s": 6, "motor": 0, "thrust_factor": 0.8}])"));
  take_off(sim);
  sim.hover();
  sim.step_to(12.0);
  const TwinStatus s = sim.status();
  EXPECT_EQ(s.mode, TwinMode::kFlying);
  EXPECT_NEAR(s.z_m, 1.0, 0.05);
  EXPECT_LT(std::hypot(s.x_m, s.y_m), 0.1);
  // Motor 0 delivers 80 % of what it is asked: the others make up for it.
  EXPECT_LT(s.motor_thrust_n[0], s.motor_thrust_n[2]);
}

TEST_F(TwinFaults, SensorNoiseIsOnTheReportsOnlyAndSeeded) {
  TwinSim& noisy = make_sim({}, 3);
  TwinSim& clean = make_sim({}, 3);
  noisy.set_faults(FaultSchedule::from_json_text(
      R"([{"type": "sensor_noise", "start_s": 0, "position_sigma_m": 0.05,
           "velocity_sigma_m_s": 0.1, "heading_sigma_deg": 3}])"));
  take_off(noisy);
  take_off(clean);
  noisy.hover();
  clean.hover();
  double sum_sq_x = 0, sum_sq_heading = 0;
  int n = 0;
  for (int i = 1; i <= 2000; ++i) {
    const double t = 5.0 + i * 0.004;
    noisy.step_to(t);
    clean.step_to(t);
    const TwinStatus a = noisy.status();
    const TwinStatus b = clean.status();
    EXPECT_EQ(a.x_m, noisy.status().x_m);  // asking twice gives the same answer
    sum_sq_x += (a.x_m - b.x_m) * (a.x_m - b.x_m);
    double dh = std::remainder(a.heading_deg - b.heading_deg, 360.0);
    sum_sq_heading += dh * dh;
    ++n;
  }
  EXPECT_NEAR(std::sqrt(sum_sq_x / n), 0.05, 0.005);
  EXPECT_NEAR(std::sqrt(sum_sq_heading / n), 3.0, 0.3);
  // The physics did not see it: the same state underneath.
  EXPECT_EQ(noisy.data()->qpos[0], clean.data()->qpos[0]);
}

TEST_F(TwinFaults, BatteryJumpHappensOnceAtItsTime) {
  TwinSim& sim = make_sim();
  sim.set_faults(FaultSchedule::from_json_text(
      R"([{"type": "battery_jump", "start_s": 2, "battery_pct": 30}])"));
  sim.step_to(1.9);
  EXPECT_GT(sim.status().battery_pct, 99.0);
  sim.step_to(2.1);
  EXPECT_NEAR(sim.status().battery_pct, 30.0, 0.01);
  sim.step_to(3.0);
  EXPECT_LT(sim.status().battery_pct, 30.0);  // not re-applied
  // A new schedule does not replay jumps already in the past.
  sim.set_faults(FaultSchedule::from_json_text(
      R"([{"type": "battery_jump", "start_s": 2, "battery_pct": 90}])"));
  sim.step_to(4.0);
  EXPECT_LT(sim.status().battery_pct, 30.0);
}

TEST_F(TwinFaults, AdapterQueriesAreOnTheSimulatedClock) {
  TwinSim& sim = make_sim({}, 5);
  sim.set_faults(FaultSchedule::from_json_text(R"([
      {"type": "link_loss", "start_s": 3, "duration_s": 2},
      {"type": "telemetry_delay", "start_s": 1, "delay_ms": 150, "jitter_ms": 20}])"));
  EXPECT_FALSE(sim.link_lost(2.9));
  EXPECT_TRUE(sim.link_lost(3.0));
  EXPECT_FALSE(sim.link_lost(5.0));
  EXPECT_EQ(sim.telemetry_delay_s(0.5), 0.0);
  const double d = sim.telemetry_delay_s(2.0);
  EXPECT_GE(d, 0.130);
  EXPECT_LE(d, 0.170);
  EXPECT_EQ(d, sim.faults().telemetry_delay_s(2.0, 5));
}

TEST(TwinOptions, FromJsonIsStrict) {
  const auto o = TwinOptions::from_json(nlohmann::json::parse(R"({
      "controller": {"max_horizontal_m_s": 2.0},
      "battery": {"start_pct": 50},
      "crash_speed_m_s": 3,
      "faults": [{"type": "link_loss", "start_s": 1, "duration_s": 1}]})"));
  EXPECT_DOUBLE_EQ(o.controller.max_horizontal_m_s, 2.0);
  EXPECT_DOUBLE_EQ(o.battery.start_pct, 50);
  EXPECT_DOUBLE_EQ(o.crash_speed_m_s, 3);
  EXPECT_DOUBLE_EQ(o.auto_land_after_s, 15);
  EXPECT_EQ(o.faults.faults().size(), 1u);
  try {
    TwinOptions::from_json(nlohmann::json::parse(R"({"crash_speed": 3})"));
    FAIL() << "unknown key accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("TwinOptions: 'crash_speed' is not a known option"));
  }
  EXPECT_THROW(TwinOptions::from_json(nlohmann::json::parse(R"({"controller": {"x": 1}})")),
               std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::sim
