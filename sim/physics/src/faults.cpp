#include "gbdcs/sim/faults.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "counter_rng.hpp"
#include "gbdcs/contracts/json_file.hpp"
#include "gbdcs/contracts/json_options.hpp"

namespace gbdcs::sim {
namespace {

constexpr std::array<std::pair<FaultType, std::string_view>, 6> kFaultNames = {{
    {FaultType::kLinkLoss, "link_loss"},
    {FaultType::kTelemetryDelay, "telemetry_delay"},
    {FaultType::kBatteryJump, "battery_jump"},
    {FaultType::kWindGust, "wind_gust"},
    {FaultType::kMotorDegraded, "motor_degraded"},
    {FaultType::kSensorNoise, "sensor_noise"},
}};

std::string known_types() {
  std::string list;
  for (const auto& [type, name] : kFaultNames)
    list += (list.empty() ? "" : ", ") + std::string(name);
  return list;
}

void require_key(const nlohmann::json& item, const std::string& owner, const std::string& key) {
  if (!item.contains(key)) throw std::invalid_argument(owner + ": '" + key + "' is required");
}

Fault parse_fault(const nlohmann::json& item, std::size_t index) {
  std::string owner = "fault " + std::to_string(index);
  if (!item.is_object()) {
    throw std::invalid_argument(owner + ": must be a JSON object, got " +
                                std::string(item.type_name()));
  }
  const auto type_it = item.find("type");
  if (type_it == item.end() || !type_it->is_string()) {
    throw std::invalid_argument(owner + ": 'type' is required, a string (one of: " + known_types() +
                                ")");
  }
  const auto type = fault_type_from_string(type_it->get<std::string>());
  if (!type) {
    throw std::invalid_argument(owner + ": unknown type '" + type_it->get<std::string>() +
                                "' (known: " + known_types() + ")");
  }
  owner += " (" + std::string(to_string(*type)) + ")";
  Fault f;
  f.type = *type;
  nlohmann::json rest = item;
  rest.erase("type");
  if (f.type == FaultType::kWindGust) {
    require_key(rest, owner, "force_n");
    const auto& force = rest["force_n"];
    if (!force.is_array() || force.size() != 3 ||
        !std::all_of(force.begin(), force.end(), [](const auto& v) { return v.is_number(); })) {
      throw std::invalid_argument(owner + ": 'force_n' must be an array of 3 numbers [x, y, z]");
    }
    for (std::size_t i = 0; i < 3; ++i) f.force_n[i] = force[i].get<double>();
    rest.erase("force_n");
  }

  contracts::JsonOptionReader r(rest, owner);
  r.read("start_s", f.start_s);
  if (f.type != FaultType::kBatteryJump) r.read("duration_s", f.duration_s);
  switch (f.type) {
    case FaultType::kLinkLoss:
    case FaultType::kWindGust:
      break;
    case FaultType::kTelemetryDelay:
      require_key(rest, owner, "delay_ms");
      r.read("delay_ms", f.delay_ms);
      r.read("jitter_ms", f.jitter_ms);
      break;
    case FaultType::kBatteryJump:
      require_key(rest, owner, "battery_pct");
      r.read("battery_pct", f.battery_pct);
      break;
    case FaultType::kMotorDegraded:
      require_key(rest, owner, "motor");
      require_key(rest, owner, "thrust_factor");
      r.read("motor", f.motor);
      r.read("thrust_factor", f.thrust_factor);
      break;
    case FaultType::kSensorNoise:
      r.read("position_sigma_m", f.position_sigma_m);
      r.read("velocity_sigma_m_s", f.velocity_sigma_m_s);
      r.read("heading_sigma_deg", f.heading_sigma_deg);
      break;
  }
  r.finish();
  return f;
}

void validate(const Fault& f, std::size_t index) {
  const std::string owner =
      "fault " + std::to_string(index) + " (" + std::string(to_string(f.type)) + ")";
  using contracts::require;
  require(std::isfinite(f.start_s) && f.start_s >= 0, owner, "start_s", "must be >= 0");
  require(f.duration_s > 0, owner, "duration_s", "must be > 0 (omit it: to the end of the run)");
  require(f.delay_ms >= 0 && std::isfinite(f.delay_ms), owner, "delay_ms", "must be >= 0");
  require(f.jitter_ms >= 0 && std::isfinite(f.jitter_ms), owner, "jitter_ms", "must be >= 0");
  require(f.battery_pct >= 0 && f.battery_pct <= 100, owner, "battery_pct", "must be in [0, 100]");
  for (const double c : f.force_n) {
    require(std::isfinite(c) && std::abs(c) <= 100, owner, "force_n",
            "components must be within +-100 N");
  }
  require(f.motor >= 0 && f.motor <= 3, owner, "motor", "must be 0...3");
  require(f.thrust_factor >= 0 && f.thrust_factor <= 1, owner, "thrust_factor",
          "must be in [0, 1]");
  require(f.position_sigma_m >= 0, owner, "position_sigma_m", "must be >= 0");
  require(f.velocity_sigma_m_s >= 0, owner, "velocity_sigma_m_s", "must be >= 0");
  require(f.heading_sigma_deg >= 0, owner, "heading_sigma_deg", "must be >= 0");
}

}  // namespace

std::string_view to_string(FaultType t) {
  for (const auto& [type, name] : kFaultNames) {
    if (type == t) return name;
  }
  return "?";
}

std::optional<FaultType> fault_type_from_string(std::string_view s) {
  for (const auto& [type, name] : kFaultNames) {
    if (name == s) return type;
  }
  return std::nullopt;
}

FaultSchedule::FaultSchedule(std::vector<Fault> faults) : faults_(std::move(faults)) {
  for (std::size_t i = 0; i < faults_.size(); ++i) validate(faults_[i], i);
}

FaultSchedule FaultSchedule::from_json(const nlohmann::json& doc) {
  const nlohmann::json* list = &doc;
  if (doc.is_object()) {
    for (const auto& [key, value] : doc.items()) {
      if (key != "faults") {
        throw std::invalid_argument("FaultSchedule: '" + key +
                                    "' is not a known key (known: faults)");
      }
    }
    if (!doc.contains("faults")) throw std::invalid_argument("FaultSchedule: 'faults' is required");
    list = &doc["faults"];
  }
  if (!list->is_array()) {
    throw std::invalid_argument("FaultSchedule: expected an array of faults, got " +
                                std::string(list->type_name()));
  }
  std::vector<Fault> faults;
  for (std::size_t i = 0; i < list->size(); ++i) faults.push_back(parse_fault((*list)[i], i));
  return FaultSchedule(std::move(faults));
}

FaultSchedule FaultSchedule::from_json_text(std::string_view text) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw std::invalid_argument("FaultSchedule: malformed JSON at byte " + std::to_string(e.byte) +
                                ": " + e.what());
  } catch (const nlohmann::json::exception& e) {  // out_of_range: a number too large (1e999)
    throw std::invalid_argument(std::string("FaultSchedule: malformed JSON: ") + e.what());
  }
  return from_json(doc);
}

