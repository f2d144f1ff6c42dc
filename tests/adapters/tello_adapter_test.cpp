// TelloAdapter beyond the shared contract: errors with their fix, the state stream's
// robustness, keep-alive against the 15 s auto-land, queries, options.
#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <nlohmann/json.hpp>

#include "contract_rigs.hpp"
#include "gbdcs/adapters/tello_adapter.hpp"
#include "gbdcs/sim/tello_emulator.hpp"
#include "gbdcs/sim/twin_host.hpp"

namespace gbdcs::adapters::testing {
namespace {

namespace asio = boost::asio;
using asio::ip::udp;
using contracts::FlightState;
using control::Result;

// The twin's Tello emulator and a TelloAdapter pointed at it, lockstep on a ManualClock.
struct TelloBench {
  explicit TelloBench(sim::TwinHostOptions host_options = {}, nlohmann::json extra = {})
      : host(clock, shared_model(), host_options), emulator(host, emulator_options()) {
    nlohmann::json o = {{"address", "127.0.0.1"},   {"bind_address", "127.0.0.1"},
                        {"command_port", emulator.port()}, {"state_port", 0},
                        {"reply_timeout_ms", 3000}, {"ack_wait_ms", 100}};
    if (extra.is_object()) o.update(extra);
    drone = std::make_unique<TelloAdapter>(clock, TelloOptions::from_json(o));
    emulator.set_state_port(drone->local_state_port());
    drone->set_telemetry_sink([this](const contracts::TelemetryFrame& f) {
      std::lock_guard lock(mutex);
      last = f;
    });
  }
  static sim::TelloEmulatorOptions emulator_options() {
    sim::TelloEmulatorOptions e;
    e.command_port = 0;
    return e;
  }
  void run(double seconds) {
    for (int i = 0; i < static_cast<int>(seconds / 0.05 + 0.5); ++i) {
      clock.advance(contracts::from_seconds(0.05));
      host.poll();
      drone->poll();
      ASSERT_TRUE(await([&] {
        const auto a = drone->stats();
        const auto e = emulator.stats();
        return e.datagrams + e.dropped >= a.commands_sent &&
               a.state_packets + a.malformed_packets >= e.state_packets + foreign_datagrams;
      }));
    }
  }
  contracts::TelemetryFrame frame() {
    std::lock_guard lock(mutex);
    return last;
  }

