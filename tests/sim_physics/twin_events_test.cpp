// TwinSim events: collisions, crashes, auto-land, battery drain and forced landing.
#include <gtest/gtest.h>

#include <cmath>

#include "twin_test_support.hpp"

namespace gbdcs::sim {
namespace {

using TwinEvents = TwinTest;

TEST_F(TwinEvents, FlyingIntoTheFrontWallIsACollision) {
  TwinSim& sim = make_sim();
  take_off(sim);
  ASSERT_TRUE(sim.rc(0, 100, 0, 0).ok);  // 1 m/s toward the wall at x = 3 m
  sim.step_to(sim.time_s() + 2.0);
  EXPECT_EQ(sim.status().collisions, 0);
  sim.step_to(sim.time_s() + 3.0);
  const TwinStatus s = sim.status();
  EXPECT_EQ(s.collisions, 1);      // pressing on the wall is one collision
  EXPECT_NEAR(s.x_m, 2.95, 0.05);  // the hull's front (49 mm) at the wall
  EXPECT_NE(s.mode, TwinMode::kCrashed);
  ASSERT_TRUE(sim.rc(0, -50, 0, 0).ok);  // back off, then in again: a second collision
  sim.step_to(sim.time_s() + 1.0);
  ASSERT_TRUE(sim.rc(0, 50, 0, 0).ok);
  sim.step_to(sim.time_s() + 2.0);
  EXPECT_EQ(sim.status().collisions, 2);
  ASSERT_TRUE(sim.land().ok);
  sim.step_to(sim.time_s() + 4.0);
  EXPECT_EQ(sim.mode(), TwinMode::kLanded);
}

TEST_F(TwinEvents, HardFloorImpactCrashes) {
  TwinSim& sim = make_sim();
  take_off(sim);
  ASSERT_TRUE(sim.rc(0, 0, 100, 0).ok);  // up to 1.8 m, then cut: ~6 m/s at the floor
  sim.step_to(sim.time_s() + 1.0);
  ASSERT_TRUE(sim.emergency().ok);
  sim.step_to(sim.time_s() + 3.0);
  const TwinStatus s = sim.status();
  EXPECT_EQ(s.mode, TwinMode::kCrashed);
  EXPECT_EQ(s.collisions, 0);  // the floor is not an obstacle
  EXPECT_EQ(sim.takeoff().error, "crashed");
  EXPECT_EQ(sim.rc(0, 0, 0, 0).error, "crashed");
  EXPECT_EQ(sim.land().error, "crashed");
  EXPECT_TRUE(sim.emergency().ok);
}

TEST_F(TwinEvents, GentleLandingIsNotACrash) {
  TwinOptions options;
  options.controller.land_descent_m_s = 1.5;  // still below the 2 m/s crash speed
  TwinSim& sim = make_sim(options);
  take_off(sim);
  sim.land();
  sim.step_to(sim.time_s() + 3.0);
  EXPECT_EQ(sim.mode(), TwinMode::kLanded);
}

TEST_F(TwinEvents, FifteenSecondsWithoutACommandLandsIt) {
  TwinSim& sim = make_sim();
  ASSERT_TRUE(sim.takeoff().ok);  // the last command, at t = 0
  sim.step_to(14.9);
  EXPECT_EQ(sim.mode(), TwinMode::kFlying);
  sim.step_to(15.1);
  EXPECT_EQ(sim.mode(), TwinMode::kLanding);
  sim.step_to(19.0);
  EXPECT_EQ(sim.mode(), TwinMode::kLanded);
  EXPECT_NEAR(sim.status().last_command_age_s, 19.0, 1e-9);
}

TEST_F(TwinEvents, AnyCommandResetsTheNoCommandTimer) {
  TwinSim& sim = make_sim();
  ASSERT_TRUE(sim.takeoff().ok);
  sim.step_to(10.0);
  ASSERT_TRUE(sim.hover().ok);
  sim.step_to(20.0);
  EXPECT_EQ(sim.mode(), TwinMode::kFlying);
  EXPECT_EQ(sim.takeoff().error, "already flying");  // refused, but heard
  sim.step_to(34.0);
  EXPECT_EQ(sim.mode(), TwinMode::kFlying);
  sim.step_to(35.1);
  EXPECT_EQ(sim.mode(), TwinMode::kLanding);
}

TEST_F(TwinEvents, BatteryDrainsAtTheModelledRate) {
  TwinSim& sim = make_sim();
  take_off(sim);
  sim.hover();
  const TwinStatus start = sim.status();
  sim.step_to(start.time_s + 10.0);
  sim.hover();
  sim.step_to(start.time_s + 20.0);
  const TwinStatus end = sim.status();
  // The model's prediction for a steady hover: the current that carries the weight, for 20 s.
  BatteryModel model;
  model.set_pct(start.battery_pct);
  const double weight_n = 0.08 * 9.81;
  const double current_a = model.current_for_power_a(
      model.power_w({weight_n / 4, weight_n / 4, weight_n / 4, weight_n / 4}));
  const double predicted_pct = current_a * 20.0 / 3.6 / 1100.0 * 100.0;
  EXPECT_NEAR(start.battery_pct - end.battery_pct, predicted_pct, 0.02 * predicted_pct);
  EXPECT_NEAR(end.current_a, current_a, 0.05 * current_a);
  EXPECT_LT(end.voltage_v, 4.2);  // sag plus a little discharge
  EXPECT_GT(end.voltage_v, 3.6);
}

TEST_F(TwinEvents, EmptyBatteryForcesALandingAndNoTakeoff) {
  TwinSim& sim = make_sim();
  sim.set_faults(FaultSchedule::from_json_text(
      R"([{"type": "battery_jump", "start_s": 6, "battery_pct": 0.2}])"));
  take_off(sim);
  sim.hover();
  sim.step_to(6.1);
  EXPECT_NEAR(sim.status().battery_pct, 0.2, 0.03);  // ~6.5 A at 3.4 V for 0.1 s
  EXPECT_EQ(sim.mode(), TwinMode::kFlying);
  sim.step_to(8.0);  // 2.2 mAh at ~5 A: empty after ~1.6 s
  EXPECT_EQ(sim.status().battery_pct, 0.0);
  EXPECT_EQ(sim.mode(), TwinMode::kLanding);
  sim.step_to(12.0);
  EXPECT_EQ(sim.mode(), TwinMode::kLanded);
  EXPECT_EQ(sim.takeoff().error, "battery low");
}

}  // namespace
}  // namespace gbdcs::sim
