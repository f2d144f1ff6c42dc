// The emulator drones of a scenario: the twin behind its Tello / AirSim / XFly emulator on a
// loopback port, flown by the REAL adapter (through the adapter registry) over real sockets.
//
// Lockstep over sockets. The runner owns simulated time; the sockets deliver in real time.
// Each step is therefore a small handshake (see docs/SCENARIOS.md, "Emulator drones"):
//   advance(t): the twin (TwinHost, lockstep) is stepped to t by the runner's thread, so the
//               emulator's state stream and deferred replies for t go out; then settle();
//               only then does the adapter's own clock move to t.
//   settle():   waits (real time, bounded) until every datagram / RPC frame sent either way
//               has been handled on the other side, from the adapter's and the emulator's
//               counters. Nothing is sent spontaneously in between (the emulator answers only
//               requests and the runner's steps; the adapter's timers read its clock, which
//               does not move while we wait), so equal counters mean a quiet link.
// The adapter gets a clock of its own that trails the core's until advance() has settled: its
// 10 ms I/O timer can fire at any real moment, but it never sees time t before the emulator's
// output for t has arrived, so what it does at t does not depend on thread scheduling.
#include <algorithm>
#include <chrono>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "gbdcs/adapters/airsim_adapter.hpp"
#include "gbdcs/adapters/registry.hpp"
#include "gbdcs/adapters/tello_adapter.hpp"
#include "gbdcs/sim/airsim_emulator.hpp"
#include "gbdcs/sim/tello_emulator.hpp"
#include "gbdcs/sim/twin_host.hpp"
#include "runner_parts.hpp"

namespace gbdcs::sim::detail {

namespace {

using WallClock = std::chrono::steady_clock;

// Real-time bound of one settle(): far beyond a loaded machine's scheduling delays; a link
// that is still busy after this is a fault of the rig, reported as the run's error.
constexpr auto kSettleLimit = std::chrono::seconds(10);

nlohmann::json object_or_empty(const nlohmann::json& v) {
  return v.is_object() ? v : nlohmann::json::object();
}

// The emulator drone's options: {"adapter": {...}, "emulator": {...}, "twin": {...},
// "seed": N}. Strict, so a typo is named.
struct EmulatorDroneOptions {
  nlohmann::json adapter = nlohmann::json::object();
  nlohmann::json emulator = nlohmann::json::object();
  TwinOptions twin;
  std::uint32_t seed = 1;

  static EmulatorDroneOptions from_json(const nlohmann::json& doc, std::string_view kind) {
    EmulatorDroneOptions o;
    const std::string owner = "drone.options (" + std::string(kind) + ")";
    const auto given = object_or_empty(doc);
    for (const auto& [key, value] : given.items()) {
      if (key == "adapter" || key == "emulator") {
        if (!value.is_object()) {
          throw std::invalid_argument(owner + "." + key + ": must be an object of the " + key +
                                      "'s options");
        }
        (key == "adapter" ? o.adapter : o.emulator) = value;
      } else if (key == "twin") {
        o.twin = TwinOptions::from_json(value);
      } else if (key == "seed") {
        if (!value.is_number_unsigned() || value.get<std::uint64_t>() > 0xffffffffULL) {
          throw std::invalid_argument(owner + ".seed: must be an integer in [0, 4294967295]");
        }
        o.seed = static_cast<std::uint32_t>(value.get<std::uint64_t>());
      } else {
        throw std::invalid_argument(owner + ": unknown key '" + key +
                                    "'; use adapter, emulator, twin or seed");
      }
    }
    for (const char* fixed : {"address", "command_port", "port", "state_port", "bind_address"}) {
      if (o.adapter.contains(fixed) || o.emulator.contains(fixed)) {
        throw std::invalid_argument(owner + ": '" + fixed +
                                    "' is the runner's (a loopback port of its own); remove it");
      }
    }
    return o;
  }
};

// A clock the drone moves by hand; the core's ManualClock is never moved from here.
class TrailingClock final : public contracts::Clock {
 public:
  explicit TrailingClock(const contracts::Clock& core) : core_(core), utc_origin_(core.utc_now()) {}
  contracts::Duration now() const override {
    std::lock_guard lock(mutex_);
    return now_;
  }
  contracts::UtcTime utc_now() const override {
    std::lock_guard lock(mutex_);
    return utc_origin_ + std::chrono::duration_cast<contracts::UtcTime::duration>(now_);
  }
  void catch_up() {
    std::lock_guard lock(mutex_);
    now_ = core_.now();
  }

