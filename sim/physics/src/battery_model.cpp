#include "gbdcs/sim/battery_model.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "gbdcs/contracts/json_options.hpp"

namespace gbdcs::sim {

BatteryOptions BatteryOptions::from_json(const nlohmann::json& doc) {
  BatteryOptions o;
  contracts::JsonOptionReader r(doc, "BatteryOptions");
  r.read("capacity_mah", o.capacity_mah);
  r.read("nominal_voltage_v", o.nominal_voltage_v);
  r.read("voltage_span_v", o.voltage_span_v);
  r.read("internal_resistance_ohm", o.internal_resistance_ohm);
  r.read("idle_power_w", o.idle_power_w);
  r.read("thrust_power_w_per_n1_5", o.thrust_power_w_per_n1_5);
  r.read("start_pct", o.start_pct);
  r.finish();
  const std::string owner = "BatteryOptions";
  contracts::require(o.capacity_mah > 0, owner, "capacity_mah", "must be > 0");
  contracts::require(o.nominal_voltage_v > 0, owner, "nominal_voltage_v", "must be > 0");
  contracts::require(o.voltage_span_v >= 0 && o.voltage_span_v < 2 * o.nominal_voltage_v, owner,
                     "voltage_span_v", "must be in [0, 2 * nominal_voltage_v)");
  contracts::require(o.internal_resistance_ohm >= 0, owner, "internal_resistance_ohm",
                     "must be >= 0");
  contracts::require(o.idle_power_w >= 0, owner, "idle_power_w", "must be >= 0");
  contracts::require(o.thrust_power_w_per_n1_5 >= 0, owner, "thrust_power_w_per_n1_5",
                     "must be >= 0");
  contracts::require(o.start_pct >= 0 && o.start_pct <= 100, owner, "start_pct",
                     "must be in [0, 100]");
  return o;
}

BatteryModel::BatteryModel(BatteryOptions options)
    : options_(options),
      remaining_mah_(options.capacity_mah * std::clamp(options.start_pct, 0.0, 100.0) / 100.0),
      voltage_v_(open_circuit_voltage_v()) {}

double BatteryModel::open_circuit_voltage_v() const {
  const double soc = remaining_mah_ / options_.capacity_mah;
  return options_.nominal_voltage_v + (soc - 0.5) * options_.voltage_span_v;
}

double BatteryModel::power_w(const MotorThrusts& thrust_n) const {
  double rotor = 0;
  for (const double f : thrust_n) rotor += std::pow(std::max(f, 0.0), 1.5);
  return options_.idle_power_w + options_.thrust_power_w_per_n1_5 * rotor;
}

double BatteryModel::current_for_power_a(double power_w) const {
  const double voc = open_circuit_voltage_v();
  const double r = options_.internal_resistance_ohm;
  if (r <= 0) return power_w / voc;
  // P = I (Voc - I R): the smaller root; past the maximum power point, that point.
  const double disc = voc * voc - 4.0 * r * power_w;
  return disc > 0 ? (voc - std::sqrt(disc)) / (2.0 * r) : voc / (2.0 * r);
}

void BatteryModel::step(double dt_s, const MotorThrusts& thrust_n) {
  current_a_ = current_for_power_a(power_w(thrust_n));
  remaining_mah_ = std::max(0.0, remaining_mah_ - current_a_ * dt_s / 3.6);
  voltage_v_ = open_circuit_voltage_v() - current_a_ * options_.internal_resistance_ohm;
}

void BatteryModel::set_pct(double pct) {
  remaining_mah_ = options_.capacity_mah * std::clamp(pct, 0.0, 100.0) / 100.0;
  voltage_v_ = open_circuit_voltage_v() - current_a_ * options_.internal_resistance_ohm;
}

}  // namespace gbdcs::sim
