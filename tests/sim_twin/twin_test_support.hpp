// Shared by the sim_twin tests: one loaded model, a ManualClock-driven twin and a frame log.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/sim/twin_adapter.hpp"

namespace gbdcs::sim::testing {

inline std::shared_ptr<const TwinModel> shared_model() {
  static const auto model =
      std::make_shared<const TwinModel>(GBDCS_SOURCE_DIR "/sim/models/quadrotor.xml");
  return model;
}

// A frame as received: when it arrived (simulated seconds) and what it says.
struct Received {
  double arrived_s = 0;
  contracts::TelemetryFrame frame;
};

// A twin on a ManualClock, polled lockstep like the scenario runner does.
class TwinRig {
 public:
  explicit TwinRig(TwinAdapterOptions options = {})
      : twin(clock, shared_model(), std::move(options)) {
    twin.set_telemetry_sink([this](const contracts::TelemetryFrame& f) {
      std::lock_guard lock(mutex);
      frames.push_back({now_s(), f});
    });
  }

  // A MuJoCo warning fails the test that caused it.
  ~TwinRig() {
    twin.inspect([](const TwinSim& s) {
      for (const auto& w : s.mujoco_warnings()) ADD_FAILURE() << "MuJoCo warning: " << w;
    });
  }

  double now_s() const { return contracts::to_seconds(clock.now()); }

  // Advances `seconds` of simulated time, polling every `poll_s`.
  void run(double seconds, double poll_s = 0.01) {
    const auto steps = static_cast<long>(seconds / poll_s + 0.5);
    for (long i = 0; i < steps; ++i) {
      clock.advance(contracts::from_seconds(poll_s));
      twin.poll();
    }
  }
  // Runs until `done()` or `limit_s` passes; returns whether done() became true.
  template <class Pred>
  bool run_until(Pred done, double limit_s, double poll_s = 0.01) {
    for (double t = 0; t < limit_s; t += poll_s) {
      if (done()) return true;
      run(poll_s, poll_s);
    }
    return done();
  }
  // Seconds since the session's UTC origin of a frame's timestamp.
  double sample_s(const contracts::TelemetryFrame& f) const {
    return std::chrono::duration<double>(f.timestamp - utc_origin).count();
  }

  contracts::ManualClock clock;
  contracts::UtcTime utc_origin = clock.utc_now();
  TwinAdapter twin;
  std::mutex mutex;
  std::vector<Received> frames;
};

}  // namespace gbdcs::sim::testing
