#include "gbdcs/sim/battery_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

namespace gbdcs::sim {
namespace {

MotorThrusts equal(double total_n) {
  return {total_n / 4, total_n / 4, total_n / 4, total_n / 4};
}
constexpr double kHoverN = 0.08 * 9.81;

TEST(BatteryModel, HoverLastsAboutATelloFlight) {
  BatteryModel b;
  const double power = b.power_w(equal(kHoverN));
  // idle 2 W + 50 W/N^1.5 * 4 * (0.196 N)^1.5
  EXPECT_NEAR(power, 2.0 + 50.0 * 4 * std::pow(kHoverN / 4, 1.5), 1e-9);
  const double current = b.current_for_power_a(power);
  EXPECT_NEAR(current * (4.2 - current * 0.06), power, 1e-9);  // P = I (Voc - I R) at 100 %
  const double minutes = 1100.0 / 1000.0 / current * 60.0;
  EXPECT_GT(minutes, 11.0);  // the Tello's 13 min, give or take
  EXPECT_LT(minutes, 15.0);
}

TEST(BatteryModel, DrainsAtTheModelledRate) {
  BatteryModel b;
  double expected_mah = 0;
  for (int i = 0; i < 30'000; ++i) {  // 60 s at 2 ms
    expected_mah += b.current_for_power_a(b.power_w(equal(kHoverN))) * 0.002 / 3.6;
    b.step(0.002, equal(kHoverN));
  }
  EXPECT_NEAR(1100.0 - b.remaining_mah(), expected_mah, 1e-6);
  // ... which is about 5 A for a minute: 83 mAh, 7.6 %.
  EXPECT_NEAR(100.0 - b.pct(), 7.6, 0.6);
}

TEST(BatteryModel, MoreThrustDrainsFasterAndSagsMore) {
  BatteryModel hover;
  BatteryModel climb;
  hover.step(1.0, equal(kHoverN));
  climb.step(1.0, equal(1.6));
  EXPECT_GT(climb.current_a(), hover.current_a());
  EXPECT_LT(climb.pct(), hover.pct());
  EXPECT_LT(climb.voltage_v(), hover.voltage_v());
  EXPECT_LT(hover.voltage_v(), hover.open_circuit_voltage_v());  // sag under load
  EXPECT_NEAR(hover.open_circuit_voltage_v() - hover.voltage_v(), hover.current_a() * 0.06, 1e-12);
}

TEST(BatteryModel, VoltageFollowsTheChargeAndJumpsSetIt) {
  BatteryModel b;
  EXPECT_NEAR(b.voltage_v(), 4.2, 1e-12);
  b.set_pct(50);
  EXPECT_NEAR(b.open_circuit_voltage_v(), 3.8, 1e-12);
  b.set_pct(-5);
  EXPECT_EQ(b.pct(), 0.0);
  EXPECT_TRUE(b.empty());
  b.step(10.0, equal(kHoverN));
  EXPECT_EQ(b.pct(), 0.0);  // never below empty
  b.set_pct(250);
  EXPECT_EQ(b.pct(), 100.0);
}

TEST(BatteryModel, OptionsFromJson) {
  const auto o =
      BatteryOptions::from_json(nlohmann::json{{"capacity_mah", 2000}, {"start_pct", 40}});
  BatteryModel b(o);
  EXPECT_NEAR(b.remaining_mah(), 800, 1e-9);
  EXPECT_THROW(BatteryOptions::from_json(nlohmann::json{{"capacity", 1}}), std::invalid_argument);
  EXPECT_THROW(BatteryOptions::from_json(nlohmann::json{{"capacity_mah", 0}}),
               std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::sim