FaultSchedule FaultSchedule::load(const std::string& path) {
  const auto doc = contracts::read_json_file<std::invalid_argument>(path, "fault schedule");
  return contracts::prefix_errors<std::invalid_argument>(path, [&] { return from_json(doc); });
}

nlohmann::json FaultSchedule::to_json() const {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& f : faults_) {
    nlohmann::json j{{"type", to_string(f.type)}, {"start_s", f.start_s}};
    if (f.type != FaultType::kBatteryJump && std::isfinite(f.duration_s)) {
      j["duration_s"] = f.duration_s;
    }
    switch (f.type) {
      case FaultType::kLinkLoss:
        break;
      case FaultType::kTelemetryDelay:
        j["delay_ms"] = f.delay_ms;
        j["jitter_ms"] = f.jitter_ms;
        break;
      case FaultType::kBatteryJump:
        j["battery_pct"] = f.battery_pct;
        break;
      case FaultType::kWindGust:
        j["force_n"] = f.force_n;
        break;
      case FaultType::kMotorDegraded:
        j["motor"] = f.motor;
        j["thrust_factor"] = f.thrust_factor;
        break;
      case FaultType::kSensorNoise:
        j["position_sigma_m"] = f.position_sigma_m;
        j["velocity_sigma_m_s"] = f.velocity_sigma_m_s;
        j["heading_sigma_deg"] = f.heading_sigma_deg;
        break;
    }
    list.push_back(std::move(j));
  }
  return nlohmann::json{{"faults", std::move(list)}};
}

bool FaultSchedule::link_lost(double t_s) const {
  return std::any_of(faults_.begin(), faults_.end(), [&](const Fault& f) {
    return f.type == FaultType::kLinkLoss && f.active(t_s);
  });
}

double FaultSchedule::telemetry_delay_s(double t_s, std::uint32_t seed) const {
  const Fault* worst = nullptr;
  for (const auto& f : faults_) {
    if (f.type == FaultType::kTelemetryDelay && f.active(t_s) &&
        (worst == nullptr || f.delay_ms > worst->delay_ms)) {
      worst = &f;
    }
  }
  if (worst == nullptr) return 0;
  const auto ms = static_cast<std::uint64_t>(std::llround(std::max(t_s, 0.0) * 1000.0));
  const double u = 2.0 * detail::counter_uniform(seed, ms, 0x7e1e) - 1.0;
  return std::max(0.0, worst->delay_ms + u * worst->jitter_ms) / 1000.0;
}

std::array<double, 3> FaultSchedule::wind_force_n(double t_s) const {
  std::array<double, 3> sum{};
  for (const auto& f : faults_) {
    if (f.type != FaultType::kWindGust || !f.active(t_s)) continue;
    for (std::size_t i = 0; i < 3; ++i) sum[i] += f.force_n[i];
  }
  return sum;
}

double FaultSchedule::motor_factor(int motor, double t_s) const {
  double factor = 1.0;
  for (const auto& f : faults_) {
    if (f.type == FaultType::kMotorDegraded && f.motor == motor && f.active(t_s)) {
      factor *= f.thrust_factor;
    }
  }
  return factor;
}

SensorNoise FaultSchedule::sensor_noise(double t_s) const {
  SensorNoise n;
  for (const auto& f : faults_) {
    if (f.type != FaultType::kSensorNoise || !f.active(t_s)) continue;
    n.position_sigma_m = std::max(n.position_sigma_m, f.position_sigma_m);
    n.velocity_sigma_m_s = std::max(n.velocity_sigma_m_s, f.velocity_sigma_m_s);
    n.heading_sigma_deg = std::max(n.heading_sigma_deg, f.heading_sigma_deg);
  }
  return n;
}

}  // namespace gbdcs::sim