  contracts::ManualClock clock;
  sim::TwinHost host;
  sim::TelloEmulator emulator;
  std::unique_ptr<TelloAdapter> drone;
  // Datagrams a test sent to the state port itself: without them in the barrier above, they
  // would stand in for the emulator's state datagrams still on their way.
  std::uint64_t foreign_datagrams = 0;
  std::mutex mutex;
  contracts::TelemetryFrame last;
};

TEST(TelloAdapter, UnreachableDroneIsATimeoutNamingTheWifiAndAddress) {
  asio::io_context io;
  udp::socket silent(io, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));  // never answers
  contracts::ManualClock clock;
  TelloAdapter drone(clock, TelloOptions::from_json({{"address", "127.0.0.1"},
                                                     {"command_port", silent.local_endpoint().port()},
                                                     {"state_port", 0},
                                                     {"reply_timeout_ms", 50},
                                                     {"handshake_retries", 2}}));
  EXPECT_EQ(drone.connect(), Result::kTimeout);
  const auto e = drone.last_error();
  EXPECT_NE(e.find("no reply"), std::string::npos) << e;
  EXPECT_NE(e.find("Wi-Fi"), std::string::npos) << e;
  EXPECT_NE(e.find("127.0.0.1:" + std::to_string(silent.local_endpoint().port())),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("2 tries"), std::string::npos) << e;
  EXPECT_EQ(drone.state(), FlightState::kInit);
  EXPECT_EQ(drone.takeoff(), Result::kNotConnected);
}

TEST(TelloAdapter, ErrorReplyIsARejectionWithTheDronesWords) {
  sim::TwinHostOptions h;
  h.twin.faults = sim::FaultSchedule::from_json(
      nlohmann::json::array({{{"type", "battery_jump"}, {"start_s", 0}, {"battery_pct", 0}}}));
  TelloBench bench(h);
  ASSERT_EQ(bench.drone->connect(), Result::kOk) << bench.drone->last_error();
  bench.run(0.3);
  EXPECT_EQ(bench.drone->takeoff(), Result::kRejected);
  EXPECT_NE(bench.drone->last_error().find("answered 'error"), std::string::npos)
      << bench.drone->last_error();
  EXPECT_EQ(bench.drone->state(), FlightState::kReady);
  EXPECT_EQ(bench.frame().battery_pct, 0);
}

TEST(TelloAdapter, MalformedStateDatagramsAreDroppedAndCounted) {
  TelloBench bench;
  ASSERT_EQ(bench.drone->connect(), Result::kOk);
  bench.run(0.5);
  const auto before = bench.drone->stats();
  asio::io_context io;
  udp::socket noise(io, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  const udp::endpoint to(asio::ip::make_address("127.0.0.1"), bench.drone->local_state_port());
  const std::vector<std::string> noise_datagrams = {"garbage", "h:1;bat:500;yaw:0;", "x",
                                                    "h:;bat:;yaw:;", std::string(3000, '\xff')};
  for (const auto& d : noise_datagrams) {
    noise.send_to(asio::buffer(d), to);
  }
  ASSERT_TRUE(await([&] { return bench.drone->stats().malformed_packets >= before.malformed_packets + 5; }));
  bench.foreign_datagrams = noise_datagrams.size();
  EXPECT_FALSE(bench.drone->stats().last_malformed.empty());
  bench.run(0.5);  // still flying the stream
  EXPECT_GT(bench.drone->stats().state_packets, before.state_packets);
  EXPECT_EQ(bench.drone->takeoff(), Result::kOk) << bench.drone->last_error();
}

TEST(TelloAdapter, KeepAliveHoldsAHoverPastTheFifteenSecondAutoLand) {
  TelloBench bench;
  ASSERT_EQ(bench.drone->connect(), Result::kOk);
  ASSERT_EQ(bench.drone->takeoff(), Result::kOk);
  bench.run(4.0);
  ASSERT_EQ(bench.drone->hover(), Result::kOk) << bench.drone->last_error();
  bench.run(25.0);
  EXPECT_EQ(bench.drone->state(), FlightState::kFlying);
  EXPECT_GT(bench.frame().altitude_m, 0.6);
}

TEST(TelloAdapter, EmulatorLandsBySelfAfterFifteenSilentSecondsAndTheAdapterSeesIt) {
  // keepalive_s is the adapter's; a silent raw client shows the emulator's own auto-land.
  contracts::ManualClock clock;
  sim::TwinHost host(clock, shared_model());
  sim::TelloEmulatorOptions e;
  e.command_port = 0;
  sim::TelloEmulator emulator(host, e);
  asio::io_context io;
  udp::socket client(io, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  emulator.set_state_port(client.local_endpoint().port());
  const udp::endpoint to(asio::ip::make_address("127.0.0.1"), emulator.port());
  std::array<char, 512> buf{};
  udp::endpoint from;
  std::uint64_t sent = 0;
  auto send = [&](const std::string& cmd) {  // returns once the emulator has handled it
    client.send_to(asio::buffer(cmd), to);
    ++sent;
    ASSERT_TRUE(await([&] { return emulator.stats().datagrams >= sent; }));
  };
  auto reply = [&]() {
    std::string out = "<none>";
    await([&] {
      while (client.available() > 0) {
        const auto n = client.receive_from(asio::buffer(buf), from);
        std::string r(buf.data(), n);
        if (r.find(';') == std::string::npos) {  // not a state datagram
          out = r;
          return true;
        }
      }
      return false;
    }, std::chrono::seconds(5));
    return out;
  };
  auto run = [&](double seconds) {
    for (int i = 0; i < static_cast<int>(seconds / 0.05 + 0.5); ++i) {
      clock.advance(contracts::from_seconds(0.05));
      host.poll();
    }
  };
  send("command");
  EXPECT_EQ(reply(), "ok");
  send("battery?");
  EXPECT_EQ(reply(), "100");
  send("flip l");
  EXPECT_EQ(reply().rfind("error", 0), 0u);
  send("dance");
  EXPECT_EQ(reply(), "unknown command: dance");
  send("land");
  EXPECT_EQ(reply().rfind("error", 0), 0u);  // on the ground
  send("takeoff");
  run(4.0);
  EXPECT_EQ(reply(), "ok");  // when the climb was done
  EXPECT_EQ(host.with_sim([](sim::TwinSim& s) { return s.mode(); }), sim::TwinMode::kFlying);
  send("rc 0 0 200 0");
  EXPECT_EQ(reply(), "error");
  run(9.0);  // 13 s after the last command: still up
  EXPECT_EQ(host.with_sim([](sim::TwinSim& s) { return s.mode(); }), sim::TwinMode::kFlying);
  run(6.0);
  EXPECT_NE(host.with_sim([](sim::TwinSim& s) { return s.mode(); }), sim::TwinMode::kFlying);
  EXPECT_GT(emulator.stats().state_packets, 150u);  // 10 Hz
}

TEST(TelloAdapter, QueriesReturnTheValue) {
  TelloBench bench;
  ASSERT_EQ(bench.drone->connect(), Result::kOk);
  std::string value;
  ASSERT_EQ(bench.drone->query("battery?", value), Result::kOk) << bench.drone->last_error();
  EXPECT_EQ(value, "100");
  ASSERT_EQ(bench.drone->query("sdk?", value), Result::kOk);
  EXPECT_EQ(value, "20");
  EXPECT_EQ(bench.drone->query("nonsense?", value), Result::kRejected);
  EXPECT_NE(bench.drone->last_error().find("unknown command"), std::string::npos);
}

TEST(TelloAdapter, OptionsAreStrictAndNameTheKey) {
  contracts::ManualClock clock;
  auto error_of = [&](const nlohmann::json& o) -> std::string {
    try {
      TelloAdapter drone(clock, TelloOptions::from_json(o));
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error_of({{"adress", "1.2.3.4"}}).find("'adress' is not a known option"),
            std::string::npos);
  EXPECT_NE(error_of({{"address", "tello.local"}, {"state_port", 0}}).find("not an IP address"),
            std::string::npos);
  EXPECT_NE(error_of({{"rc_hz", 0}}).find("rc_hz"), std::string::npos);
  EXPECT_NE(error_of({{"commands", {{"fly", "x"}}}}).find("'fly' is not a command word"),
            std::string::npos);
  // A state port in use: the error says which option to change.
  asio::io_context io;
  udp::socket taken(io, udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  const auto e = error_of({{"bind_address", "127.0.0.1"},
                           {"state_port", taken.local_endpoint().port()}});
  EXPECT_NE(e.find("'state_port'"), std::string::npos) << e;
}

}  // namespace
}  // namespace gbdcs::adapters::testing

#include "gbdcs/adapters/registry.hpp"

namespace gbdcs::adapters::testing {
namespace {

TEST(Registry, XflyIsTheTelloEngineWithItsAssumedProfile) {
  contracts::ManualClock clock;
  auto xfly = make_adapter("xfly", clock,
                           {{"state_port", 0}, {"reply_timeout_ms", 20}, {"handshake_retries", 1}});
  EXPECT_EQ(xfly->name(), "xfly");
  EXPECT_NE(xfly->connect(), control::Result::kOk);  // nobody at 192.168.4.1 here
  EXPECT_NE(xfly->last_error().find("192.168.4.1"), std::string::npos) << xfly->last_error();
  try {
    make_adapter("xfly", clock, {{"colour", "red"}});
    ADD_FAILURE() << "accepted an unknown option";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("xfly options: 'colour'"), std::string::npos) << e.what();
  }
  const auto names = adapter_names();
  for (const char* n : {"dummy", "airsim", "tello", "xfly"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  }
}

}  // namespace
}  // namespace gbdcs::adapters::testing
