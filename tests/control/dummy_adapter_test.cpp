#include <gtest/gtest.h>

#include "gbdcs/adapters/dummy_adapter.hpp"
#include "gbdcs/adapters/registry.hpp"

namespace gbdcs::adapters {
namespace {

using contracts::FlightState;
using control::Result;

class DummyTest : public ::testing::Test {
 protected:
  void run(double seconds) {
    for (int i = 0; i < static_cast<int>(seconds * 100); ++i) {
      clock.advance(contracts::from_seconds(0.01));
      drone.poll();
    }
  }
  contracts::ManualClock clock;
  DummyDroneAdapter drone{clock};
  std::vector<contracts::TelemetryFrame> frames;
  void SetUp() override {
    drone.set_telemetry_sink([this](const contracts::TelemetryFrame& f) { frames.push_back(f); });
  }
};

TEST_F(DummyTest, CommandsNeedConnection) {
  EXPECT_EQ(drone.takeoff(), Result::kNotConnected);
  EXPECT_EQ(drone.state(), FlightState::kInit);
  EXPECT_EQ(drone.connect(), Result::kOk);
  EXPECT_EQ(drone.state(), FlightState::kReady);
}

TEST_F(DummyTest, TakesOffMovesAndLands) {
  drone.connect();
  EXPECT_EQ(drone.land(), Result::kRejected);
  EXPECT_EQ(drone.takeoff(), Result::kOk);
  run(3);
  EXPECT_EQ(drone.state(), FlightState::kFlying);
  EXPECT_NEAR(drone.snapshot().altitude_m, 1.0, 0.05);
  EXPECT_EQ(drone.move({0, 0.5, 0, 0, 2.0}), Result::kOk);  // right for 2 s
  run(3);
  EXPECT_NEAR(drone.snapshot().y_m, 1.0, 0.05);
  EXPECT_NEAR(drone.snapshot().speed_m_s, 0, 1e-9);  // the timed move ended in a hover
  EXPECT_EQ(drone.move({0, 0, 0, 90, 1.0}), Result::kOk);
  run(1.5);
  EXPECT_NEAR(drone.snapshot().heading_deg, 90, 1.0);
  EXPECT_EQ(drone.move({1.0, 0, 0, 0, 1.0}), Result::kOk);  // forward is now +y
  run(1.5);
  EXPECT_NEAR(drone.snapshot().y_m, 2.0, 0.05);
  EXPECT_EQ(drone.land(), Result::kOk);
  run(4);
  EXPECT_EQ(drone.state(), FlightState::kReady);
  EXPECT_DOUBLE_EQ(drone.snapshot().altitude_m, 0);
}

TEST_F(DummyTest, TelemetryAtTenHertzWithDrainingBattery) {
  drone.connect();
  drone.takeoff();
  run(10);
  EXPECT_NEAR(static_cast<double>(frames.size()), 100.0, 2.0);
  EXPECT_LT(frames.back().battery_pct, frames.front().battery_pct);
  EXPECT_NEAR(frames.front().battery_pct - frames.back().battery_pct, 2.5, 0.2);
}

TEST_F(DummyTest, LinkLossDropsCommandsAndTelemetry) {
  drone.connect();
  drone.set_link_lost(true);
  run(1);
  EXPECT_TRUE(frames.empty());
  EXPECT_EQ(drone.takeoff(), Result::kNotConnected);
  drone.set_link_lost(false);
  run(1);
  EXPECT_FALSE(frames.empty());
}

TEST_F(DummyTest, EmergencyStopFalls) {
  drone.connect();
  drone.takeoff();
  run(3);
  EXPECT_EQ(drone.emergency_stop(), Result::kOk);
  run(1);
  EXPECT_DOUBLE_EQ(drone.snapshot().altitude_m, 0);
  EXPECT_EQ(drone.state(), FlightState::kFault);  // a 1 m drop hits at ~4.4 m/s: a crash
}

TEST_F(DummyTest, EmptyBatteryForcesLanding) {
  drone.connect();
  drone.takeoff();
  run(3);
  drone.set_battery_pct(0.01);
  run(4);
  EXPECT_EQ(drone.state(), FlightState::kReady);
  EXPECT_EQ(drone.takeoff(), Result::kRejected);
}

TEST(Registry, MakesDummyAndRejectsUnknown) {
  contracts::ManualClock clock;
  auto a = make_adapter("dummy", clock);
  EXPECT_EQ(a->name(), "dummy");
  try {
    make_adapter("mavic", clock);
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("known: dummy"), std::string::npos);
  }
  EXPECT_THROW(make_adapter("dummy", clock, {{"warp", 9}}), std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::adapters
