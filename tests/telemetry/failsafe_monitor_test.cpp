#include <gtest/gtest.h>

#include "gbdcs/telemetry/failsafe_monitor.hpp"

namespace gbdcs::telemetry {
namespace {

using contracts::CommandType;
using contracts::FlightState;
using contracts::Severity;

class FailsafeTest : public ::testing::Test {
 protected:
  FailsafeTest()
      : monitor(clock, FailsafeSinks{
                           [this](const contracts::DroneCommand& c) { commands.push_back(c); },
                           [this](const contracts::Alert& a) { alerts.push_back(a); },
                           [this](const std::string& r, bool on) { inhibits.emplace_back(r, on); }}) {}

  contracts::TelemetryFrame frame(FlightState state, double battery = 90,
                                  contracts::LinkState link = contracts::LinkState::kOk) {
    contracts::TelemetryFrame f;
    f.flight_state = state;
    f.battery_pct = battery;
    f.link = link;
    return f;
  }
  // Telemetry at 10 Hz for `seconds`, operator silent; timers ticked every frame.
  void fly_for(double seconds, FlightState state = FlightState::kFlying, double battery = 90) {
    for (int i = 0; i < static_cast<int>(seconds * 10); ++i) {
      clock.advance(contracts::from_seconds(0.1));
      monitor.on_telemetry(frame(state, battery));
      monitor.tick();
    }
  }
  void silence_for(double seconds) {
    for (int i = 0; i < static_cast<int>(seconds * 20); ++i) {
      clock.advance(contracts::from_seconds(0.05));
      monitor.tick();
    }
  }
  std::vector<std::string> codes() const {
    std::vector<std::string> out;
    for (const auto& a : alerts) out.push_back(a.code);
    return out;
  }

