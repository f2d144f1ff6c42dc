// The rigs of the adapter contract suite: every drone on a ManualClock (lockstep), the
// networked ones talking to the twin's emulators over real loopback sockets. step() moves
// simulated time, lets the twin and the adapter run, then waits (real time, generous
// deadline) until every datagram/RPC in flight has been handled, so results do not depend
// on how loaded the machine is.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/control/drone_adapter.hpp"
#include "gbdcs/adapters/airsim_adapter.hpp"
#include "gbdcs/sim/airsim_emulator.hpp"
#include "gbdcs/sim/twin_host.hpp"
#include "gbdcs/sim/twin_model.hpp"
#include <nlohmann/json.hpp>

namespace gbdcs::adapters::testing {

inline std::shared_ptr<const sim::TwinModel> shared_model() {
  static const auto model =
      std::make_shared<const sim::TwinModel>(GBDCS_SOURCE_DIR "/sim/models/quadrotor.xml");
  return model;
}

// Waits (real time) until `done()`; false after `limit`.
template <class Pred>
bool await(Pred done, std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return true;
}

class Rig {
 public:
  virtual ~Rig() = default;
  virtual control::DroneAdapter& adapter() = 0;
  virtual void set_link_lost(bool lost) = 0;

  // Connects the frame log to the adapter; call once the adapter exists.
  void attach() {
    adapter().set_telemetry_sink([this](const contracts::TelemetryFrame& f) {
      std::lock_guard lock(mutex_);
      frames_.push_back(f);
    });
  }
  double now_s() const { return contracts::to_seconds(clock.now()); }
  void run(double seconds, double step_s = 0.05) {
    const auto steps = static_cast<long>(seconds / step_s + 0.5);
    for (long i = 0; i < steps; ++i) step(step_s);
  }
  template <class Pred>
  bool run_until(Pred done, double limit_s, double step_s = 0.05) {
    for (double t = 0; t < limit_s; t += step_s) {
      if (done()) return true;
      step(step_s);
    }
    return done();
  }
  std::vector<contracts::TelemetryFrame> frames() const {
    std::lock_guard lock(mutex_);
    return frames_;
  }
  std::size_t frame_count() const {
    std::lock_guard lock(mutex_);
    return frames_.size();
  }
  contracts::TelemetryFrame last_frame() const {
    std::lock_guard lock(mutex_);
    return frames_.empty() ? contracts::TelemetryFrame{} : frames_.back();
  }
  void clear_frames() {
    std::lock_guard lock(mutex_);
    frames_.clear();
  }

  contracts::ManualClock clock;

 protected:
  virtual void step(double dt_s) = 0;

 private:
  mutable std::mutex mutex_;
  std::vector<contracts::TelemetryFrame> frames_;
};

// AirSimAdapter -> the twin's AirSim emulator over loopback TCP (exposed for AirSim's own tests).
class AirSimRig final : public Rig {
 public:
  explicit AirSimRig(nlohmann::json extra_options = {});
  ~AirSimRig() override;
  control::DroneAdapter& adapter() override;
  void set_link_lost(bool lost) override;
  AirSimAdapter& airsim() { return *drone_; }
  sim::AirSimEmulator& emulator() { return emulator_; }
  sim::TwinHost& host() { return host_; }
  void settle();

 protected:
  void step(double dt_s) override;

 private:
  static sim::AirSimEmulatorOptions emulator_options();
  sim::TwinHost host_;
  sim::AirSimEmulator emulator_;
  std::unique_ptr<AirSimAdapter> drone_;
};

using RigFactory = std::function<std::unique_ptr<Rig>()>;

struct RigCase {
  std::string name;
  RigFactory make;
};

// Defined in contract_rigs.cpp: dummy, twin, tello (-> TelloEmulator), and the others as they
// exist.
std::vector<RigCase> all_rigs();
std::unique_ptr<Rig> make_rig(const std::string& name);

}  // namespace gbdcs::adapters::testing