 private:
  const contracts::Clock& core_;
  contracts::UtcTime utc_origin_;
  mutable std::mutex mutex_;
  contracts::Duration now_{0};
};

class EmulatorDrone : public ScenarioDrone {
 public:
  EmulatorDrone(const Scenario& s, const contracts::Clock& clock,
                std::shared_ptr<const TwinModel> model, const EmulatorDroneOptions& options)
      : adapter_clock_(clock), host_(clock, std::move(model), host_options(s, options)) {
    for (const auto& e : s.events) {
      if (e.type == EventType::kTelemetryDelay) {
        throw std::invalid_argument(
            "the " + std::string(to_string(s.drone.kind)) +
            " has no telemetry_delay fault (the twin adapter models it, the emulators do not); "
            "fly the twin (\"drone\": \"twin\") for that event");
      }
    }
  }

  control::DroneAdapter& adapter() override { return *adapter_; }
  void on_event(const ScenarioEvent&, bool) override {}  // all in the twin's fault schedule
  std::optional<int> collisions() const override {
    return const_cast<TwinHost&>(host_).with_sim([](TwinSim& sim) { return sim.status().collisions; });
  }
  std::vector<double> pose_qpos() const override {
    return const_cast<TwinHost&>(host_).with_sim([](TwinSim& sim) {
      const int adr = sim.twin_model().free_joint_qpos_address();
      return std::vector<double>(sim.data()->qpos + adr, sim.data()->qpos + adr + 7);
    });
  }

  bool advance() override {
    host_.poll();  // the twin to the core clock's now: state stream, deferred replies
    const bool ok = settle();
    adapter_clock_.catch_up();
    return ok;
  }

  bool settle() override {
    const auto until = WallClock::now() + kSettleLimit;
    auto pause = std::chrono::microseconds(20);
    while (!quiet()) {
      if (WallClock::now() > until) {
        settle_error_ = "the " + describe() + " link did not settle within " +
                        std::to_string(kSettleLimit.count()) + " s of real time (" + counters() +
                        "); is the machine overloaded?";
        return false;
      }
      std::this_thread::sleep_for(pause);
      pause = std::min(pause * 2, std::chrono::microseconds(1000));
    }
    return true;
  }
  std::string settle_error() const override { return settle_error_; }
  void count_frames_taken(std::function<std::uint64_t()> taken) override {
    frames_taken_ = std::move(taken);
  }

 protected:
  static TwinHostOptions host_options(const Scenario& s, const EmulatorDroneOptions& o) {
    TwinHostOptions h;
    h.seed = o.seed;
    h.twin = o.twin;
    h.twin.faults = faults_of(s, o.twin.faults.faults());
    return h;
  }
  virtual bool quiet() const = 0;
  virtual std::string counters() const = 0;

  std::uint64_t frames_taken() const { return frames_taken_ ? frames_taken_() : 0; }

  TrailingClock adapter_clock_;
  TwinHost host_;
  std::function<std::uint64_t()> frames_taken_;
  std::unique_ptr<control::DroneAdapter> adapter_;
  std::string settle_error_;
};

// Tello and XFly: the Tello engine against the TelloEmulator (the XFly profile's words).
class TelloEmulatorDrone final : public EmulatorDrone {
 public:
  TelloEmulatorDrone(const Scenario& s, const contracts::Clock& clock,
                     std::shared_ptr<const TwinModel> model, bool xfly)
      : TelloEmulatorDrone(s, clock, std::move(model), xfly,
                           EmulatorDroneOptions::from_json(s.drone.options,
                                                           to_string(s.drone.kind))) {}
  ~TelloEmulatorDrone() override { adapter_.reset(); }  // before the emulator it talks to

  std::string describe() const override {
    return std::string(xfly_ ? "XFly" : "Tello") + " emulator (udp://127.0.0.1:" +
           std::to_string(emulator_->port()) + ")";
  }

 private:
  TelloEmulatorDrone(const Scenario& s, const contracts::Clock& clock,
                     std::shared_ptr<const TwinModel> model, bool xfly,
                     const EmulatorDroneOptions& o)
      : EmulatorDrone(s, clock, std::move(model), o), xfly_(xfly) {
    auto e = TelloEmulatorOptions::from_json(o.emulator);
    e.bind_address = "127.0.0.1";
    e.command_port = 0;
    e.label = xfly ? "xfly" : "tello";
    emulator_ = std::make_unique<TelloEmulator>(host_, e);
    nlohmann::json a = {{"reply_timeout_ms", 3000}};  // a loaded 2-core machine
    a.update(o.adapter);
    a["address"] = "127.0.0.1";
    a["bind_address"] = "127.0.0.1";
    a["command_port"] = emulator_->port();
    a["state_port"] = 0;
    adapter_ = adapters::make_adapter(xfly ? "xfly" : "tello", adapter_clock_, a);
    tello_ = dynamic_cast<adapters::TelloAdapter*>(adapter_.get());
    if (!tello_) throw std::logic_error("the registry's tello/xfly adapter is not the Tello engine");
    emulator_->set_state_port(tello_->local_state_port());
  }

