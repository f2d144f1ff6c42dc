// TelloAdapter: a DJI/Ryze Tello through its SDK (1.3 and 2.0): text commands over UDP, the
// state stream on UDP 8890. Registered as "tello"; with another command profile it also flies
// Tello-like text-over-UDP drones ("xfly", see adapters/xfly and docs/ADAPTERS.md).
//
// Protocol: commands go to address:command_port (192.168.10.1:8889) from one local socket;
//   the drone answers each with "ok", "error ..." or a value, to that socket.
//   connect()   "command" (enters SDK mode), retried handshake_retries times, reply_timeout_ms
//               each; the state stream then arrives on local UDP state_port.
//   takeoff()/land()  the Tello answers only when the manoeuvre is done (seconds later): the
//               call waits ack_wait_ms for an immediate "error" (kRejected), otherwise kOk; a
//               late "error" is logged and kept in last_error().
//   hover()     "rc 0 0 0 0" (sent a few times) then "stop" (SDK 2.0; skipped after the drone
//               answered "error" to it once, i.e. SDK 1.3, and while take-off/land is pending).
//   move(m)     "rc a b c d" (a right, b forward, c up, d yaw clockwise; each round(100 * value
//               / max) clamped to +-100), re-sent at rc_hz while any stick is off centre (a lost
//               datagram costs one period); duration_s > 0: centred after that many seconds.
//   emergency_stop()  "emergency" (motors off at once), sent even during a link loss; pending
//               replies are abandoned first so the answer cannot be mistaken.
//   keep-alive  "command" after keepalive_s without any command (the Tello lands by itself
//               after 15 s without one).
// Telemetry: one TelemetryFrame per state datagram (10 Hz): altitude h (cm -> m), body
//   velocity from vgx/vgy (velocity_unit_m_s per unit, the Tello's x forward / y right frame
//   at power-on, rotated by yaw), vz = -vgz, x/y integrated from the velocity in the session
//   frame (the drone's heading at connect), heading = yaw - yaw at connect, battery bat.
//   A malformed datagram is dropped and counted (stats()).
// States : INIT -connect-> READY -takeoff-> FLYING -land-> LANDING -> READY once h stays at
//   or below ground_height_cm for 0.5 s; FLYING -> READY when it landed by itself (auto-land,
//   battery) after having climbed. emergency: LANDING (falling) -> READY on the ground.
// Link   : no state datagram for link_timeout_s -> link LOST (one frame with link LOST, then
//   commands are kNotConnected); datagrams again -> OK, and "command" is sent again.
// Time   : the rc stream, keep-alive, timed moves and link watchdog read the injected Clock
//   (ticked by an I/O thread every 10 ms and by poll()), so lockstep tests run on a
//   ManualClock; a call blocked on its reply waits real time (a socket's), while replies
//   nobody waits for (keep-alive, take-off/land answered late) expire on the Clock.
// Errors : nothing throws across the interface; the constructor throws std::runtime_error
//   when a local port cannot be bound (with the fix) and std::invalid_argument for options.
// Threads: any thread may call; the sink is called from the I/O thread or poll().
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/control/drone_adapter.hpp"

namespace gbdcs::adapters {

// The command words of a text-over-UDP drone. The defaults are the Tello SDK's.
struct TelloCommandWords {
  std::string handshake = "command";
  std::string takeoff = "takeoff";
  std::string land = "land";
  std::string emergency = "emergency";
  std::string stop = "stop";  // empty: hover is rc 0 0 0 0 only
  std::string rc = "rc";      // followed by " a b c d"
  std::string keepalive = "command";
  std::string battery = "battery?";
};

struct TelloOptions {
  std::string name = "tello";  // the adapter's name() (the registry sets "xfly")
  std::string drone_label = "Tello";  // in messages: "no reply from the Tello at ..."
  std::string wifi_hint = "the drone's Wi-Fi (TELLO-XXXXXX)";
  std::string address = "192.168.10.1";
  int command_port = 8889;
  std::string bind_address = "0.0.0.0";
  int local_command_port = 0;  // 0: any free port (the drone answers to the sender)
  int state_port = 8890;       // local UDP port of the state stream; 0: any free port
  int reply_timeout_ms = 1000;
  int handshake_retries = 3;
  int ack_wait_ms = 300;
  double rc_hz = 20;
  double keepalive_s = 5;
  double link_timeout_s = 1.5;
  double velocity_unit_m_s = 0.1;  // vgx/vgy/vgz unit (dm/s)
  double max_horizontal_m_s = 1.0;  // rc +-100 means this speed (the drone's `speed`)
  double max_vertical_m_s = 0.8;
  double max_yaw_rate_deg_s = 100;
  double ground_height_cm = 10;
  TelloCommandWords words;

  // Keys: the fields above except name/drone_label/wifi_hint, plus "commands": {handshake,
  // takeoff, land, emergency, stop, rc, keepalive, battery}. Unknown keys throw
  // std::invalid_argument naming the key.
  static TelloOptions from_json(const nlohmann::json& doc);
  static TelloOptions from_json(const nlohmann::json& doc, TelloOptions defaults);
};

struct TelloStats {
  std::uint64_t commands_sent = 0;
  std::uint64_t replies = 0;
  std::uint64_t unexpected_replies = 0;  // a reply with no command waiting for one
  std::uint64_t state_packets = 0;       // valid state datagrams
  std::uint64_t malformed_packets = 0;   // dropped
  std::string last_malformed;            // why the last one was dropped
  std::uint64_t frames = 0;
  std::uint64_t link_losses = 0;
};

class TelloAdapter final : public control::DroneAdapter {
 public:
  TelloAdapter(const contracts::Clock& clock, TelloOptions options = {});
  ~TelloAdapter() override;
  TelloAdapter(const TelloAdapter&) = delete;
  TelloAdapter& operator=(const TelloAdapter&) = delete;

  std::string_view name() const override;
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

  // A read command ("battery?", "sdk?", "wifi?", ...): its reply text in `reply`.
  control::Result query(const std::string& command, std::string& reply);
  // The rc sticks for a motion, from the options' maxima.
  std::array<int, 4> sticks_for(const contracts::MotionPayload& motion) const;
  std::uint16_t local_state_port() const;
  std::uint16_t local_command_port() const;
  TelloStats stats() const;
  const TelloOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gbdcs::adapters
