// TwinSim in normal flight: take-off, hover, rc, land, emergency, command replies,
// determinism. Simulated time only; every test also fails on any MuJoCo warning (TearDown).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "twin_test_support.hpp"

namespace gbdcs::sim {
namespace {

using TwinFlight = TwinTest;

TEST_F(TwinFlight, StartsLandedAtTheOrigin) {
  TwinSim& sim = make_sim();
  const TwinStatus s = sim.status();
  EXPECT_EQ(s.mode, TwinMode::kLanded);
  EXPECT_EQ(s.time_s, 0.0);
  EXPECT_NEAR(s.z_m, 0.0, 1e-9);
  EXPECT_NEAR(s.heading_deg, 0.0, 1e-9);
  EXPECT_EQ(s.battery_pct, 100.0);
  sim.step_to(2.0);  // resting on the floor: it settles, motors off
  EXPECT_NEAR(sim.status().z_m, 0.0, 0.002);
  EXPECT_EQ(sim.time_s(), 2.0);
  EXPECT_EQ(sim.status().motor_thrust_n, (std::array<double, 4>{}));
}

TEST_F(TwinFlight, TakeoffClimbsToAboutOneMetre) {
  TwinSim& sim = make_sim();
  ASSERT_TRUE(sim.takeoff().ok);
  EXPECT_EQ(sim.mode(), TwinMode::kTakingOff);
  sim.step_to(5.0);
  const TwinStatus s = sim.status();
  EXPECT_EQ(s.mode, TwinMode::kFlying);
  EXPECT_NEAR(s.z_m, 1.0, 0.05);
  EXPECT_NEAR(std::hypot(s.x_m, s.y_m), 0.0, 0.05);
  double total = 0;
  for (const double f : s.motor_thrust_n) total += f;
  EXPECT_NEAR(total, 0.08 * 9.81, 0.01);  // hovering: thrust carries the weight
}

TEST_F(TwinFlight, HoverHoldsAltitudeWithinFiveCentimetresForTenSeconds) {
  TwinSim& sim = make_sim();
  take_off(sim);
  ASSERT_TRUE(sim.hover().ok);
  const double start = sim.time_s();
  double low = 1e9, high = -1e9, drift = 0;
  each_step_until(sim, start + 10.0, [&](const TwinStatus& s) {
    low = std::min(low, s.z_m);
    high = std::max(high, s.z_m);
    drift = std::max(drift, std::hypot(s.x_m, s.y_m));
  });
  EXPECT_GT(low, 0.95);
  EXPECT_LT(high, 1.05);
  EXPECT_LT(drift, 0.05);
  EXPECT_EQ(sim.mode(), TwinMode::kFlying);
}

TEST_F(TwinFlight, ForwardStickMovesTheDistanceTheMaximumPredicts) {
  TwinSim& sim = make_sim();  // max_horizontal_m_s 1.0: rc b=50 -> 0.5 m/s
  take_off(sim);
  const TwinStatus before = sim.status();
  ASSERT_TRUE(sim.rc(0, 50, 0, 0).ok);
  sim.step_to(sim.time_s() + 2.0);
  EXPECT_NEAR(sim.status().body_vx_m_s, 0.5, 0.05);  // at the commanded speed
  ASSERT_TRUE(sim.hover().ok);
  sim.step_to(sim.time_s() + 3.0);  // brakes and holds
  const TwinStatus after = sim.status();
  const double predicted = 0.5 * 1.0 * 2.0;  // 50 % of max_horizontal_m_s for 2 s
  EXPECT_NEAR(after.x_m - before.x_m, predicted, 0.2 * predicted);
  EXPECT_NEAR(after.y_m - before.y_m, 0.0, 0.05);
  EXPECT_NEAR(after.z_m, 1.0, 0.05);
  EXPECT_LT(after.speed_m_s, 0.05);
}

TEST_F(TwinFlight, SticksFollowTelloSemanticsInTheContractsFrame) {
  TwinSim& sim = make_sim();
  take_off(sim);
  ASSERT_TRUE(sim.rc(50, 0, 0, 0).ok);  // a > 0: right
  sim.step_to(sim.time_s() + 2.0);
  EXPECT_GT(sim.status().y_m, 0.6);
  EXPECT_NEAR(sim.status().body_vy_m_s, 0.5, 0.05);
  ASSERT_TRUE(sim.rc(0, 0, 50, 0).ok);  // c > 0: up at 0.4 m/s
  const double z0 = sim.status().z_m;
  sim.step_to(sim.time_s() + 1.0);
  EXPECT_NEAR(sim.status().vz_m_s, 0.4, 0.05);
  EXPECT_GT(sim.status().z_m - z0, 0.3);
  ASSERT_TRUE(sim.rc(0, 0, 0, 50).ok);  // d > 0: clockwise at 50 deg/s
  sim.step_to(sim.time_s() + 2.0);
  EXPECT_NEAR(sim.status().heading_deg, 100.0, 15.0);
  // Forward now points along the heading: about +y (right) in the world.
  ASSERT_TRUE(sim.rc(0, 100, 0, 0).ok);
  sim.step_to(sim.time_s() + 2.0);
  const TwinStatus s = sim.status();
  EXPECT_NEAR(s.body_vx_m_s, 1.0, 0.1);
  EXPECT_GT(s.vy_m_s, 0.8);
  EXPECT_NEAR(s.speed_m_s, std::hypot(s.vx_m_s, s.vy_m_s, s.vz_m_s), 1e-12);
}

TEST_F(TwinFlight, LandEndsOnTheFloorDisarmed) {
  TwinSim& sim = make_sim();
  take_off(sim);
  ASSERT_TRUE(sim.land().ok);
  EXPECT_EQ(sim.mode(), TwinMode::kLanding);
  sim.step_to(sim.time_s() + 1.0);
  EXPECT_NEAR(sim.status().vz_m_s, -0.5, 0.05);  // descends at land_descent_m_s
  sim.step_to(sim.time_s() + 3.0);
  const TwinStatus s = sim.status();
  EXPECT_EQ(s.mode, TwinMode::kLanded);
  EXPECT_NEAR(s.z_m, 0.0, 0.005);
  for (const double f : s.motor_thrust_n) EXPECT_LT(f, 1e-6);
  EXPECT_EQ(s.collisions, 0);
  EXPECT_EQ(sim.rc(0, 50, 0, 0).error, "not flying");
  EXPECT_TRUE(sim.takeoff().ok);  // and it can fly again
}

TEST_F(TwinFlight, EmergencyCutsTheMotorsAndItFalls) {
  TwinSim& sim = make_sim();
  take_off(sim);
  ASSERT_TRUE(sim.emergency().ok);
  EXPECT_EQ(sim.mode(), TwinMode::kFalling);
  sim.step_to(sim.time_s() + 0.2);
  const TwinStatus falling = sim.status();
  EXPECT_LT(falling.vz_m_s, -1.0);
  for (const double f : falling.motor_thrust_n) EXPECT_LT(f, 0.01);  // spun down (25 ms lag)
  EXPECT_EQ(sim.land().error, "motors stopped");
  sim.step_to(sim.time_s() + 2.0);
  // From 1 m it meets the floor at ~4.4 m/s: above the 2 m/s crash speed.
  EXPECT_EQ(sim.mode(), TwinMode::kCrashed);
  EXPECT_NEAR(sim.status().z_m, 0.0, 0.01);
}

TEST_F(TwinFlight, EmergencyBelowTheCrashSpeedLands) {
  TwinOptions options;
  options.crash_speed_m_s = 6.0;
  TwinSim& sim = make_sim(options);
  take_off(sim);
  ASSERT_TRUE(sim.emergency().ok);
  sim.step_to(sim.time_s() + 2.0);
  EXPECT_EQ(sim.mode(), TwinMode::kLanded);
}

TEST_F(TwinFlight, CommandsAnswerLikeATello) {
  TwinSim& sim = make_sim();
  EXPECT_EQ(sim.land().error, "not flying");
  EXPECT_EQ(sim.hover().error, "not flying");
  EXPECT_TRUE(sim.emergency().ok);  // ok whatever the state
  EXPECT_EQ(sim.mode(), TwinMode::kLanded);
  ASSERT_TRUE(sim.takeoff().ok);
  EXPECT_EQ(sim.takeoff().error, "already flying");
  EXPECT_TRUE(sim.rc(0, 20, 0, 0).ok);  // stored; applies once the climb is done
  EXPECT_EQ(sim.rc(0, 101, 0, 0).error, "rc values must be within -100...100");
  sim.step_to(5.0);
  ASSERT_TRUE(sim.land().ok);
  EXPECT_TRUE(sim.land().ok);  // landing already: ok
  EXPECT_EQ(sim.rc(0, 0, 0, 0).error, "landing");
  EXPECT_EQ(sim.takeoff().error, "landing");
  EXPECT_EQ(sim.status().last_command_age_s, 0.0);
  sim.step_to(sim.time_s() + 0.5);
  EXPECT_NEAR(sim.status().last_command_age_s, 0.5, 1e-9);
}

TEST_F(TwinFlight, TimeNeverGoesBack) {
  TwinSim& sim = make_sim();
  sim.step_to(1.0);
  sim.step_to(0.5);
  EXPECT_EQ(sim.time_s(), 1.0);
  sim.step_to(1.0009);  // less than one step: nothing
  EXPECT_EQ(sim.time_s(), 1.0);
  sim.step_to(1.001);
  EXPECT_NEAR(sim.time_s(), 1.0, 1e-12);
  sim.step_to(1.002);
  EXPECT_NEAR(sim.time_s(), 1.002, 1e-12);
  EXPECT_EQ(sim.data()->time, sim.time_s());
}

// Flies a script with noise on the reports; returns every status and the final qpos.
std::vector<TwinStatus> fly_script(TwinSim& sim) {
  sim.set_faults(FaultSchedule::from_json_text(R"([
      {"type": "sensor_noise", "start_s": 0, "position_sigma_m": 0.02, "heading_sigma_deg": 1},
      {"type": "wind_gust", "start_s": 7, "duration_s": 0.5, "force_n": [0, 0.1, 0]}])"));
  std::vector<TwinStatus> out;
  sim.takeoff();
  for (int i = 1; i <= 120; ++i) {
    sim.step_to(i * 0.1);
    out.push_back(sim.status());
    if (i == 50) sim.rc(10, 40, 0, -30);
    if (i == 90) sim.hover();
  }
  return out;
}

bool bitwise_equal(const TwinStatus& a, const TwinStatus& b) {
  return a.x_m == b.x_m && a.y_m == b.y_m && a.z_m == b.z_m && a.vx_m_s == b.vx_m_s &&
         a.vy_m_s == b.vy_m_s && a.vz_m_s == b.vz_m_s && a.heading_deg == b.heading_deg &&
         a.battery_pct == b.battery_pct && a.motor_thrust_n == b.motor_thrust_n &&
         a.mode == b.mode && a.time_s == b.time_s;
}

TEST_F(TwinFlight, SameSeedSameTrajectoryBitForBit) {
  TwinSim& a = make_sim({}, 7);
  TwinSim& b = make_sim({}, 7);
  TwinSim& c = make_sim({}, 8);
  const auto ta = fly_script(a);
  const auto tb = fly_script(b);
  const auto tc = fly_script(c);
  ASSERT_EQ(ta.size(), tb.size());
  for (std::size_t i = 0; i < ta.size(); ++i) {
    ASSERT_TRUE(bitwise_equal(ta[i], tb[i])) << "differs at sample " << i;
  }
  const int nq = a.model()->nq;
  EXPECT_EQ(std::memcmp(a.data()->qpos, b.data()->qpos, sizeof(mjtNum) * nq), 0);
  // Another seed: other sensor noise, but the physics does not see the noise.
  EXPECT_FALSE(bitwise_equal(ta.back(), tc.back()));
  EXPECT_EQ(std::memcmp(a.data()->qpos, c.data()->qpos, sizeof(mjtNum) * nq), 0);
  EXPECT_GT(a.status().x_m, 0.5);  // it did fly somewhere
}

TEST_F(TwinFlight, NormalFlightRaisesNoMuJoCoWarnings) {
  TwinSim& sim = make_sim();
  fly_script(sim);
  sim.land();
  sim.step_to(sim.time_s() + 5);
  EXPECT_EQ(sim.mode(), TwinMode::kLanded);
  EXPECT_TRUE(sim.mujoco_warnings().empty());
}

}  // namespace
}  // namespace gbdcs::sim
