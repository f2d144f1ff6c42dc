// The contract every DroneAdapter keeps, run against each drone (dummy, the twin, and the
// real protocol adapters flying the twin's emulators over loopback sockets).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "contract_rigs.hpp"
#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::adapters::testing {
namespace {

using contracts::FlightState;
using control::Result;

class AdapterContract : public ::testing::TestWithParam<RigCase> {
 protected:
  void SetUp() override { rig_ = GetParam().make(); }
  control::DroneAdapter& drone() { return rig_->adapter(); }

  // Connected, airborne and hovering near 1 m.
  void fly_up() {
    ASSERT_EQ(drone().connect(), Result::kOk) << drone().last_error();
    rig_->run(0.5);
    ASSERT_EQ(drone().takeoff(), Result::kOk) << drone().last_error();
    ASSERT_TRUE(rig_->run_until([&] { return rig_->last_frame().altitude_m > 0.8; }, 10))
        << "altitude " << rig_->last_frame().altitude_m;
    rig_->run(1.5);  // the climb ends in a hover
    ASSERT_EQ(drone().state(), FlightState::kFlying);
  }

  std::unique_ptr<Rig> rig_;
};

TEST_P(AdapterContract, ConnectsAndReportsReady) {
  EXPECT_EQ(drone().state(), FlightState::kInit);
  ASSERT_EQ(drone().connect(), Result::kOk) << drone().last_error();
  EXPECT_EQ(drone().state(), FlightState::kReady);
  rig_->run(1.0);
  ASSERT_GT(rig_->frame_count(), 0u);
  EXPECT_EQ(rig_->last_frame().flight_state, FlightState::kReady);
  EXPECT_LT(rig_->last_frame().altitude_m, 0.05);
  EXPECT_EQ(drone().disconnect(), Result::kOk);
}

TEST_P(AdapterContract, RefusesTakeoffBeforeReady) {
  EXPECT_EQ(drone().takeoff(), Result::kNotConnected);
  EXPECT_FALSE(drone().last_error().empty());
  EXPECT_EQ(drone().move({0.5, 0, 0, 0, 1}), Result::kNotConnected);
  ASSERT_EQ(drone().connect(), Result::kOk) << drone().last_error();
  EXPECT_EQ(drone().land(), Result::kRejected);   // on the ground
  EXPECT_EQ(drone().hover(), Result::kRejected);  // nothing to hold
  ASSERT_EQ(drone().takeoff(), Result::kOk) << drone().last_error();
  rig_->run(0.2);
  EXPECT_EQ(drone().takeoff(), Result::kRejected);  // not READY: already flying
}

TEST_P(AdapterContract, TakesOffHoversAndLands) {
  fly_up();
  EXPECT_EQ(drone().hover(), Result::kOk) << drone().last_error();
  rig_->run(2.0);
  const auto hovering = rig_->last_frame();
  EXPECT_GT(hovering.altitude_m, 0.6);
  EXPECT_LT(hovering.altitude_m, 1.5);
  EXPECT_LT(hovering.speed_m_s, 0.3);
  EXPECT_EQ(hovering.flight_state, FlightState::kFlying);

  ASSERT_EQ(drone().land(), Result::kOk) << drone().last_error();
  EXPECT_EQ(drone().state(), FlightState::kLanding);
  ASSERT_TRUE(rig_->run_until([&] { return drone().state() == FlightState::kReady; }, 15))
      << "still " << contracts::to_string(drone().state());
  rig_->run(0.5);
  EXPECT_LT(rig_->last_frame().altitude_m, 0.1);
  EXPECT_EQ(rig_->last_frame().flight_state, FlightState::kReady);
}

TEST_P(AdapterContract, MovesForwardThenStopsAfterTheDuration) {
  fly_up();
  const auto start = rig_->last_frame();
  ASSERT_EQ(drone().move({0.5, 0, 0, 0, 2.0}), Result::kOk) << drone().last_error();
  rig_->run(1.0);
  EXPECT_GT(rig_->last_frame().vx_m_s, 0.2);  // body frame: forward
  rig_->run(3.0);                              // the move ended after 2 s
  const auto after = rig_->last_frame();
  EXPECT_GT(after.x_m - start.x_m, 0.5);
  EXPECT_LT(std::abs(after.y_m - start.y_m), 0.3);
  EXPECT_LT(after.speed_m_s, 0.2);
  EXPECT_EQ(after.flight_state, FlightState::kFlying);
}

TEST_P(AdapterContract, YawsClockwise) {
  fly_up();
  const double h0 = rig_->last_frame().heading_deg;
  ASSERT_EQ(drone().move({0, 0, 0, 45, 1.0}), Result::kOk) << drone().last_error();
  rig_->run(2.5);
  double turned = rig_->last_frame().heading_deg - h0;
  if (turned < -180) turned += 360;
  if (turned > 180) turned -= 360;
  EXPECT_GT(turned, 20);
  EXPECT_LT(turned, 70);
}

TEST_P(AdapterContract, EmergencyStopCutsTheMotors) {
  fly_up();
  ASSERT_EQ(drone().emergency_stop(), Result::kOk) << drone().last_error();
  EXPECT_NE(drone().state(), FlightState::kFlying);
  ASSERT_TRUE(rig_->run_until(
      [&] {
        const auto s = drone().state();
        return s == FlightState::kReady || s == FlightState::kFault;
      },
      5))
      << "still " << contracts::to_string(drone().state());
  rig_->run(0.5);
  EXPECT_LT(rig_->last_frame().altitude_m, 0.1);
  EXPECT_NE(drone().hover(), Result::kOk);  // on the ground: nothing to hover
}

TEST_P(AdapterContract, TelemetryShapeAndRate) {
  ASSERT_EQ(drone().connect(), Result::kOk) << drone().last_error();
  rig_->run(0.2);
  rig_->clear_frames();
  const double start = rig_->now_s();
  rig_->run(5.0);
  const auto frames = rig_->frames();
  const double elapsed = rig_->now_s() - start;
  EXPECT_GE(static_cast<double>(frames.size()), 5.0 * elapsed - 2) << "below 5 Hz";
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto problems = contracts::violations("telemetry_frame", contracts::to_json(frames[i]));
    EXPECT_TRUE(problems.empty()) << problems.front();
    EXPECT_GE(frames[i].heading_deg, 0);
    EXPECT_LT(frames[i].heading_deg, 360);
    EXPECT_GE(frames[i].battery_pct, 0);
    EXPECT_LE(frames[i].battery_pct, 100);
    EXPECT_EQ(frames[i].link, contracts::LinkState::kOk);
    if (i > 0) {
      EXPECT_GE(frames[i].timestamp, frames[i - 1].timestamp);
    }
  }
}