  contracts::ManualClock clock;
  std::vector<contracts::DroneCommand> commands;
  std::vector<contracts::Alert> alerts;
  std::vector<std::pair<std::string, bool>> inhibits;
  FailsafeMonitor monitor;
};

TEST_F(FailsafeTest, NoTelemetryForTwoSecondsHoversAndAlerts) {
  monitor.start();
  fly_for(1.0);
  monitor.note_operator_input();
  const auto lost_at = clock.now();
  silence_for(1.9);
  EXPECT_TRUE(commands.empty());
  silence_for(0.2);  // 2.1 s without a frame
  ASSERT_EQ(commands.size(), 1u);
  EXPECT_EQ(commands[0].type, CommandType::kHover);
  EXPECT_EQ(commands[0].source, contracts::CommandSource::kFailsafe);
  EXPECT_EQ(commands[0].source_id, "LINK_LOSS");
  ASSERT_EQ(codes(), std::vector<std::string>{"LINK_LOSS"});
  EXPECT_EQ(alerts[0].severity, Severity::kCritical);
  EXPECT_LE(contracts::to_seconds(clock.now() - lost_at), 2.1 + 1e-9);
  silence_for(5);  // once per episode
  EXPECT_EQ(commands.size(), 1u);
  monitor.on_telemetry(frame(FlightState::kFlying));
  ASSERT_GE(codes().size(), 2u);
  EXPECT_EQ(codes()[1], "LINK_RESTORED");
  // The operator was silent through the outage, so the idle rule applies at once too.
  EXPECT_EQ(codes().back(), "IDLE_HOVER");
  EXPECT_FALSE(monitor.link_lost());
}

TEST_F(FailsafeTest, LinkTimerOnlyAfterStart) {
  silence_for(10);
  EXPECT_TRUE(alerts.empty());
}

TEST_F(FailsafeTest, LinkLostFlagInTelemetryActsAtOnce) {
  monitor.start();
  monitor.on_telemetry(frame(FlightState::kFlying, 90, contracts::LinkState::kLost));
  ASSERT_EQ(codes(), std::vector<std::string>{"LINK_LOSS"});
  EXPECT_EQ(commands.size(), 1u);
}

TEST_F(FailsafeTest, IdleForThreeSecondsWhileFlyingHovers) {
  monitor.start();
  fly_for(2.9);
  EXPECT_TRUE(commands.empty());
  fly_for(0.3);
  ASSERT_EQ(commands.size(), 1u);
  EXPECT_EQ(commands[0].source_id, "IDLE_HOVER");
  EXPECT_EQ(codes(), std::vector<std::string>{"IDLE_HOVER"});
  EXPECT_NE(alerts[0].cause.find("Idle – hovering"), std::string::npos);
  EXPECT_TRUE(monitor.idle_hovering());
  fly_for(5);
  EXPECT_EQ(commands.size(), 1u);  // not repeated while still idle
  monitor.note_operator_input();
  EXPECT_FALSE(monitor.idle_hovering());
  fly_for(2);
  EXPECT_EQ(commands.size(), 1u);
  fly_for(1.5);
  EXPECT_EQ(commands.size(), 2u);  // idle again after 3 s without input
}

TEST_F(FailsafeTest, OperatorInputKeepsItFlying) {
  monitor.start();
  for (int i = 0; i < 10; ++i) {
    fly_for(2);
    monitor.note_operator_input();
  }
  EXPECT_TRUE(commands.empty());
}

TEST_F(FailsafeTest, NoIdleHoverOnTheGround) {
  monitor.start();
  fly_for(10, FlightState::kReady);
  EXPECT_TRUE(commands.empty());
  EXPECT_TRUE(alerts.empty());
}

TEST_F(FailsafeTest, BatteryWarnsBelowThirtyAndLandsBelowFifteen) {
  monitor.start();
  monitor.note_operator_input();
  monitor.on_telemetry(frame(FlightState::kFlying, 31));
  EXPECT_TRUE(alerts.empty());
  monitor.on_telemetry(frame(FlightState::kFlying, 29.5));
  ASSERT_EQ(codes(), std::vector<std::string>{"BATTERY_LOW"});
  EXPECT_EQ(alerts[0].severity, Severity::kWarning);
  monitor.on_telemetry(frame(FlightState::kFlying, 29));
  EXPECT_EQ(alerts.size(), 1u);  // once
  EXPECT_TRUE(commands.empty());
  monitor.on_telemetry(frame(FlightState::kFlying, 14.9));
  EXPECT_EQ(codes().back(), "BATTERY_CRITICAL");
  ASSERT_EQ(commands.size(), 1u);
  EXPECT_EQ(commands[0].type, CommandType::kLand);
  ASSERT_EQ(inhibits.size(), 1u);
  EXPECT_TRUE(inhibits[0].second);
  monitor.on_telemetry(frame(FlightState::kLanding, 14));
  EXPECT_EQ(commands.size(), 1u);
  EXPECT_TRUE(monitor.battery_critical());
}

TEST_F(FailsafeTest, BatteryJumpStraightToCriticalAlsoWarns) {
  monitor.start();
  monitor.on_telemetry(frame(FlightState::kReady, 10));
  EXPECT_EQ(codes(), std::vector<std::string>{"BATTERY_CRITICAL"});
  EXPECT_TRUE(commands.empty());  // on the ground: nothing to land, take-off inhibited
  ASSERT_EQ(inhibits.size(), 1u);
  monitor.on_telemetry(frame(FlightState::kReady, 100));  // swapped
  ASSERT_EQ(inhibits.size(), 2u);
  EXPECT_FALSE(inhibits[1].second);
}

TEST_F(FailsafeTest, VisionUnhealthyHoversWhenFlying) {
  monitor.start();
  monitor.on_telemetry(frame(FlightState::kFlying));
  monitor.on_vision_health(false, "camera closed");
  ASSERT_EQ(codes(), std::vector<std::string>{"VISION_UNHEALTHY"});
  EXPECT_EQ(alerts[0].severity, Severity::kCritical);
  EXPECT_NE(alerts[0].cause.find("camera closed"), std::string::npos);
  ASSERT_EQ(commands.size(), 1u);
  EXPECT_EQ(commands[0].type, CommandType::kHover);
  monitor.on_vision_health(false, "still closed");
  EXPECT_EQ(alerts.size(), 1u);
  monitor.on_vision_health(true, "");
  EXPECT_EQ(codes().back(), "VISION_RESTORED");
  EXPECT_FALSE(inhibits.back().second);
}

TEST_F(FailsafeTest, VisionUnhealthyOnGroundWarnsOnly) {
  monitor.start();
  monitor.on_telemetry(frame(FlightState::kReady));
  monitor.on_vision_health(false, "no frames");
  EXPECT_EQ(alerts[0].severity, Severity::kWarning);
  EXPECT_TRUE(commands.empty());
  EXPECT_TRUE(inhibits[0].second);
}

TEST(FailsafeOptions, RejectsBadOptions) {
  EXPECT_THROW(FailsafeOptions::from_json({{"link_timeout", 2}}), std::invalid_argument);
  EXPECT_THROW(FailsafeOptions::from_json({{"link_timeout_s", -1}}), std::invalid_argument);
  EXPECT_THROW(FailsafeOptions::from_json({{"battery_land_pct", 40}}), std::invalid_argument);
  EXPECT_DOUBLE_EQ(FailsafeOptions::from_json({{"idle_timeout_s", 5}}).idle_timeout_s, 5);
}

}  // namespace
}  // namespace gbdcs::telemetry
