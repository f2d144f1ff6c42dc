#include <stdexcept>

#include "gbdcs/adapters/airsim_adapter.hpp"
#include "gbdcs/contracts/json_options.hpp"

namespace gbdcs::adapters {

AirSimOptions AirSimOptions::from_json(const nlohmann::json& doc) {
  AirSimOptions o;
  const std::string owner = "airsim options";
  if (doc.is_null()) return o;
  if (!doc.is_object()) {
    throw std::invalid_argument(owner + ": options must be a JSON object, got " +
                                std::string(doc.type_name()));
  }
  nlohmann::json rest = doc;
  for (const char* key : {"address", "vehicle"}) {
    if (auto it = rest.find(key); it != rest.end()) {
      if (!it->is_string()) {
        throw std::invalid_argument(owner + ": '" + key + "' must be a string, got " + it->dump());
      }
      (std::string(key) == "address" ? o.address : o.vehicle) = it->get<std::string>();
      rest.erase(key);
    }
  }
  contracts::JsonOptionReader r(rest, owner);
  r.read("port", o.port);
  r.read("connect_timeout_ms", o.connect_timeout_ms);
  r.read("rpc_timeout_ms", o.rpc_timeout_ms);
  r.read("ack_wait_ms", o.ack_wait_ms);
  r.read("telemetry_hz", o.telemetry_hz);
  r.read("link_timeout_s", o.link_timeout_s);
  r.read("reconnect_min_s", o.reconnect_min_s);
  r.read("reconnect_max_s", o.reconnect_max_s);
  r.read("takeoff_timeout_s", o.takeoff_timeout_s);
  r.read("land_timeout_s", o.land_timeout_s);
  r.read("move_chunk_s", o.move_chunk_s);
  r.read("move_resend_s", o.move_resend_s);
  r.read("max_horizontal_m_s", o.max_horizontal_m_s);
  r.read("max_vertical_m_s", o.max_vertical_m_s);
  r.read("max_yaw_rate_deg_s", o.max_yaw_rate_deg_s);
  try {
    r.finish();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(e.what()) + " (also: address, vehicle)");
  }
  contracts::require(o.port >= 1 && o.port <= 65535, owner, "port", "must be within [1, 65535]");
  contracts::require(o.connect_timeout_ms >= 10 && o.rpc_timeout_ms >= 10, owner,
                     "connect_timeout_ms/rpc_timeout_ms", "must be at least 10");
  contracts::require(o.ack_wait_ms >= 0 && o.ack_wait_ms <= 10000, owner, "ack_wait_ms",
                     "must be within [0, 10000]");
  contracts::require(o.telemetry_hz >= 5 && o.telemetry_hz <= 100, owner, "telemetry_hz",
                     "must be within [5, 100]");
  contracts::require(o.link_timeout_s >= 0.2, owner, "link_timeout_s", "must be at least 0.2");
  contracts::require(o.reconnect_min_s > 0 && o.reconnect_max_s >= o.reconnect_min_s, owner,
                     "reconnect_min_s/reconnect_max_s", "must be positive, min <= max");
  contracts::require(o.move_chunk_s > o.move_resend_s && o.move_resend_s > 0, owner,
                     "move_chunk_s/move_resend_s",
                     "must be positive with move_chunk_s > move_resend_s");
  contracts::require(o.takeoff_timeout_s > 0 && o.land_timeout_s > 0, owner, "*_timeout_s",
                     "must be positive");
  contracts::require(o.max_horizontal_m_s > 0 && o.max_vertical_m_s > 0 &&
                         o.max_yaw_rate_deg_s > 0,
                     owner, "max_*", "must be positive");
  return o;
}

}  // namespace gbdcs::adapters
