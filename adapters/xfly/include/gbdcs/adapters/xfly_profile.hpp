// The XFly profile: what we assume about the Qubebots X-Fly (ESP32-based). Its only public
// trace names a Python SDK but no wire protocol, so the drone is flown as a Tello-like
// text-over-UDP drone whose addresses and command words are configuration:
//
//   address 192.168.4.1 (an ESP32 soft access point's default), command port 8889, state
//   stream to local UDP 8890 as `key:value;` pairs (h cm, bat %, yaw deg required), replies
//   "ok" / "error ..." / values; command words default to the Tello SDK's (command, takeoff,
//   land, emergency, stop, rc a b c d, battery?), each replaceable under "commands".
//
// The registry builds the "xfly" adapter as the Tello engine (adapters/tello) with these
// defaults; the options JSON is read on top of them, with the same keys as the Tello's.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace gbdcs::adapters {

struct XflyProfile {
  std::string name = "xfly";
  std::string label = "XFly";
  std::string wifi_hint = "the XFly's own Wi-Fi access point (its ESP32, e.g. XFLY-XXXX)";
  // The defaults, as Tello-engine options JSON (address, ports, command words).
  nlohmann::json defaults = {{"address", "192.168.4.1"}, {"command_port", 8889},
                             {"state_port", 8890}};
};

// The profile with `options` (the user's JSON) merged over its defaults; the result is what
// the Tello engine reads. Throws std::invalid_argument when options is not an object or null.
nlohmann::json xfly_engine_options(const nlohmann::json& options, const XflyProfile& profile = {});

}  // namespace gbdcs::adapters