  bool quiet() const override {
    const auto a = tello_->stats();
    const auto e = emulator_->stats();
    return e.datagrams + e.dropped >= a.commands_sent &&
           a.state_packets + a.malformed_packets >= e.state_packets && a.replies >= e.replies &&
           frames_taken() >= a.frames;
  }
  std::string counters() const override {
    const auto a = tello_->stats();
    const auto e = emulator_->stats();
    return "adapter sent " + std::to_string(a.commands_sent) + ", emulator got " +
           std::to_string(e.datagrams + e.dropped) + "; emulator sent " +
           std::to_string(e.state_packets) + " states and " + std::to_string(e.replies) +
           " replies, adapter got " + std::to_string(a.state_packets + a.malformed_packets) +
           " and " + std::to_string(a.replies) + "; adapter made " + std::to_string(a.frames) +
           " frames, the core took " + std::to_string(frames_taken());
  }

  bool xfly_;
  std::unique_ptr<TelloEmulator> emulator_;
  adapters::TelloAdapter* tello_ = nullptr;
};

class AirSimEmulatorDrone final : public EmulatorDrone {
 public:
  AirSimEmulatorDrone(const Scenario& s, const contracts::Clock& clock,
                      std::shared_ptr<const TwinModel> model)
      : AirSimEmulatorDrone(s, clock, std::move(model),
                            EmulatorDroneOptions::from_json(s.drone.options,
                                                            to_string(s.drone.kind))) {}
  ~AirSimEmulatorDrone() override { adapter_.reset(); }

  std::string describe() const override {
    return "AirSim emulator (tcp://127.0.0.1:" + std::to_string(emulator_->port()) + ")";
  }

 private:
  AirSimEmulatorDrone(const Scenario& s, const contracts::Clock& clock,
                      std::shared_ptr<const TwinModel> model, const EmulatorDroneOptions& o)
      : EmulatorDrone(s, clock, std::move(model), o) {
    AirSimEmulatorOptions e;
    for (const auto& [key, value] : o.emulator.items()) {
      if (key != "vehicle" || !value.is_string()) {
        throw std::invalid_argument("drone.options.emulator." + key +
                                    ": the AirSim emulator takes only 'vehicle' (a string)");
      }
      e.vehicle = value.get<std::string>();
    }
    e.bind_address = "127.0.0.1";
    e.port = 0;
    emulator_ = std::make_unique<AirSimEmulator>(host_, e);
    nlohmann::json a = {{"rpc_timeout_ms", 3000}, {"connect_timeout_ms", 5000}};
    a.update(o.adapter);
    a["address"] = "127.0.0.1";
    a["port"] = emulator_->port();
    adapter_ = adapters::make_adapter("airsim", adapter_clock_, a);
    airsim_ = dynamic_cast<adapters::AirSimAdapter*>(adapter_.get());
    if (!airsim_) throw std::logic_error("the registry's airsim adapter is not AirSimAdapter");
  }

  bool quiet() const override {
    const auto a = airsim_->stats();
    const auto e = emulator_->stats();
    return e.requests + e.malformed + a.lost_requests >= a.requests &&
           a.responses >= e.responses && frames_taken() >= a.states + a.link_losses;
  }
  std::string counters() const override {
    const auto a = airsim_->stats();
    const auto e = emulator_->stats();
    return "adapter sent " + std::to_string(a.requests) + " requests, emulator got " +
           std::to_string(e.requests) + "; emulator sent " + std::to_string(e.responses) +
           " responses, adapter got " + std::to_string(a.responses) + "; adapter made " +
           std::to_string(a.states + a.link_losses) + " frames, the core took " +
           std::to_string(frames_taken());
  }

  std::unique_ptr<AirSimEmulator> emulator_;
  adapters::AirSimAdapter* airsim_ = nullptr;
};

}  // namespace

std::unique_ptr<ScenarioDrone> make_emulator_drone(const Scenario& s,
                                                   const contracts::Clock& clock,
                                                   std::shared_ptr<const TwinModel> model) {
  switch (s.drone.kind) {
    case DroneKind::kTelloEmulator:
      return std::make_unique<TelloEmulatorDrone>(s, clock, std::move(model), false);
    case DroneKind::kXflyEmulator:
      return std::make_unique<TelloEmulatorDrone>(s, clock, std::move(model), true);
    case DroneKind::kAirsimEmulator:
      return std::make_unique<AirSimEmulatorDrone>(s, clock, std::move(model));
    default: break;
  }
  throw std::invalid_argument("drone '" + std::string(to_string(s.drone.kind)) +
                              "' is not an emulator drone");
}

}  // namespace gbdcs::sim::detail
