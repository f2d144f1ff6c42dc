// AirSimEmulator: the twin answering AirSim's multirotor RPC (msgpack-RPC over TCP, rpclib's
// framing: [0, msgid, method, params] -> [1, msgid, error, result]), so the real
// AirSimAdapter, or AirSim's own Python/C++ client, can fly it.
//
// Socket : listens on bind_address:port (127.0.0.1:41451; 0 = any free port, see port());
//          any number of clients; each request answered on its connection.
// Methods (covered; anything else: "rpclib: server could not find function '<name>'"):
//   ping -> true; getServerVersion / getMinRequiredClientVersion -> 1
//   enableApiControl(bool, vehicle) -> nil; isApiControlEnabled(vehicle) -> bool
//   armDisarm(bool, vehicle) -> bool (disarm in flight = motors off, as an emergency stop)
//   takeoff(timeout_s, vehicle) -> true when the climb is done (~2 s simulated); error at
//       once when the twin refuses; false if it times out or another task replaces it
//   land(timeout_s, vehicle) -> true on touch-down (as take-off)
//   hover(vehicle) -> true at once; cancelLastTask(vehicle) -> nil (hover)
//   moveByVelocityBodyFrame(vx, vy, vz, duration, drivetrain, yaw_mode, vehicle) -> true
//       after `duration` (then it brakes and holds), false when a newer task replaces it;
//       vx forward, vy right, vz DOWN (m/s) -> the twin's rc sticks (its maxima: 1 m/s
//       horizontal, 0.8 vertical, 100 deg/s yaw); yaw_mode must be {is_rate: true, ...}
//   getMultirotorState(vehicle) -> MultirotorState map: kinematics_estimated (position,
//       orientation, linear/angular velocity, accelerations: NED, z = -altitude), landed_state
//       (0 landed or crashed, 1 otherwise), collision, gps_location (a fixed home + offset),
//       timestamp (ns of simulated time), rc_data, ready, ready_message, can_arm
//   Control methods need enableApiControl(true) first, takeoff needs armDisarm(true), as
//   AirSim's. Vehicle names: "" or `vehicle` (Drone1); another name is an error naming it.
// Robustness: a frame that is not a request gets an error response when it has a msgid,
//   otherwise the connection is closed; undecodable msgpack or a frame over 1 MiB closes that
//   connection (counted in stats().malformed); the emulator keeps serving the others.
// Faults : set_link_lost(true), or a link_loss in the twin's schedule, drops requests
//   unanswered (the TCP connection stays, as over a stalled network); drop_connections()
//   closes every client connection (a restarted simulator).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "gbdcs/sim/twin_host.hpp"

namespace gbdcs::sim {

struct AirSimEmulatorOptions {
  std::string bind_address = "127.0.0.1";
  int port = 41451;  // 0: any free port
  std::string vehicle = "Drone1";
};

struct AirSimEmulatorStats {
  std::uint64_t connections = 0;
  std::uint64_t requests = 0;  // every request frame received, answered or dropped
  std::uint64_t dropped = 0;   // during a link loss
  std::uint64_t responses = 0;  // sent, or on their way, to a connected client
  std::uint64_t malformed = 0;
  std::string last_malformed;
};

class AirSimEmulator {
 public:
  AirSimEmulator(TwinHost& host, AirSimEmulatorOptions options = {});
  ~AirSimEmulator();
  AirSimEmulator(const AirSimEmulator&) = delete;
  AirSimEmulator& operator=(const AirSimEmulator&) = delete;

  std::uint16_t port() const;
  void set_link_lost(bool lost);
  void drop_connections();
  AirSimEmulatorStats stats() const;

  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace gbdcs::sim
