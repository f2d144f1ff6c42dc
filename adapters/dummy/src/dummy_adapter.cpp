#include "gbdcs/adapters/dummy_adapter.hpp"

#include "gbdcs/contracts/json_options.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace gbdcs::adapters {

using contracts::FlightState;
using control::Result;

namespace {
constexpr double kStepS = 0.01;
constexpr double kGravityM_s2 = 9.81;
}  // namespace

DummyOptions DummyOptions::from_json(const nlohmann::json& doc) {
  DummyOptions o;
  contracts::JsonOptionReader r(doc, "dummy options");
  r.read("telemetry_hz", o.telemetry_hz);
  r.read("takeoff_altitude_m", o.takeoff_altitude_m);
  r.read("climb_m_s", o.climb_m_s);
  r.read("land_m_s", o.land_m_s);
  r.read("max_speed_m_s", o.max_speed_m_s);
  r.read("battery_start_pct", o.battery_start_pct);
  r.read("drain_idle_pct_s", o.drain_idle_pct_s);
  r.read("drain_flying_pct_s", o.drain_flying_pct_s);
  r.read("crash_speed_m_s", o.crash_speed_m_s);
  r.finish();
  const std::string owner = "dummy options";
  contracts::require(o.telemetry_hz >= 5 && o.telemetry_hz <= 100, owner, "telemetry_hz",
                     "must be within [5, 100]");
  contracts::require(o.battery_start_pct >= 0 && o.battery_start_pct <= 100, owner,
                     "battery_start_pct", "must be within [0, 100]");
  for (double v : {o.takeoff_altitude_m, o.climb_m_s, o.land_m_s, o.max_speed_m_s,
                   o.crash_speed_m_s}) {
    contracts::require(v > 0, owner, "speeds and altitudes", "must be positive");
  }
  contracts::require(o.drain_idle_pct_s >= 0 && o.drain_flying_pct_s >= 0, owner, "drain_*",
                     "must not be negative");
  return o;
}

DummyDroneAdapter::DummyDroneAdapter(const contracts::Clock& clock, DummyOptions options)
    : clock_(clock), options_(options), battery_pct_(options.battery_start_pct) {
  last_step_ = clock_.now();
  next_telemetry_ = last_step_;
}

Result DummyDroneAdapter::guard_locked(const char* what) {
  if (!connected_) {
    last_error_ = std::string(what) + ": not connected (call connect first)";
    return Result::kNotConnected;
  }
  if (link_lost_) {
    last_error_ = std::string(what) + ": link lost";
    return Result::kNotConnected;
  }
  return Result::kOk;
}

Result DummyDroneAdapter::connect() {
  std::lock_guard lock(mutex_);
  connected_ = true;
  if (state_ == FlightState::kInit) state_ = FlightState::kReady;
  last_step_ = clock_.now();
  next_telemetry_ = last_step_;
  return Result::kOk;
}

Result DummyDroneAdapter::disconnect() {
  std::lock_guard lock(mutex_);
  connected_ = false;
  return Result::kOk;
}

Result DummyDroneAdapter::takeoff() {
  std::lock_guard lock(mutex_);
  if (auto r = guard_locked("takeoff"); r != Result::kOk) return r;
  if (state_ != FlightState::kReady || battery_pct_ <= 0) {
    last_error_ = "takeoff: drone is " + std::string(contracts::to_string(state_)) +
                  (battery_pct_ <= 0 ? " with an empty battery" : "");
    return Result::kRejected;
  }
  motors_cut_ = false;
  state_ = FlightState::kFlying;
  vx_m_s_ = vy_m_s_ = yaw_rate_deg_s_ = 0;
  vz_m_s_ = options_.climb_m_s;
  taking_off_ = true;
  move_remaining_s_ = options_.takeoff_altitude_m / std::max(options_.climb_m_s, 1e-3);
  return Result::kOk;
}

Result DummyDroneAdapter::land() {
  std::lock_guard lock(mutex_);
  if (auto r = guard_locked("land"); r != Result::kOk) return r;
  if (state_ != FlightState::kFlying) {
    last_error_ = "land: drone is " + std::string(contracts::to_string(state_));
    return Result::kRejected;
  }
  state_ = FlightState::kLanding;
  taking_off_ = false;
  vx_m_s_ = vy_m_s_ = yaw_rate_deg_s_ = 0;
  vz_m_s_ = -options_.land_m_s;
  return Result::kOk;
}

Result DummyDroneAdapter::hover() {
  std::lock_guard lock(mutex_);
  if (auto r = guard_locked("hover"); r != Result::kOk) return r;
  if (state_ != FlightState::kFlying) {
    last_error_ = "hover: drone is " + std::string(contracts::to_string(state_));
    return Result::kRejected;
  }
  if (taking_off_) return Result::kOk;  // the climb ends in a hover anyway
  vx_m_s_ = vy_m_s_ = vz_m_s_ = yaw_rate_deg_s_ = 0;
  move_remaining_s_ = 0;
  return Result::kOk;
}

Result DummyDroneAdapter::move(const contracts::MotionPayload& motion) {
  std::lock_guard lock(mutex_);
  if (auto r = guard_locked("move"); r != Result::kOk) return r;
  if (state_ != FlightState::kFlying) {
    last_error_ = "move: drone is " + std::string(contracts::to_string(state_));
    return Result::kRejected;
  }
  if (taking_off_) {
    last_error_ = "move: still taking off (wait until it hovers)";
    return Result::kRejected;
  }
  const double limit = options_.max_speed_m_s;
  vx_m_s_ = std::clamp(motion.vx_m_s, -limit, limit);
  vy_m_s_ = std::clamp(motion.vy_m_s, -limit, limit);
  vz_m_s_ = std::clamp(motion.vz_m_s, -limit, limit);
  yaw_rate_deg_s_ = std::clamp(motion.yaw_rate_deg_s, -180.0, 180.0);
  move_remaining_s_ = motion.duration_s > 0 ? motion.duration_s : -1;
  return Result::kOk;
}

