#include <nlohmann/json.hpp>
#include <stdexcept>

#include "gbdcs/contracts/json_options.hpp"
#include "gbdcs/sim/twin_sim.hpp"

namespace gbdcs::sim {

TwinOptions TwinOptions::from_json(const nlohmann::json& doc) {
  if (!doc.is_object()) {
    throw std::invalid_argument("TwinOptions: options must be a JSON object, got " +
                                std::string(doc.type_name()));
  }
  TwinOptions o;
  nlohmann::json scalars = doc;  // the nested parts are read here, the numbers below
  if (const auto it = doc.find("controller"); it != doc.end()) {
    o.controller = FlightControllerOptions::from_json(*it);
    scalars.erase("controller");
  }
  if (const auto it = doc.find("battery"); it != doc.end()) {
    o.battery = BatteryOptions::from_json(*it);
    scalars.erase("battery");
  }
  if (const auto it = doc.find("faults"); it != doc.end()) {
    o.faults = FaultSchedule::from_json(*it);
    scalars.erase("faults");
  }
  contracts::JsonOptionReader r(scalars, "TwinOptions");
  r.read("crash_speed_m_s", o.crash_speed_m_s);
  r.read("auto_land_after_s", o.auto_land_after_s);
  r.finish();
  contracts::require(o.crash_speed_m_s > 0, "TwinOptions", "crash_speed_m_s", "must be > 0");
  contracts::require(o.auto_land_after_s > 0, "TwinOptions", "auto_land_after_s", "must be > 0");
  return o;
}

}  // namespace gbdcs::sim
