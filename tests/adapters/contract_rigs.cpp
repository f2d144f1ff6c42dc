#include "contract_rigs.hpp"

#include <nlohmann/json.hpp>

#include "gbdcs/adapters/airsim_adapter.hpp"
#include "gbdcs/adapters/dummy_adapter.hpp"
#include "gbdcs/adapters/tello_adapter.hpp"
#include "gbdcs/adapters/xfly_profile.hpp"
#include "gbdcs/sim/airsim_emulator.hpp"
#include "gbdcs/sim/tello_emulator.hpp"
#include "gbdcs/sim/twin_adapter.hpp"
#include "gbdcs/sim/twin_host.hpp"

namespace gbdcs::adapters::testing {
namespace {

class DummyRig final : public Rig {
 public:
  DummyRig() : drone_(clock) { attach(); }
  control::DroneAdapter& adapter() override { return drone_; }
  void set_link_lost(bool lost) override { drone_.set_link_lost(lost); }

 protected:
  void step(double dt_s) override {
    clock.advance(contracts::from_seconds(dt_s));
    drone_.poll();
  }

 private:
  DummyDroneAdapter drone_;
};

class TwinRig final : public Rig {
 public:
  TwinRig() : twin_(clock, shared_model()) { attach(); }
  control::DroneAdapter& adapter() override { return twin_; }
  void set_link_lost(bool lost) override {
    const double t = twin_.sim_time_s();
    if (lost) {
      lost_since_ = t;
      twin_.set_faults(sim::FaultSchedule::from_json(
          nlohmann::json::array({{{"type", "link_loss"}, {"start_s", t}}})));
    } else {
      twin_.set_faults(sim::FaultSchedule::from_json(nlohmann::json::array(
          {{{"type", "link_loss"}, {"start_s", lost_since_}, {"duration_s", t - lost_since_}}})));
    }
  }

 protected:
  void step(double dt_s) override {
    clock.advance(contracts::from_seconds(dt_s));
    twin_.poll();
  }

 private:
  sim::TwinAdapter twin_;
  double lost_since_ = 0;
};

// A Tello-protocol drone (Tello or an XFly profile) flying the twin through the emulator.
class TelloRig final : public Rig {
 public:
  TelloRig(const nlohmann::json& adapter_options, const sim::TelloEmulatorOptions& emulator,
           const TelloOptions& defaults)
      : host_(clock, shared_model()), emulator_(host_, emulator) {
    nlohmann::json o = adapter_options;
    o["address"] = "127.0.0.1";
    o["bind_address"] = "127.0.0.1";
    o["command_port"] = emulator_.port();
    o["state_port"] = 0;
    o["reply_timeout_ms"] = 3000;  // a loaded 2-core machine
    o["ack_wait_ms"] = 100;
    drone_ = std::make_unique<TelloAdapter>(clock, TelloOptions::from_json(o, defaults));
    emulator_.set_state_port(drone_->local_state_port());
    attach();
  }
  control::DroneAdapter& adapter() override { return *drone_; }
  void set_link_lost(bool lost) override { emulator_.set_link_lost(lost); }
  TelloAdapter& tello() { return *drone_; }
  sim::TelloEmulator& emulator() { return emulator_; }
  sim::TwinHost& host() { return host_; }

 protected:
  void step(double dt_s) override {
    clock.advance(contracts::from_seconds(dt_s));
    host_.poll();
    drone_->poll();
    settle();
  }

 private:
  // Every datagram sent either way has been handled.
  void settle() {
    const bool ok = await([&] {
      const auto a = drone_->stats();
      const auto e = emulator_.stats();
      return e.datagrams + e.dropped >= a.commands_sent &&
             a.state_packets + a.malformed_packets >= e.state_packets;
    });
    EXPECT_TRUE(ok) << "the emulator and the adapter did not settle in 10 s";
  }

  sim::TwinHost host_;
  sim::TelloEmulator emulator_;
  std::unique_ptr<TelloAdapter> drone_;
};

}  // namespace

AirSimRig::AirSimRig(nlohmann::json extra)
    : host_(clock, shared_model()), emulator_(host_, emulator_options()) {
  nlohmann::json o = {{"address", "127.0.0.1"}, {"port", emulator_.port()},
                      {"rpc_timeout_ms", 3000}, {"ack_wait_ms", 100},
                      {"connect_timeout_ms", 5000}};
  if (extra.is_object()) o.update(extra);
  drone_ = std::make_unique<AirSimAdapter>(clock, AirSimOptions::from_json(o));
  attach();
}

AirSimRig::~AirSimRig() = default;

sim::AirSimEmulatorOptions AirSimRig::emulator_options() {
  sim::AirSimEmulatorOptions e;
  e.port = 0;
  return e;
}

control::DroneAdapter& AirSimRig::adapter() { return *drone_; }
void AirSimRig::set_link_lost(bool lost) { emulator_.set_link_lost(lost); }

void AirSimRig::step(double dt_s) {
  clock.advance(contracts::from_seconds(dt_s));
  host_.poll();
  drone_->poll();
  settle();
}

void AirSimRig::settle() {
  const bool ok = await([&] {
    const auto a = drone_->stats();
    const auto e = emulator_.stats();
    return e.requests + e.malformed + a.lost_requests >= a.requests &&
           a.responses >= e.responses;
  });
  EXPECT_TRUE(ok) << "the AirSim emulator and the adapter did not settle in 10 s";
}

std::unique_ptr<Rig> make_rig(const std::string& name) {
  if (name == "dummy") return std::make_unique<DummyRig>();
  if (name == "twin") return std::make_unique<TwinRig>();
  if (name == "tello") {
    sim::TelloEmulatorOptions emulator;
    emulator.command_port = 0;
    return std::make_unique<TelloRig>(nlohmann::json::object(), emulator, TelloOptions{});
  }
  if (name == "airsim") return std::make_unique<AirSimRig>();
  if (name == "xfly") {
    // The XFly profile with its command words renamed on both sides: the profile is config.
    const nlohmann::json words = {{"handshake", "sdk_on"}, {"takeoff", "launch"},
                                  {"land", "descend"},     {"emergency", "kill"},
                                  {"stop", "halt"},        {"rc", "sticks"},
                                  {"keepalive", "sdk_on"}, {"battery", "bat?"}};
    sim::TelloEmulatorOptions emulator = sim::TelloEmulatorOptions::from_json(
        {{"command_port", 0}, {"commands", words}});
    emulator.label = "xfly";
    const XflyProfile profile;
    TelloOptions defaults;
    defaults.name = profile.name;
    defaults.drone_label = profile.label;
    defaults.wifi_hint = profile.wifi_hint;
    return std::make_unique<TelloRig>(xfly_engine_options({{"commands", words}}, profile),
                                      emulator, defaults);
  }
  throw std::invalid_argument("no rig named " + name);
}

std::vector<RigCase> all_rigs() {
  std::vector<RigCase> out;
  for (const char* n : {"dummy", "twin", "tello", "airsim", "xfly"}) {
    out.push_back({n, [name = std::string(n)] { return make_rig(name); }});
  }
  return out;
}

}  // namespace gbdcs::adapters::testing
