// AirSim beyond the contract: errors with their fix, reconnect with back-off, the emulator's
// answers to bad requests, and fuzzed/truncated RPC frames on both sides (no crash, no hang).
#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <random>
#include <thread>

#include "contract_rigs.hpp"
#include "gbdcs/adapters/airsim_rpc.hpp"

namespace gbdcs::adapters::testing {
namespace {

namespace asio = boost::asio;
using asio::ip::tcp;
using contracts::FlightState;
using control::Result;

std::string request(std::uint32_t id, const std::string& method,
                    const std::function<void(msgpack::packer<msgpack::sbuffer>&)>& params) {
  return airsim::encode_request(id, method, params);
}

// A blocking msgpack-RPC client for poking the emulator directly.
struct RawClient {
  explicit RawClient(std::uint16_t port) : socket(io) {
    socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  }
  void send(const std::string& bytes) { asio::write(socket, asio::buffer(bytes)); }
  // The next response, or nullopt when the server closed the connection.
  std::optional<airsim::Response> next() {
    for (;;) {
      msgpack::object_handle oh;
      if (unpacker.next(oh)) {
        std::string why;
        auto r = airsim::decode_response(std::move(oh), why);
        EXPECT_TRUE(r) << why;
        return r;
      }
      std::array<char, 4096> buf{};
      boost::system::error_code ec;
      const auto n = socket.read_some(asio::buffer(buf), ec);
      if (ec) return std::nullopt;
      unpacker.reserve_buffer(n);
      std::copy_n(buf.data(), n, unpacker.buffer());
      unpacker.buffer_consumed(n);
    }
  }
  asio::io_context io;
  tcp::socket socket;
  msgpack::unpacker unpacker;
};

TEST(AirSimAdapter, UnreachableServerNamesTheAddressAndTheFix) {
  std::uint16_t port = 0;
  {
    asio::io_context io;
    tcp::acceptor a(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    port = a.local_endpoint().port();
  }  // closed: connection refused
  contracts::ManualClock clock;
  AirSimAdapter drone(clock, AirSimOptions::from_json({{"port", port}}));
  EXPECT_NE(drone.connect(), Result::kOk);
  const auto e = drone.last_error();
  EXPECT_NE(e.find("cannot reach AirSim at 127.0.0.1:" + std::to_string(port)), std::string::npos)
      << e;
  EXPECT_NE(e.find("gbdcs twin --airsim"), std::string::npos) << e;
  EXPECT_EQ(drone.takeoff(), Result::kNotConnected);
}

TEST(AirSimAdapter, UnknownVehicleIsAnErrorNamingIt) {
  AirSimRig rig(nlohmann::json{{"vehicle", "Nope"}});
  EXPECT_EQ(rig.adapter().connect(), Result::kError);
  EXPECT_NE(rig.adapter().last_error().find("'Nope'"), std::string::npos)
      << rig.adapter().last_error();
}

TEST(AirSimAdapter, ReconnectsAfterTheServerDropsTheConnection) {
  AirSimRig rig;
  ASSERT_EQ(rig.adapter().connect(), Result::kOk) << rig.adapter().last_error();
  ASSERT_EQ(rig.adapter().takeoff(), Result::kOk);
  ASSERT_TRUE(rig.run_until([&] { return rig.last_frame().altitude_m > 0.8; }, 10));
  rig.emulator().drop_connections();
  ASSERT_TRUE(await([&] { return rig.adapter().hover() == Result::kNotConnected; }));
  ASSERT_TRUE(rig.run_until([&] { return rig.airsim().stats().connects >= 2; }, 10))
      << rig.adapter().last_error();
  rig.clear_frames();
  ASSERT_TRUE(rig.run_until(
      [&] { return rig.frame_count() > 3 && rig.last_frame().link == contracts::LinkState::kOk; },
      5));
  EXPECT_EQ(rig.adapter().hover(), Result::kOk) << rig.adapter().last_error();
  EXPECT_EQ(rig.adapter().state(), FlightState::kFlying);
  EXPECT_GT(rig.last_frame().altitude_m, 0.6);
}

TEST(AirSimEmulator, BadRequestsGetClearErrors) {
  AirSimRig rig;
  RawClient c(rig.emulator().port());
  c.send(request(1, "ping", [](auto& p) { p.pack_array(0); }));
  auto r = c.next();
  ASSERT_TRUE(r && r->ok);
  EXPECT_TRUE(r->result.get().as<bool>());

  c.send(request(2, "flyToMars", [](auto& p) { p.pack_array(0); }));
  r = c.next();
  ASSERT_TRUE(r);
  EXPECT_FALSE(r->ok);
  EXPECT_NE(r->error.find("could not find function 'flyToMars'"), std::string::npos) << r->error;

  c.send(request(3, "takeoff", [](auto& p) {
    p.pack_array(2);
    p.pack(20);
    p.pack(std::string(""));
  }));
  r = c.next();
  ASSERT_TRUE(r);
  EXPECT_NE(r->error.find("EnableApiControl"), std::string::npos) << r->error;

  c.send(request(4, "armDisarm", [](auto& p) { p.pack_array(1); p.pack(true); }));
  r = c.next();
  ASSERT_TRUE(r);
  EXPECT_NE(r->error.find("taking 2 arg(s)) called with 1"), std::string::npos) << r->error;

  msgpack::sbuffer b;  // [0, 5, 42, []]: method is not a string
  msgpack::packer<msgpack::sbuffer> p(b);
  p.pack_array(4);
  p.pack(0);
  p.pack(5);
  p.pack(42);
  p.pack_array(0);
  c.send(std::string(b.data(), b.size()));
  r = c.next();
  ASSERT_TRUE(r);
  EXPECT_EQ(r->msgid, 5u);
  EXPECT_NE(r->error.find("method must be a string"), std::string::npos) << r->error;

  c.send(std::string("\xc1", 1));  // never-used msgpack byte: the connection is closed
  EXPECT_FALSE(c.next());
  EXPECT_GE(rig.emulator().stats().malformed, 2u);
}

TEST(AirSimEmulator, FuzzedFramesNeverCrashItAndOthersKeepFlying) {
  AirSimRig rig;
  ASSERT_EQ(rig.adapter().connect(), Result::kOk);
  // A second emulator on the same twin takes the abuse (the rig's counts stay its own).
  sim::AirSimEmulatorOptions o;
  o.port = 0;
  sim::AirSimEmulator target(rig.host(), o);
  std::mt19937 rng(99);  // seeded
  const std::string good = request(9, "getMultirotorState", [](auto& p) {
    p.pack_array(1);
    p.pack(std::string(""));
  });
  for (int i = 0; i < 60; ++i) {
    RawClient c(target.port());
    std::string bytes;
    switch (i % 3) {
      case 0:
        bytes = good.substr(0, rng() % good.size());  // truncated, then the peer goes away
        break;
      case 1:
        bytes = good;
        for (int k = 0; k < 4; ++k) bytes[rng() % bytes.size()] = static_cast<char>(rng());
        break;
      default:
        bytes.resize(1 + rng() % 200);
        for (auto& ch : bytes) ch = static_cast<char>(rng());
    }
    c.send(bytes);
    c.socket.shutdown(tcp::socket::shutdown_send);
    while (c.next()) {  // whatever it answers, until it closes
    }
  }
  EXPECT_GT(target.stats().malformed, 0u);
  RawClient after(target.port());  // still serving
  after.send(request(1, "ping", [](auto& p) { p.pack_array(0); }));
  const auto pong = after.next();
  ASSERT_TRUE(pong && pong->ok);
  // The adapter flying the same twin was never disturbed.
  rig.run(1.0);
  EXPECT_EQ(rig.adapter().takeoff(), Result::kOk) << rig.adapter().last_error();
  EXPECT_TRUE(rig.run_until([&] { return rig.last_frame().altitude_m > 0.5; }, 10));
}

TEST(AirSimAdapter, GarbageFromTheServerIsCountedNotACrash) {
  asio::io_context io;
  tcp::acceptor acceptor(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  std::thread server([&] {
    std::mt19937 rng(7);
    for (int round = 0; round < 1; ++round) {
      tcp::socket s(io);
      boost::system::error_code ec;
      acceptor.accept(s, ec);
      if (ec) return;
      std::array<char, 256> junk{};
      for (auto& ch : junk) ch = static_cast<char>(rng());
      junk[0] = '\x94';  // an array of 4 ...
      junk[1] = '\x01';  // ... type 1, then noise
      asio::write(s, asio::buffer(junk), ec);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  contracts::ManualClock clock;
  AirSimAdapter drone(clock, AirSimOptions::from_json(
                                 {{"port", acceptor.local_endpoint().port()},
                                  {"rpc_timeout_ms", 300}}));
  EXPECT_NE(drone.connect(), Result::kOk);
  EXPECT_FALSE(drone.last_error().empty());
  server.join();
  std::string why;
  // The decoders on hostile objects.
  msgpack::object_handle nil_handle;
  EXPECT_FALSE(airsim::decode_response(std::move(nil_handle), why));
  msgpack::zone z;
  EXPECT_FALSE(airsim::decode_multirotor_state(msgpack::object(42, z), why));
  EXPECT_FALSE(why.empty());
}

}  // namespace
}  // namespace gbdcs::adapters::testing
