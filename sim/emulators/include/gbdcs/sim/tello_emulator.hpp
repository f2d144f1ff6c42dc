// TelloEmulator: the twin answering the Tello SDK (1.3 / 2.0) over UDP, so the real
// TelloAdapter, and any third-party Tello client, can fly it. One instance per client.
//
// Socket : binds bind_address:command_port (127.0.0.1:8889; 0 = any free port, see port()).
//          Replies go to the sender; the state stream goes to the sender's address at
//          state_port (8890; set_state_port() for tests with an ephemeral client port).
// Commands (covered, docs/ADAPTERS.md has the table):
//   command          "ok"; enters SDK mode (before it, everything else is ignored, as a Tello)
//   takeoff          "ok" when the climb is done (~2 s of simulated time), "error <why>" at
//                    once when the twin refuses (already flying, battery low, crashed)
//   land             "ok" on touch-down, "error not flying" at once when on the ground
//   emergency        "ok" at once: motors off
//   stop             "ok": sticks centred, brake and hold (SDK 2.0; "unknown command" in 1.3)
//   rc a b c d       no reply; each -100...100 (a right, b forward, c up, d yaw clockwise)
//   speed x          "ok" for 10...100 cm/s (kept for speed?; the twin's rc maxima stay)
//   battery? speed? time? height? temp? attitude? baro? tof? wifi? sdk? sn?   their values
//   streamon/streamoff  "ok"; with a stream handler (sim/tello_video's TelloVideoStreamer,
//                    `gbdcs twin --tello`) the twin's camera then streams as H.264 to the
//                    client's UDP 11111, as a Tello's
//   anything else    "unknown command: <text>"; moves by distance (up/forward/cw x ...) are
//                    "error Not supported by the twin's Tello emulator"
//   A reply-expecting command that arrives while take-off/land is still pending first
//   releases that reply ("ok"), so replies always come in command order.
// State  : state_hz (10) datagrams of `key:value;` pairs after `command`: SDK 2.0 set
//          (mid:-1;x:0;y:0;z:0;mpry:0,0,0; first) or 1.3 (sdk "1.3"); h/tof cm, vgx/vgy/vgz
//          dm/s in the frame x forward / y right at start, vgz positive down, yaw clockwise.
// Timers : every command (also queries) resets the twin's 15 s auto-land timer.
// Faults : set_link_lost(true), or a link_loss in the twin's fault schedule, drops every
//          datagram both ways, as an out-of-range Wi-Fi would.
// Words  : `words` renames the commands (the XFly profile runs the same emulator).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "gbdcs/sim/twin_host.hpp"

namespace gbdcs::sim {

struct TelloEmulatorWords {
  std::string handshake = "command";
  std::string takeoff = "takeoff";
  std::string land = "land";
  std::string emergency = "emergency";
  std::string stop = "stop";
  std::string rc = "rc";
  std::string battery = "battery?";
};

struct TelloEmulatorOptions {
  std::string bind_address = "127.0.0.1";
  int command_port = 8889;  // 0: any free port
  int state_port = 8890;    // the client's port for the state stream
  double state_hz = 10;
  std::string sdk = "2.0";  // or "1.3"
  std::string label = "tello";  // in logs
  TelloEmulatorWords words;

  // Keys: bind_address, command_port, state_port, state_hz, sdk, commands {...}.
  static TelloEmulatorOptions from_json(const nlohmann::json& doc);
};

struct TelloEmulatorStats {
  std::uint64_t datagrams = 0;        // received while the link was up
  std::uint64_t dropped = 0;          // received during a link loss
  std::uint64_t replies = 0;
  std::uint64_t state_packets = 0;
  std::uint64_t unknown_commands = 0;
  std::uint64_t rc_commands = 0;
};

class TelloEmulator {
 public:
  TelloEmulator(TwinHost& host, TelloEmulatorOptions options = {});
  ~TelloEmulator();
  TelloEmulator(const TelloEmulator&) = delete;
  TelloEmulator& operator=(const TelloEmulator&) = delete;

  std::uint16_t port() const;
  void set_state_port(int port);
  void set_link_lost(bool lost);
  bool link_lost() const;  // set_link_lost()'s flag (the fault schedule is the twin's)
  TelloEmulatorStats stats() const;

  // streamon / streamoff from the client (in SDK mode): handler(true, the client's IP
  // address) / handler(false, ...), called on the emulator's I/O thread with its lock held
  // (keep it short). Without a handler both are only answered "ok".
  using StreamHandler = std::function<void(bool on, const std::string& client_address)>;
  void set_stream_handler(StreamHandler handler);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace gbdcs::sim
