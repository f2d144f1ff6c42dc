// DummyDroneAdapter: a drone with simple kinematics and a draining battery, no simulator and
// no network. For the logic scenarios, `ci/up` before the server, and unit tests.
//
// Time  : the injected Clock; poll() advances the kinematics to clock.now() in fixed steps
//         and emits telemetry at telemetry_hz (simulated time).
// States: INIT -connect-> READY -takeoff-> FLYING (climbs to takeoff_altitude_m) -land->
//         LANDING -> READY on touch-down. emergency_stop cuts the motors: it falls and is
//         READY on the ground (FAULT if it hit the ground faster than crash_speed_m_s).
//         Battery at 0 % forces a landing.
// Faults: set_link_lost(true) drops commands (kNotConnected) and telemetry, as a radio would.
// Options (defaults): telemetry_hz 10, takeoff_altitude_m 1.0, climb_m_s 0.5, land_m_s 0.4,
//   max_speed_m_s 2.0, battery_start_pct 100, drain_idle_pct_s 0.02, drain_flying_pct_s 0.25,
//   crash_speed_m_s 3.0.
#pragma once

#include <mutex>
#include <nlohmann/json.hpp>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/control/drone_adapter.hpp"

namespace gbdcs::adapters {

struct DummyOptions {
  double telemetry_hz = 10;
  double takeoff_altitude_m = 1.0;
  double climb_m_s = 0.5;
  double land_m_s = 0.4;
  double max_speed_m_s = 2.0;
  double battery_start_pct = 100;
  double drain_idle_pct_s = 0.02;
  double drain_flying_pct_s = 0.25;
  double crash_speed_m_s = 3.0;

  static DummyOptions from_json(const nlohmann::json& doc);  // throws std::invalid_argument
};

class DummyDroneAdapter final : public control::DroneAdapter {
 public:
  DummyDroneAdapter(const contracts::Clock& clock, DummyOptions options = {});

  std::string_view name() const override { return "dummy"; }
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

  void set_link_lost(bool lost);
  void set_battery_pct(double pct);
  contracts::TelemetryFrame snapshot() const;

 private:
  void step_locked(double dt_s);
  contracts::TelemetryFrame frame_locked() const;
  control::Result guard_locked(const char* what);

  const contracts::Clock& clock_;
  DummyOptions options_;
  mutable std::mutex mutex_;
  control::TelemetrySink sink_;
  bool connected_ = false;
  bool link_lost_ = false;
  bool motors_cut_ = false;
  bool taking_off_ = false;  // climbing to take-off altitude; moves wait for the hover
  contracts::FlightState state_ = contracts::FlightState::kInit;
  double x_m_ = 0, y_m_ = 0, altitude_m_ = 0, heading_deg_ = 0;
  double vx_m_s_ = 0, vy_m_s_ = 0, vz_m_s_ = 0, yaw_rate_deg_s_ = 0;
  double fall_speed_m_s_ = 0;
  double move_remaining_s_ = 0;  // < 0: hold until the next command
  double battery_pct_ = 100;
  contracts::Duration last_step_{0};
  contracts::Duration next_telemetry_{0};
  std::string last_error_;
};

}  // namespace gbdcs::adapters