Result DummyDroneAdapter::emergency_stop() {
  std::lock_guard lock(mutex_);
  // A real radio would still try; the dummy accepts it even without a link only when connected.
  if (!connected_) return Result::kNotConnected;
  if (link_lost_) return Result::kNotConnected;
  motors_cut_ = true;
  taking_off_ = false;
  vx_m_s_ = vy_m_s_ = vz_m_s_ = yaw_rate_deg_s_ = 0;
  if (altitude_m_ > 0) state_ = FlightState::kLanding;
  return Result::kOk;
}

FlightState DummyDroneAdapter::state() const {
  std::lock_guard lock(mutex_);
  return state_;
}

void DummyDroneAdapter::set_telemetry_sink(control::TelemetrySink sink) {
  std::lock_guard lock(mutex_);
  sink_ = std::move(sink);
}

std::string DummyDroneAdapter::last_error() const {
  std::lock_guard lock(mutex_);
  return last_error_;
}

void DummyDroneAdapter::set_link_lost(bool lost) {
  std::lock_guard lock(mutex_);
  link_lost_ = lost;
}

void DummyDroneAdapter::set_battery_pct(double pct) {
  std::lock_guard lock(mutex_);
  battery_pct_ = std::clamp(pct, 0.0, 100.0);
}

contracts::TelemetryFrame DummyDroneAdapter::snapshot() const {
  std::lock_guard lock(mutex_);
  return frame_locked();
}

void DummyDroneAdapter::step_locked(double dt) {
  const bool airborne = state_ == FlightState::kFlying || state_ == FlightState::kLanding;
  battery_pct_ = std::max(
      0.0, battery_pct_ - dt * (airborne && !motors_cut_ ? options_.drain_flying_pct_s
                                                         : (connected_ ? options_.drain_idle_pct_s
                                                                       : 0.0)));
  if (!airborne) return;
  if (motors_cut_) {
    fall_speed_m_s_ += kGravityM_s2 * dt;
    altitude_m_ -= fall_speed_m_s_ * dt;
    if (altitude_m_ <= 0) {
      altitude_m_ = 0;
      state_ = fall_speed_m_s_ > options_.crash_speed_m_s ? FlightState::kFault : FlightState::kReady;
      fall_speed_m_s_ = 0;
      motors_cut_ = false;
    }
    return;
  }
  if (battery_pct_ <= 0 && state_ == FlightState::kFlying) {
    state_ = FlightState::kLanding;  // an empty battery lands by itself
    vx_m_s_ = vy_m_s_ = yaw_rate_deg_s_ = 0;
    vz_m_s_ = -options_.land_m_s;
  }
  const double h = heading_deg_ * std::numbers::pi / 180.0;
  x_m_ += (vx_m_s_ * std::cos(h) - vy_m_s_ * std::sin(h)) * dt;
  y_m_ += (vx_m_s_ * std::sin(h) + vy_m_s_ * std::cos(h)) * dt;
  altitude_m_ += vz_m_s_ * dt;
  heading_deg_ = std::fmod(heading_deg_ + yaw_rate_deg_s_ * dt + 360.0, 360.0);
  if (state_ == FlightState::kLanding) {
    if (altitude_m_ <= 0) {
      altitude_m_ = 0;
      vz_m_s_ = 0;
      state_ = FlightState::kReady;
    }
    return;
  }
  if (vz_m_s_ < 0) altitude_m_ = std::max(altitude_m_, 0.2);  // a hovering drone keeps off the floor
  if (move_remaining_s_ > 0) {
    move_remaining_s_ -= dt;
    if (move_remaining_s_ <= 0) {
      move_remaining_s_ = 0;
      taking_off_ = false;
      vx_m_s_ = vy_m_s_ = vz_m_s_ = yaw_rate_deg_s_ = 0;  // a timed move ends in a hover
    }
  }
}

contracts::TelemetryFrame DummyDroneAdapter::frame_locked() const {
  contracts::TelemetryFrame f;
  f.timestamp = clock_.utc_now();
  f.altitude_m = altitude_m_;
  f.vx_m_s = vx_m_s_;
  f.vy_m_s = vy_m_s_;
  f.vz_m_s = motors_cut_ ? -fall_speed_m_s_ : vz_m_s_;
  f.speed_m_s = std::sqrt(f.vx_m_s * f.vx_m_s + f.vy_m_s * f.vy_m_s + f.vz_m_s * f.vz_m_s);
  f.x_m = x_m_;
  f.y_m = y_m_;
  f.heading_deg = heading_deg_;
  f.battery_pct = battery_pct_;
  f.flight_state = state_;
  f.link = link_lost_ ? contracts::LinkState::kLost : contracts::LinkState::kOk;
  return f;
}

void DummyDroneAdapter::poll() {
  std::vector<contracts::TelemetryFrame> frames;
  control::TelemetrySink sink;
  {
    std::lock_guard lock(mutex_);
    const auto now = clock_.now();
    const auto step = contracts::from_seconds(kStepS);
    const auto period = contracts::from_seconds(1.0 / options_.telemetry_hz);
    while (last_step_ + step <= now) {
      step_locked(kStepS);
      last_step_ += step;
      if (connected_ && last_step_ >= next_telemetry_) {
        next_telemetry_ += period;
        if (!link_lost_) frames.push_back(frame_locked());
      }
    }
    sink = sink_;
  }
  if (sink) {
    for (const auto& f : frames) sink(f);
  }
}

}  // namespace gbdcs::adapters
