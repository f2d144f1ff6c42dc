// BatteryModel: a 1S LiPo like the Tello's (1100 mAh, 3.8 V nominal). Pure, no clock.
//
// Inputs  : step(dt_s, motor thrusts N) - called every physics step.
// Model   : electrical power = idle_power_w + thrust_power_w_per_n1_5 * sum(thrust_i^1.5)
//           (rotor power grows with thrust^1.5, momentum theory). Open-circuit voltage is
//           linear in the state of charge: nominal_voltage_v +- voltage_span_v / 2 at 100 % /
//           0 %. Under load the terminal voltage sags by I * internal_resistance_ohm, and the
//           current is what delivers the power at that voltage: P = I (V_oc - I R).
//           Charge is counted: remaining_mah -= I * dt / 3.6.
//           Defaults: hover (80 g) draws about 19 W, 5 A: a full battery lasts about 13 min.
// Outputs : pct() 0...100, voltage_v() (terminal, under the last load), current_a(), empty().
// Options : BatteryOptions below; JSON keys = member names.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include "gbdcs/sim/flight_controller.hpp"

namespace gbdcs::sim {

struct BatteryOptions {
  double capacity_mah = 1100;
  double nominal_voltage_v = 3.8;  // open-circuit voltage at 50 %
  double voltage_span_v = 0.8;     // open circuit: 4.2 V full ... 3.4 V empty
  double internal_resistance_ohm = 0.06;
  double idle_power_w = 2.0;  // flight controller, camera, radio; drawn when landed too
  double thrust_power_w_per_n1_5 = 50.0;
  double start_pct = 100;

  static BatteryOptions from_json(const nlohmann::json& doc);  // throws std::invalid_argument
};

class BatteryModel {
 public:
  explicit BatteryModel(BatteryOptions options = {});

  void step(double dt_s, const MotorThrusts& thrust_n);
  void set_pct(double pct);  // battery_jump fault; clamped to [0, 100]

  double power_w(const MotorThrusts& thrust_n) const;
  // The current that delivers `power_w` at the present state of charge (A).
  double current_for_power_a(double power_w) const;
  double open_circuit_voltage_v() const;

  double pct() const { return 100.0 * remaining_mah_ / options_.capacity_mah; }
  double remaining_mah() const { return remaining_mah_; }
  double voltage_v() const { return voltage_v_; }
  double current_a() const { return current_a_; }
  bool empty() const { return remaining_mah_ <= 0; }
  const BatteryOptions& options() const { return options_; }

 private:
  BatteryOptions options_;
  double remaining_mah_;
  double current_a_ = 0;
  double voltage_v_;
};

}  // namespace gbdcs::sim
