// The radio faults the adapter applies: link loss and telemetry delay/jitter (simulated time).
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "twin_test_support.hpp"

namespace gbdcs::sim {
namespace {

using contracts::FlightState;
using control::Result;
using testing::TwinRig;

TwinAdapterOptions with_faults(const char* json) {
  TwinAdapterOptions o;
  o.twin.faults = FaultSchedule::from_json(nlohmann::json::parse(json));
  return o;
}

TEST(TwinFaults, LinkLossDropsCommandsAndTelemetryThenRecovers) {
  TwinRig rig(with_faults(R"([{"type": "link_loss", "start_s": 5, "duration_s": 3}])"));
  ASSERT_EQ(rig.twin.connect(), Result::kOk);
  ASSERT_EQ(rig.twin.takeoff(), Result::kOk);
  rig.run(4.0);
  // A timed move whose stop falls inside the loss: the stop cannot reach the drone either.
  ASSERT_EQ(rig.twin.move({0.3, 0, 0, 0, 2.0}), Result::kOk);
  rig.run(1.5);  // t = 5.5: link down
  EXPECT_EQ(rig.twin.hover(), Result::kNotConnected);
  EXPECT_NE(rig.twin.last_error().find("link lost"), std::string::npos);
  EXPECT_EQ(rig.twin.land(), Result::kNotConnected);
  EXPECT_EQ(rig.twin.emergency_stop(), Result::kNotConnected);
  EXPECT_EQ(rig.twin.move({0, 0, 0, 0, 0}), Result::kNotConnected);
  rig.run(2.0);  // t = 7.5: still down, still flying the move (its stop was due at 6)
  EXPECT_NEAR(rig.twin.twin_status().body_vx_m_s, 0.3, 0.1);
  EXPECT_EQ(rig.twin.state(), FlightState::kFlying);

  rig.run(2.0);  // t = 9.5: back; the stop went out at 8 and it braked
  EXPECT_LT(rig.twin.twin_status().speed_m_s, 0.1);
  EXPECT_EQ(rig.twin.hover(), Result::kOk);

  std::vector<double> samples;
  for (const auto& r : rig.frames) samples.push_back(rig.sample_s(r.frame));
  const auto in_window = std::count_if(samples.begin(), samples.end(),
                                       [](double t) { return t >= 5.0 - 1e-6 && t < 8.0 - 1e-6; });
  EXPECT_EQ(in_window, 0);
  const auto before = std::count_if(samples.begin(), samples.end(), [](double t) { return t < 5; });
  const auto after = std::count_if(samples.begin(), samples.end(), [](double t) { return t >= 8; });
  EXPECT_GE(before, 149);  // 30 Hz from 0 to 5 s
  EXPECT_GE(after, 44);    // and again from 8 to 9.5 s
}

TEST(TwinFaults, ConnectFailsWhileTheLinkIsDown) {
  TwinRig rig(with_faults(R"([{"type": "link_loss", "start_s": 0, "duration_s": 1}])"));
  EXPECT_EQ(rig.twin.connect(), Result::kNotConnected);
  EXPECT_EQ(rig.twin.state(), FlightState::kInit);
  rig.run(1.0);
  EXPECT_EQ(rig.twin.connect(), Result::kOk);
}

// Delay of each frame: when it arrived minus when it was sampled.
std::vector<double> delays(const TwinRig& rig) {
  std::vector<double> out;
  for (const auto& r : rig.frames) out.push_back(r.arrived_s - rig.sample_s(r.frame));
  return out;
}

TEST(TwinFaults, TelemetryDelayShiftsFramesAndKeepsTheirSampleTime) {
  TwinRig prompt;
  TwinRig late(with_faults(
      R"([{"type": "telemetry_delay", "start_s": 2, "duration_s": 2, "delay_ms": 300}])"));
  for (auto* rig : {&prompt, &late}) {
    ASSERT_EQ(rig->twin.connect(), Result::kOk);
    rig->twin.takeoff();
    rig->run(6.0);
  }
  // Same frames (sampled at the same times, same content), delivered later.
  ASSERT_EQ(prompt.frames.size(), late.frames.size());
  for (std::size_t i = 0; i < late.frames.size(); ++i) {
    const auto& p = prompt.frames[i].frame;
    const auto& l = late.frames[i].frame;
    EXPECT_EQ(p.timestamp, l.timestamp);
    EXPECT_DOUBLE_EQ(p.altitude_m, l.altitude_m);
    const double sample_s = prompt.sample_s(p);
    const double delay_s = late.frames[i].arrived_s - sample_s;
    if (sample_s >= 2.0 && sample_s < 4.0 - 1e-6) {
      EXPECT_NEAR(delay_s, 0.3, 0.011) << "sampled at " << sample_s;
    } else if (sample_s < 2.0 - 1e-6) {
      EXPECT_LT(delay_s, 0.011);
    } else {
      // Frames after the window queue behind the last delayed one (never out of order).
      EXPECT_LE(delay_s, 0.3 + 0.011);
    }
  }
  for (double d : delays(prompt)) EXPECT_LT(d, 0.011);  // one poll (10 ms) at most
}

TEST(TwinFaults, JitterIsSeededAndNeverReorders) {
  const char* faults =
      R"([{"type": "telemetry_delay", "start_s": 0, "delay_ms": 200, "jitter_ms": 80}])";
  auto fly = [&](std::uint32_t seed) {
    auto o = with_faults(faults);
    o.seed = seed;
    auto rig = std::make_unique<TwinRig>(o);
    EXPECT_EQ(rig->twin.connect(), Result::kOk);
    rig->run(5.0, 0.001);
    return rig;
  };
  auto a = fly(1), b = fly(1), c = fly(2);
  const auto da = delays(*a), db = delays(*b), dc = delays(*c);
  ASSERT_GT(da.size(), 140u);
  EXPECT_EQ(da, db);  // same seed, same delays
  EXPECT_NE(da, dc);  // another seed, other jitter
  std::set<long> distinct;
  for (double d : da) {
    EXPECT_GE(d, 0.12 - 0.0011);
    EXPECT_LE(d, 0.28 + 0.0011);  // queueing behind an earlier frame never adds beyond that
    distinct.insert(static_cast<long>(d * 1000));
  }
  EXPECT_GT(distinct.size(), 20u);  // it really jitters
  for (std::size_t i = 1; i < a->frames.size(); ++i) {
    EXPECT_LT(a->sample_s(a->frames[i - 1].frame), a->sample_s(a->frames[i].frame));
    EXPECT_LE(a->frames[i - 1].arrived_s, a->frames[i].arrived_s);
  }
}

}  // namespace
}  // namespace gbdcs::sim
