// Adapter swap at run time (issue 6): DroneService::connect(name, options) is the mechanism
// behind PUT /api/v1/config {"adapter": ...} and the one tested here, at the adapter level:
// a Tello (the real TelloAdapter -> the twin's Tello emulator over loopback UDP) flies and
// moves; the operator swaps to AirSim (the real AirSimAdapter -> a second twin's AirSim
// emulator over loopback TCP). The old drone is landed and disconnected (its emulator hears
// nothing more from it), its session ends; the new one starts READY on the ground, with
// nothing of the old flight carried over (no take-off, no motion), and then flies on its own.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <utility>
#include <vector>
#include <boost/asio.hpp>
#include <filesystem>
#include <unistd.h>

#include "contract_rigs.hpp"
#include "gbdcs/adapters/registry.hpp"
#include "gbdcs/adapters/tello_adapter.hpp"
#include "gbdcs/server/drone_service.hpp"
#include "gbdcs/server/live_hub.hpp"
#include "gbdcs/sim/tello_emulator.hpp"
#include "gbdcs/storage/storage_manager.hpp"

namespace gbdcs::adapters::testing {
namespace {

using contracts::CommandSource;
using contracts::CommandType;
using contracts::FlightState;
using nlohmann::json;

class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    path_ = std::filesystem::temp_directory_path() /
            ("gbdcs_swap_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

sim::TelloEmulatorOptions tello_emulator_options() {
  sim::TelloEmulatorOptions o;
  o.command_port = 0;
  return o;
}

sim::AirSimEmulatorOptions airsim_emulator_options() {
  sim::AirSimEmulatorOptions o;
  o.port = 0;
  return o;
}

// Every command the service's loops report, with its outcome.
class CommandLog final : public runtime::EventListener {
 public:
  void on_command(const contracts::DroneCommand& c, const std::string& outcome) override {
    std::lock_guard lock(mutex_);
    log_.emplace_back(c, outcome);
  }
  // The outcome of the last command of this type from this source id, or "" if none yet.
  std::string outcome_of(CommandType type, const std::string& source_id) const {
    std::lock_guard lock(mutex_);
    for (auto it = log_.rbegin(); it != log_.rend(); ++it) {
      if (it->first.type == type && it->first.source_id == source_id) return it->second;
    }
    return {};
  }
  std::size_t size() const {
    std::lock_guard lock(mutex_);
    return log_.size();
  }

 private:
  mutable std::mutex mutex_;
  std::vector<std::pair<contracts::DroneCommand, std::string>> log_;
};

// Two physical drones (two twins, each behind its emulator) and the server's drone service.
class SwapRig {
 public:
  SwapRig()
      : tello_host(clock, shared_model()),
        tello_emulator(tello_host, tello_emulator_options()),
        airsim_host(clock, shared_model()),
        airsim_emulator(airsim_host, airsim_emulator_options()),
        storage({.path = dir.file("gbdcs.db")}, clock),
        hub(clock) {
    service = std::make_unique<server::DroneService>(
        clock, storage, hub,
        [this](const std::string& name, const json&) { return make(name); },
        control::GestureProfile::builtin_default(), nullptr);
    service->add_listener(commands);
  }
  ~SwapRig() { service.reset(); }

  std::unique_ptr<control::DroneAdapter> make(const std::string& name) {
    if (name == "tello") {
      auto a = make_adapter("tello", clock,
                            {{"address", "127.0.0.1"}, {"bind_address", "127.0.0.1"},
                             {"command_port", tello_emulator.port()}, {"state_port", 0},
                             {"reply_timeout_ms", 3000}, {"ack_wait_ms", 100}});
      auto* t = dynamic_cast<TelloAdapter*>(a.get());
      tello_emulator.set_state_port(t->local_state_port());
      tello = t;
      return a;
    }
    auto a = make_adapter(name, clock,
                          {{"address", "127.0.0.1"}, {"port", airsim_emulator.port()},
                           {"rpc_timeout_ms", 3000}, {"ack_wait_ms", 100},
                           {"connect_timeout_ms", 5000}});
    airsim = dynamic_cast<AirSimAdapter*>(a.get());
    return a;
  }

  // One step of simulated time: both twins move, the camera shows no hand (vision alive),
  // the current adapter's timers run, and its traffic settles (real time, bounded).
  void step() {
    clock.advance(std::chrono::milliseconds(50));
    tello_host.poll();
    airsim_host.poll();
    json frame = {{"type", "frame"}, {"frame_id", ++frame_id}, {"hands", json::array()}};
    service->on_vision_frame(frame);
    // The adapter's timers at the new time (its state poll, rc stream, keep-alive), as the
    // runner's tick would; the service's own tick thread runs in real time besides.
    if (auto* t = tello.load()) t->poll();
    if (auto* s = airsim.load()) s->poll();
    bool ok = true;
    if (auto* t = tello.load()) {
      ok = await([&] {
        const auto a = t->stats();
        const auto e = tello_emulator.stats();
        return e.datagrams + e.dropped >= a.commands_sent &&
               a.state_packets + a.malformed_packets >= e.state_packets;
      });
    }
    if (auto* s = airsim.load()) {
      ok = ok && await([&] {
        const auto a = s->stats();
        const auto e = airsim_emulator.stats();
        return e.requests + e.malformed + a.lost_requests >= a.requests &&
               a.responses >= e.responses;
      });
    }
    EXPECT_TRUE(ok) << "the link did not settle in 10 s";
  }
  template <class Pred>
  bool run_until(Pred done, double limit_s) {
    for (double t = 0; t < limit_s; t += 0.05) {
      if (done()) return true;
      step();
    }
    return done();
  }
  // Submits as the API does and waits (real time, bounded) until the service's own tick
  // thread has dispatched it, so simulated time never runs ahead of a pending command.
  control::Decision submit(CommandType type, contracts::MotionPayload motion = {}) {
    contracts::DroneCommand c;
    c.type = type;
    c.source = CommandSource::kApi;
    c.source_id = "swap_test_" + std::to_string(++submitted);
    if (type == CommandType::kMove) c.payload = motion;
    c.issued_at = clock.utc_now();
    auto d = service->submit(c);
    if (!d || !d->accepted) return d ? *d : control::Decision{};
    EXPECT_TRUE(await([&] { return !commands->outcome_of(type, c.source_id).empty(); }))
        << "the service never dispatched " << contracts::to_string(type);
    EXPECT_EQ(commands->outcome_of(type, c.source_id), "OK");
    return *d;
  }

  void send_marker_to_tello_emulator() {
    boost::asio::io_context io;
    boost::asio::ip::udp::socket socket(io, boost::asio::ip::udp::endpoint(
                                                boost::asio::ip::make_address("127.0.0.1"), 0));
    const std::string marker = "gbdcs-swap-test-marker";
    socket.send_to(boost::asio::buffer(marker),
                   boost::asio::ip::udp::endpoint(boost::asio::ip::make_address("127.0.0.1"),
                                                  tello_emulator.port()));
  }

  static sim::TwinStatus status_of(sim::TwinHost& host) {
    return host.with_sim([](sim::TwinSim& s) { return s.status(); });
  }

  TempDir dir;
  contracts::ManualClock clock;
  sim::TwinHost tello_host;
  sim::TelloEmulator tello_emulator;
  sim::TwinHost airsim_host;
  sim::AirSimEmulator airsim_emulator;
  storage::StorageManager storage;
  server::LiveHub hub;
  std::unique_ptr<server::DroneService> service;
  std::atomic<TelloAdapter*> tello{nullptr};
  std::atomic<AirSimAdapter*> airsim{nullptr};
  std::int64_t frame_id = 0;
  int submitted = 0;
  std::shared_ptr<CommandLog> commands = std::make_shared<CommandLog>();
};

TEST(AdapterSwap, TelloToAirSimLandsTheOldAndStartsTheNewIdle) {
  SwapRig rig;
  ASSERT_EQ(rig.service->connect("tello", json::object()), "");
  const auto tello_session = rig.service->session_id();
  ASSERT_TRUE(tello_session);
  ASSERT_NE(rig.tello.load(), nullptr);
  ASSERT_TRUE(rig.run_until([&] { return rig.tello.load()->state() == FlightState::kReady; }, 2));
  for (int i = 0; i < 5; ++i) rig.step();  // the camera's first frames: vision ready

  // The Tello takes off and moves forward (rc streamed).
  const auto takeoff = rig.submit(CommandType::kTakeoff);
  ASSERT_TRUE(takeoff.accepted) << takeoff.reason;
  ASSERT_TRUE(rig.run_until(
      [&] {
        const auto s = SwapRig::status_of(rig.tello_host);
        return s.mode == sim::TwinMode::kFlying && s.z_m > 0.5;
      },
      10))
      << "the Tello twin never took off";
  contracts::MotionPayload forward;
  forward.vx_m_s = 0.5;
  ASSERT_TRUE(rig.submit(CommandType::kMove, forward).accepted);
  ASSERT_TRUE(rig.run_until([&] { return SwapRig::status_of(rig.tello_host).body_vx_m_s > 0.2; }, 5))
      << "the Tello twin never moved forward";
  ASSERT_EQ(rig.tello.load()->state(), FlightState::kFlying);

  // Swap while it flies and moves.
  rig.tello = nullptr;  // destroyed inside connect()
  ASSERT_EQ(rig.service->connect("airsim", json::object()), "");
  // Everything the old adapter sent is queued at its emulator by now (loopback); a marker
  // sent after it tells when the emulator has handled all of it.
  rig.send_marker_to_tello_emulator();
  ASSERT_TRUE(await([&] { return rig.tello_emulator.stats().unknown_commands == 1; }));
  const auto datagrams_at_swap = rig.tello_emulator.stats().datagrams;
  EXPECT_EQ(rig.service->adapter_name(), "airsim");
  ASSERT_NE(rig.airsim.load(), nullptr);
  EXPECT_EQ(rig.airsim.load()->state(), FlightState::kReady) << "the new drone starts READY";

  // The old session ended with the landing the swap ordered; a new session is open.
  const auto airsim_session = rig.service->session_id();
  ASSERT_TRUE(airsim_session);
  EXPECT_NE(*airsim_session, *tello_session);
  EXPECT_TRUE(rig.storage.get_session(*tello_session)->ended_at.has_value());
  EXPECT_FALSE(rig.storage.get_session(*airsim_session)->ended_at.has_value());
  bool landed_for_swap = false;
  for (const auto& c : rig.storage.commands(*tello_session)) {
    if (c.command.type == CommandType::kLand && c.command.source_id == "ADAPTER_SWAP") {
      landed_for_swap = c.result == "OK";
    }
  }
  EXPECT_TRUE(landed_for_swap) << "the swap did not land the flying Tello first";
  EXPECT_TRUE(rig.storage.commands(*airsim_session).empty())
      << "a command of the old drone was carried over to the new one";

  // Three simulated seconds later: the old twin came down on the LAND it got, and heard
  // nothing more from the old adapter (no keep-alive, no rc: it is disconnected); the new
  // twin never left the ground nor moved (nothing in flight carried over).
  double new_max_speed = 0, new_max_z = 0;
  for (int i = 0; i < 60; ++i) {
    rig.step();
    const auto s = SwapRig::status_of(rig.airsim_host);
    new_max_speed = std::max(new_max_speed, s.speed_m_s);
    new_max_z = std::max(new_max_z, s.z_m);
  }
  EXPECT_EQ(rig.tello_emulator.stats().datagrams, datagrams_at_swap)
      << "the old adapter still talks to its drone after the swap";
  EXPECT_TRUE(rig.run_until(
      [&] { return SwapRig::status_of(rig.tello_host).mode == sim::TwinMode::kLanded; }, 10))
      << "the old drone did not land";
  EXPECT_EQ(SwapRig::status_of(rig.airsim_host).mode, sim::TwinMode::kLanded);
  EXPECT_LT(new_max_z, 0.02);
  EXPECT_LT(new_max_speed, 0.05);
  EXPECT_EQ(rig.airsim.load()->state(), FlightState::kReady);
  EXPECT_TRUE(rig.storage.commands(*airsim_session).empty());

  // The new drone flies on its own commands.
  const auto new_takeoff = rig.submit(CommandType::kTakeoff);
  ASSERT_TRUE(new_takeoff.accepted) << new_takeoff.reason;
  EXPECT_TRUE(rig.run_until(
      [&] {
        const auto s = SwapRig::status_of(rig.airsim_host);
        return s.mode == sim::TwinMode::kFlying && s.z_m > 0.5;
      },
      10))
      << "the AirSim twin never took off after the swap";
  ASSERT_TRUE(rig.submit(CommandType::kLand).accepted);
  EXPECT_TRUE(rig.run_until(
      [&] { return SwapRig::status_of(rig.airsim_host).mode == sim::TwinMode::kLanded; }, 15));
  rig.airsim = nullptr;
  rig.service->disconnect();
}

}  // namespace
}  // namespace gbdcs::adapters::testing
