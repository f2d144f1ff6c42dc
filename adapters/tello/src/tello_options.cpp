#include <stdexcept>

#include "gbdcs/adapters/tello_adapter.hpp"
#include "gbdcs/contracts/json_options.hpp"

namespace gbdcs::adapters {
namespace {

std::string take_string(nlohmann::json& doc, const std::string& owner, const char* key,
                        const std::string& fallback, bool allow_empty) {
  const auto it = doc.find(key);
  if (it == doc.end()) return fallback;
  if (!it->is_string()) {
    throw std::invalid_argument(owner + ": '" + key + "' must be a string, got " + it->dump());
  }
  auto value = it->get<std::string>();
  if (value.empty() && !allow_empty) {
    throw std::invalid_argument(owner + ": '" + key + "' must not be empty");
  }
  for (char c : value) {
    if (c < 0x21 || c > 0x7e) {
      if (c == ' ' && std::string(key) != "address") continue;
      throw std::invalid_argument(owner + ": '" + key + "' has a control or non-ASCII character");
    }
  }
  doc.erase(key);
  return value;
}

TelloCommandWords read_words(const nlohmann::json& doc, const std::string& owner,
                             TelloCommandWords w) {
  if (!doc.is_object()) {
    throw std::invalid_argument(owner + ": 'commands' must be an object of command words");
  }
  nlohmann::json rest = doc;
  const std::string o = owner + ": commands";
  w.handshake = take_string(rest, o, "handshake", w.handshake, false);
  w.takeoff = take_string(rest, o, "takeoff", w.takeoff, false);
  w.land = take_string(rest, o, "land", w.land, false);
  w.emergency = take_string(rest, o, "emergency", w.emergency, false);
  w.stop = take_string(rest, o, "stop", w.stop, true);
  w.rc = take_string(rest, o, "rc", w.rc, false);
  w.keepalive = take_string(rest, o, "keepalive", w.keepalive, false);
  w.battery = take_string(rest, o, "battery", w.battery, true);
  if (!rest.empty()) {
    throw std::invalid_argument(o + ": '" + rest.begin().key() +
                                "' is not a command word (known: handshake, takeoff, land, "
                                "emergency, stop, rc, keepalive, battery)");
  }
  return w;
}

}  // namespace

TelloOptions TelloOptions::from_json(const nlohmann::json& doc) {
  return from_json(doc, TelloOptions{});
}

TelloOptions TelloOptions::from_json(const nlohmann::json& doc, TelloOptions o) {
  const std::string owner = o.name + " options";
  if (doc.is_null()) return o;
  if (!doc.is_object()) {
    throw std::invalid_argument(owner + ": options must be a JSON object, got " +
                                std::string(doc.type_name()));
  }
  nlohmann::json rest = doc;
  o.address = take_string(rest, owner, "address", o.address, false);
  o.bind_address = take_string(rest, owner, "bind_address", o.bind_address, false);
  if (auto it = rest.find("commands"); it != rest.end()) {
    o.words = read_words(*it, owner, o.words);
    rest.erase("commands");
  }
  contracts::JsonOptionReader r(rest, owner);
  r.read("command_port", o.command_port);
  r.read("local_command_port", o.local_command_port);
  r.read("state_port", o.state_port);
  r.read("reply_timeout_ms", o.reply_timeout_ms);
  r.read("handshake_retries", o.handshake_retries);
  r.read("ack_wait_ms", o.ack_wait_ms);
  r.read("rc_hz", o.rc_hz);
  r.read("keepalive_s", o.keepalive_s);
  r.read("link_timeout_s", o.link_timeout_s);
  r.read("velocity_unit_m_s", o.velocity_unit_m_s);
  r.read("max_horizontal_m_s", o.max_horizontal_m_s);
  r.read("max_vertical_m_s", o.max_vertical_m_s);
  r.read("max_yaw_rate_deg_s", o.max_yaw_rate_deg_s);
  r.read("ground_height_cm", o.ground_height_cm);
  try {
    r.finish();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(e.what()) + " (also: address, bind_address, commands)");
  }
  contracts::require(o.command_port >= 1 && o.command_port <= 65535, owner, "command_port",
                     "must be within [1, 65535]");
  contracts::require(o.local_command_port >= 0 && o.local_command_port <= 65535, owner,
                     "local_command_port", "must be within [0, 65535] (0: any free port)");
  contracts::require(o.state_port >= 0 && o.state_port <= 65535, owner, "state_port",
                     "must be within [0, 65535] (0: any free port)");
  contracts::require(o.reply_timeout_ms >= 10 && o.reply_timeout_ms <= 60000, owner,
                     "reply_timeout_ms", "must be within [10, 60000]");
  contracts::require(o.handshake_retries >= 1 && o.handshake_retries <= 20, owner,
                     "handshake_retries", "must be within [1, 20]");
  contracts::require(o.ack_wait_ms >= 0 && o.ack_wait_ms <= 10000, owner, "ack_wait_ms",
                     "must be within [0, 10000]");
  contracts::require(o.rc_hz >= 1 && o.rc_hz <= 100, owner, "rc_hz", "must be within [1, 100]");
  contracts::require(o.keepalive_s >= 0.5 && o.keepalive_s <= 14, owner, "keepalive_s",
                     "must be within [0.5, 14] (the Tello lands after 15 s without a command)");
  contracts::require(o.link_timeout_s >= 0.2 && o.link_timeout_s <= 30, owner, "link_timeout_s",
                     "must be within [0.2, 30]");
  contracts::require(o.velocity_unit_m_s > 0 && o.velocity_unit_m_s <= 1, owner,
                     "velocity_unit_m_s", "must be within (0, 1]");
  contracts::require(o.max_horizontal_m_s > 0 && o.max_vertical_m_s > 0 &&
                         o.max_yaw_rate_deg_s > 0,
                     owner, "max_*", "must be positive");
  contracts::require(o.ground_height_cm >= 0 && o.ground_height_cm <= 100, owner,
                     "ground_height_cm", "must be within [0, 100]");
  return o;
}

}  // namespace gbdcs::adapters
