// TwinAdapter: the twin behind control::DroneAdapter, on a ManualClock (lockstep).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "gbdcs/contracts/codec.hpp"
#include "twin_test_support.hpp"

namespace gbdcs::sim {
namespace {

using contracts::FlightState;
using control::Result;
using testing::TwinRig;

// The flight states the telemetry went through, consecutive duplicates merged.
std::vector<FlightState> state_sequence(const std::vector<testing::Received>& frames) {
  std::vector<FlightState> out;
  for (const auto& r : frames) {
    if (out.empty() || out.back() != r.frame.flight_state) out.push_back(r.frame.flight_state);
  }
  return out;
}

TEST(TwinAdapter, StateMachineInitReadyFlyingLandingReady) {
  TwinRig rig;
  EXPECT_EQ(rig.twin.name(), "twin");
  EXPECT_EQ(rig.twin.state(), FlightState::kInit);
  EXPECT_EQ(rig.twin.takeoff(), Result::kNotConnected);
  EXPECT_NE(rig.twin.last_error().find("not connected"), std::string::npos);

  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  EXPECT_EQ(rig.twin.state(), FlightState::kReady);
  rig.run(0.5);
  EXPECT_EQ(rig.twin.land(), Result::kRejected);  // the twin refuses: it is on the ground
  EXPECT_FALSE(rig.twin.last_error().empty());

  ASSERT_EQ(rig.twin.takeoff(), Result::kOk);
  EXPECT_EQ(rig.twin.state(), FlightState::kFlying);
  rig.run(4.0);
  const auto hovering = rig.twin.snapshot();
  EXPECT_NEAR(hovering.altitude_m, 1.0, 0.15);
  EXPECT_EQ(rig.twin.hover(), Result::kOk);

  ASSERT_EQ(rig.twin.land(), Result::kOk);
  EXPECT_EQ(rig.twin.state(), FlightState::kLanding);
  ASSERT_TRUE(rig.run_until([&] { return rig.twin.state() == FlightState::kReady; }, 8.0));
  rig.run(0.5);
  EXPECT_LT(rig.twin.snapshot().altitude_m, 0.03);

  const auto seq = state_sequence(rig.frames);
  const std::vector<FlightState> expected = {FlightState::kReady, FlightState::kFlying,
                                             FlightState::kLanding, FlightState::kReady};
  EXPECT_EQ(seq, expected);
  EXPECT_EQ(rig.twin.disconnect(), Result::kOk);
  EXPECT_EQ(rig.twin.hover(), Result::kNotConnected);
}

TEST(TwinAdapter, TelemetryAtThirtyHertzOfSimulatedTimeWhateverThePolling) {
  TwinRig rig;
  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  rig.twin.takeoff();
  rig.run(10.0, /*poll_s=*/0.25);      // a slow host loop still gets every frame
  ASSERT_GE(rig.frames.size(), 299u);  // 30 Hz x 10 s
  EXPECT_LE(rig.frames.size(), 301u);
  double max_gap_s = 0;
  for (std::size_t i = 1; i < rig.frames.size(); ++i) {
    const double gap = rig.sample_s(rig.frames[i].frame) - rig.sample_s(rig.frames[i - 1].frame);
    EXPECT_GT(gap, 0);
    max_gap_s = std::max(max_gap_s, gap);
  }
  EXPECT_LE(max_gap_s, 1.0 / 20);  // >= 20 Hz in simulated time
  for (const auto& r : rig.frames) {
    // A frame arrives at the poll after its sample, never before it, and meets its schema.
    EXPECT_LE(rig.sample_s(r.frame), r.arrived_s + 1e-9);
    const auto problems = contracts::violations("telemetry_frame", contracts::to_json(r.frame));
    EXPECT_TRUE(problems.empty()) << problems.front();
  }
}

TEST(TwinAdapter, TelemetryFrameMatchesTheTwin) {
  TwinRig rig;
  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  rig.twin.takeoff();
  rig.run(4.0);
  rig.twin.rc(0, 50, 0, 0);
  rig.run(2.0);
  const auto s = rig.twin.twin_status();
  const auto f = rig.twin.snapshot();
  EXPECT_DOUBLE_EQ(f.altitude_m, s.z_m);  // in the air: no clamping
  EXPECT_DOUBLE_EQ(f.vx_m_s, s.body_vx_m_s);
  EXPECT_DOUBLE_EQ(f.speed_m_s, s.speed_m_s);
  EXPECT_DOUBLE_EQ(f.battery_pct, s.battery_pct);
  EXPECT_NEAR(f.x_m, s.x_m, 1e-9);  // the session origin is where it stood at connect
  EXPECT_GT(f.x_m, 0.4);            // forward
  EXPECT_NEAR(f.vx_m_s, 0.5, 0.1);  // rc b 50 = half of max_horizontal_m_s 1.0
  EXPECT_LT(f.battery_pct, 100);
  EXPECT_EQ(f.link, contracts::LinkState::kOk);
}

TEST(TwinAdapter, MotionMapsToRcAgainstTheConfiguredMaxima) {
  FlightControllerOptions maxima;  // 1.0 m/s, 0.8 m/s, 100 deg/s
  contracts::MotionPayload m{0.5, -0.25, 0.4, 50, 0};
  EXPECT_EQ(motion_to_rc(m, maxima), (std::array<int, 4>{-25, 50, 50, 50}));
  contracts::MotionPayload fast{3.0, 5.0, -2.0, -400, 1};
  EXPECT_EQ(motion_to_rc(fast, maxima), (std::array<int, 4>{100, 100, -100, -100}));
  maxima.max_horizontal_m_s = 2.0;
  EXPECT_EQ(motion_to_rc(contracts::MotionPayload{0.4, 0, 0, 0, 0}, maxima)[1], 20);
}

TEST(TwinAdapter, TimedMoveHoldsForItsDurationThenStops) {
  TwinRig rig;
  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  rig.twin.takeoff();
  rig.run(4.0);
  const double x0 = rig.twin.snapshot().x_m;
  ASSERT_EQ(rig.twin.move({0.5, 0, 0, 0, 2.0}), Result::kOk);
  rig.run(1.9);
  EXPECT_NEAR(rig.twin.snapshot().vx_m_s, 0.5, 0.1);  // still flying the move
  rig.run(2.1);
  const auto stopped = rig.twin.snapshot();
  EXPECT_LT(stopped.speed_m_s, 0.1);  // rc 0 0 0 0 came at 2.0 s and it braked
  // 2 s at 0.5 m/s, less the time to reach the speed, plus the braking distance.
  EXPECT_NEAR(stopped.x_m - x0, 1.0, 0.3);

  // duration 0: held until the next command.
  ASSERT_EQ(rig.twin.move({0, 0, 0, 50, 0}), Result::kOk);
  const double h0 = rig.twin.snapshot().heading_deg;
  rig.run(3.0);
  const double turned = std::fmod(rig.twin.snapshot().heading_deg - h0 + 360.0, 360.0);
  EXPECT_NEAR(turned, 150, 25);  // 50 deg/s clockwise, still turning after 3 s
  ASSERT_EQ(rig.twin.hover(), Result::kOk);
  rig.run(2.0);
  EXPECT_LT(rig.twin.snapshot().speed_m_s, 0.1);
}

TEST(TwinAdapter, AnyCommandCancelsTheTimedStop) {
  TwinRig rig;
  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  rig.twin.takeoff();
  rig.run(4.0);
  ASSERT_EQ(rig.twin.move({0.4, 0, 0, 0, 1.0}), Result::kOk);
  rig.run(0.5);
  ASSERT_EQ(rig.twin.rc(0, 40, 0, 0), Result::kOk);  // held: no stop from the earlier move
  rig.run(2.0);
  EXPECT_NEAR(rig.twin.snapshot().vx_m_s, 0.4, 0.1);
}

TEST(TwinAdapter, RcOutOfRangeIsRejectedNotClamped) {
  TwinRig rig;
  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  EXPECT_EQ(rig.twin.rc(0, 101, 0, 0), Result::kRejected);
  EXPECT_NE(rig.twin.last_error().find("[-100, 100]"), std::string::npos);
  EXPECT_EQ(rig.twin.move({0, 0, 0, 0, -1}), Result::kRejected);
}

TEST(TwinAdapter, EmergencyFromOneMetreCrashesIntoFault) {
  TwinRig rig;
  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  rig.twin.takeoff();
  rig.run(4.0);
  ASSERT_EQ(rig.twin.emergency_stop(), Result::kOk);
  EXPECT_EQ(rig.twin.state(), FlightState::kLanding);  // falling
  ASSERT_TRUE(rig.run_until([&] { return rig.twin.state() == FlightState::kFault; }, 3.0));
  rig.run(0.2);
  EXPECT_EQ(rig.frames.back().frame.flight_state, FlightState::kFault);
  EXPECT_EQ(rig.twin.takeoff(), Result::kRejected);  // a crashed twin refuses everything
  EXPECT_FALSE(rig.twin.last_error().empty());
}

TEST(TwinAdapter, OptionsFromJsonAreStrict) {
  auto o = TwinAdapterOptions::from_json(nlohmann::json::parse(
      R"({"telemetry_hz": 50, "realtime": true, "seed": 7,
          "twin": {"controller": {"max_horizontal_m_s": 2.0}}})"));
  EXPECT_EQ(o.telemetry_hz, 50);
  EXPECT_TRUE(o.realtime);
  EXPECT_EQ(o.seed, 7u);
  EXPECT_EQ(o.twin.controller.max_horizontal_m_s, 2.0);
  auto fails_with = [](const char* text, const std::string& needle) {
    try {
      TwinAdapterOptions::from_json(nlohmann::json::parse(text));
      ADD_FAILURE() << "accepted " << text;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  fails_with(R"({"telemetry_hz": 10})", "'telemetry_hz' must be within [20, 200]");
  fails_with(R"({"telemtry_hz": 30})", "'telemtry_hz' is not a known option");
  fails_with(R"({"realtime": 1})", "'realtime' must be true or false");
  fails_with(R"({"seed": -1})", "'seed'");
  fails_with(R"({"twin": {"bogus": 1}})", "'twin'");
}

TEST(TwinAdapter, RealtimeThreadStepsWithTheClock) {
  // A ManualClock stands in for the steady clock: the thread follows whatever now() says.
  TwinAdapterOptions o;
  o.realtime = true;
  TwinRig rig(o);
  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  rig.clock.advance(contracts::from_seconds(1.0));
  const bool caught_up = [&] {
    for (int i = 0; i < 2000; ++i) {  // the thread steps 200 times a wall second
      {
        std::lock_guard lock(rig.mutex);
        if (rig.frames.size() >= 30) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }();
  EXPECT_TRUE(caught_up);
  EXPECT_NEAR(rig.twin.sim_time_s(), 1.0, 0.01);
  rig.twin.disconnect();  // joins the thread
  std::lock_guard lock(rig.mutex);
  EXPECT_LE(rig.frames.size(), 31u);
}

}  // namespace
}  // namespace gbdcs::sim
