// AirSimAdapter: a multirotor in Microsoft AirSim (or anything speaking its RPC) through
// msgpack-RPC over TCP (default 127.0.0.1:41451). Registered as "airsim".
//
// connect()      TCP connect (connect_timeout_ms), ping, enableApiControl(true, vehicle),
//                armDisarm(true, vehicle); READY (FLYING if landed_state says it flies).
// takeoff()      takeoff(takeoff_timeout_s, vehicle): AirSim answers when the climb is done,
//                so the call waits ack_wait_ms for an immediate error (kRejected) and returns
//                kOk otherwise; a late error or `false` is kept in last_error().
// land()         land(land_timeout_s, vehicle), as take-off.
// hover()        cancelLastTask(vehicle) then hover(vehicle) (answered at once).
// move(m)        moveByVelocityBodyFrame(vx, vy, -vz, move_chunk_s, MaxDegreeOfFreedom,
//                YawMode{is_rate: true, yaw_or_rate: yaw_rate_deg_s}, vehicle), re-sent every
//                move_resend_s while the motion holds (a dead man's switch: a lost client
//                stops the drone within move_chunk_s); after duration_s: hover.
// emergency_stop()  cancelLastTask + armDisarm(false, vehicle): motors off.
// Telemetry      getMultirotorState(vehicle) at telemetry_hz: position/velocity NED ->
//                session frame (x forward at connect, y right, up positive), heading from the
//                quaternion's yaw; AirSim reports no battery: battery_pct is 100.
// States         READY -takeoff-> FLYING -land-> LANDING -> READY when landed_state is 0;
//                FLYING -> READY when it reports landed for 1 s after having flown.
// Link           no state answer for link_timeout_s: link LOST (one frame), commands
//                kNotConnected; a broken connection is re-dialled with back-off
//                (reconnect_min_s doubling to reconnect_max_s), then API control and arming
//                are asked again.
// Time / threads as TelloAdapter: the injected Clock drives the timers (an I/O thread ticks
//                every 10 ms, and poll()); a blocked RPC call waits real time, calls nobody
//                waits for expire on the Clock; nothing throws across the
//                interface; malformed frames from the server are dropped and counted.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/control/drone_adapter.hpp"

namespace gbdcs::adapters {

struct AirSimOptions {
  std::string address = "127.0.0.1";
  int port = 41451;
  std::string vehicle;  // "" = AirSim's default vehicle
  int connect_timeout_ms = 2000;
  int rpc_timeout_ms = 2000;
  int ack_wait_ms = 300;
  double telemetry_hz = 10;
  double link_timeout_s = 1.5;
  double reconnect_min_s = 0.5;
  double reconnect_max_s = 5;
  double takeoff_timeout_s = 20;
  double land_timeout_s = 60;
  double move_chunk_s = 0.5;
  double move_resend_s = 0.2;
  double max_horizontal_m_s = 5;
  double max_vertical_m_s = 3;
  double max_yaw_rate_deg_s = 180;

  static AirSimOptions from_json(const nlohmann::json& doc);  // strict; invalid_argument
};

struct AirSimStats {
  std::uint64_t requests = 0;
  std::uint64_t responses = 0;
  std::uint64_t states = 0;
  std::uint64_t malformed = 0;  // frames that are not a response, or a bad MultirotorState
  std::string last_malformed;
  std::uint64_t connects = 0;   // successful TCP connections (first + reconnects)
  std::uint64_t link_losses = 0;
  std::uint64_t outstanding = 0;  // requests waiting for their response
  std::uint64_t lost_requests = 0;  // unanswered when a connection broke
};

class AirSimAdapter final : public control::DroneAdapter {
 public:
  AirSimAdapter(const contracts::Clock& clock, AirSimOptions options = {});
  ~AirSimAdapter() override;
  AirSimAdapter(const AirSimAdapter&) = delete;
  AirSimAdapter& operator=(const AirSimAdapter&) = delete;

  std::string_view name() const override { return "airsim"; }
  control::Result connect() override;
  control::Result disconnect() override;
  control::Result takeoff() override;
  control::Result land() override;
  control::Result hover() override;
  control::Result move(const contracts::MotionPayload& motion) override;
  control::Result emergency_stop() override;
  contracts::FlightState state() const override;
  void set_telemetry_sink(control::TelemetrySink sink) override;
  void poll() override;
  std::string last_error() const override;

  AirSimStats stats() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace gbdcs::adapters