TEST_P(AdapterContract, LinkLossAndRecovery) {
  fly_up();
  rig_->set_link_lost(true);
  rig_->run(0.2);
  rig_->clear_frames();
  rig_->run(2.8);
  // During the loss: no frame says the link is fine after the adapter noticed, and commands
  // do not pretend to work.
  EXPECT_NE(drone().hover(), Result::kOk);
  const auto during = rig_->frames();
  const auto ok_frames = std::count_if(during.begin(), during.end(), [](const auto& f) {
    return f.link == contracts::LinkState::kOk;
  });
  EXPECT_LE(ok_frames, 3) << "telemetry kept flowing through a lost link";

  rig_->set_link_lost(false);
  rig_->clear_frames();
  ASSERT_TRUE(rig_->run_until(
      [&] {
        const auto frames = rig_->frames();
        return !frames.empty() && frames.back().link == contracts::LinkState::kOk;
      },
      3))
      << "no telemetry after the link came back";
  EXPECT_EQ(drone().hover(), Result::kOk) << drone().last_error();
  rig_->run(1.0);
  EXPECT_EQ(drone().state(), FlightState::kFlying);
  EXPECT_GT(rig_->last_frame().altitude_m, 0.5);
}

INSTANTIATE_TEST_SUITE_P(AllDrones, AdapterContract, ::testing::ValuesIn(all_rigs()),
                         [](const ::testing::TestParamInfo<RigCase>& p) { return p.param.name; });

}  // namespace
}  // namespace gbdcs::adapters::testing
