#include "gbdcs/sim/flight_controller.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>

#include "gbdcs/contracts/json_options.hpp"

namespace gbdcs::sim {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kIntegratorInputM_S = 0.2;
constexpr double kRateIntegralLimitRad_S2 = 50.0;

double wrap_pi(double a) {
  return std::remainder(a, 2.0 * std::numbers::pi);  // (-pi, pi]
}

double yaw_of(const Eigen::Matrix3d& r) {
  return std::atan2(r(1, 0), r(0, 0));
}

Eigen::Vector2d clamp_norm(const Eigen::Vector2d& v, double max) {
  const double n = v.norm();
  return n > max ? Eigen::Vector2d(v * (max / n)) : v;
}

}  // namespace

VehicleParams VehicleParams::tello() {
  VehicleParams p;
  p.rotor_xy_m = {Eigen::Vector2d(0.0325, 0.031), Eigen::Vector2d(0.0325, -0.031),
                  Eigen::Vector2d(-0.0325, -0.031), Eigen::Vector2d(-0.0325, 0.031)};
  p.yaw_torque_per_thrust_m = {-0.006, 0.006, -0.006, 0.006};
  return p;
}

FlightControllerOptions FlightControllerOptions::from_json(const nlohmann::json& doc) {
  FlightControllerOptions o;
  contracts::JsonOptionReader r(doc, "FlightControllerOptions");
  r.read("max_horizontal_m_s", o.max_horizontal_m_s);
  r.read("max_vertical_m_s", o.max_vertical_m_s);
  r.read("max_yaw_rate_deg_s", o.max_yaw_rate_deg_s);
  r.read("takeoff_altitude_m", o.takeoff_altitude_m);
  r.read("takeoff_climb_m_s", o.takeoff_climb_m_s);
  r.read("land_descent_m_s", o.land_descent_m_s);
  r.read("min_altitude_m", o.min_altitude_m);
  r.read("max_tilt_deg", o.max_tilt_deg);
  r.read("position_gain_1_s", o.position_gain_1_s);
  r.read("velocity_gain_1_s", o.velocity_gain_1_s);
  r.read("velocity_integral_gain_1_s2", o.velocity_integral_gain_1_s2);
  r.read("vertical_velocity_gain_1_s", o.vertical_velocity_gain_1_s);
  r.read("attitude_gain_1_s", o.attitude_gain_1_s);
  r.read("yaw_gain_1_s", o.yaw_gain_1_s);
  r.read("rate_gain_1_s", o.rate_gain_1_s);
  r.read("rate_integral_gain_1_s2", o.rate_integral_gain_1_s2);
  r.read("hold_capture_speed_m_s", o.hold_capture_speed_m_s);
  r.finish();
  const std::string owner = "FlightControllerOptions";
  contracts::require(o.max_horizontal_m_s > 0, owner, "max_horizontal_m_s", "must be > 0");
  contracts::require(o.max_vertical_m_s > 0, owner, "max_vertical_m_s", "must be > 0");
  contracts::require(o.max_yaw_rate_deg_s > 0, owner, "max_yaw_rate_deg_s", "must be > 0");
  contracts::require(o.takeoff_altitude_m > 0, owner, "takeoff_altitude_m", "must be > 0");
  contracts::require(o.takeoff_climb_m_s > 0, owner, "takeoff_climb_m_s", "must be > 0");
  contracts::require(o.land_descent_m_s > 0, owner, "land_descent_m_s", "must be > 0");
  contracts::require(o.max_tilt_deg > 0 && o.max_tilt_deg < 60, owner, "max_tilt_deg",
                     "must be in (0, 60)");
  return o;
}

std::string_view to_string(FlightPhase p) {
  switch (p) {
    case FlightPhase::kOff:
      return "OFF";
    case FlightPhase::kTakeoff:
      return "TAKEOFF";
    case FlightPhase::kFlight:
      return "FLIGHT";
    case FlightPhase::kLanding:
      return "LANDING";
  }
  return "?";
}

FlightController::FlightController(VehicleParams vehicle, FlightControllerOptions options)
    : vehicle_(std::move(vehicle)), options_(options) {
  Eigen::Matrix4d a;
  for (int i = 0; i < kRotorCount; ++i) {
    const auto& r = vehicle_.rotor_xy_m[static_cast<std::size_t>(i)];
    a(0, i) = 1.0;
    a(1, i) = r.y();   // roll torque of a +z force at (x, y)
    a(2, i) = -r.x();  // pitch torque
    a(3, i) = vehicle_.yaw_torque_per_thrust_m[static_cast<std::size_t>(i)];
  }
  Eigen::FullPivLU<Eigen::Matrix4d> lu(a);
  if (!lu.isInvertible()) {
    throw std::invalid_argument(
        "FlightController: the rotor layout cannot control thrust, roll, pitch and yaw "
        "independently (singular mixer)");
  }
  mixer_inverse_ = lu.inverse();
}

void FlightController::reset_holds(const VehicleState& state) {
  hold_xy_m_ = state.position_m.head<2>();
  hold_xy_valid_ = true;
  hold_z_m_ = state.position_m.z();
  hold_z_valid_ = true;
  yaw_target_rad_ = yaw_of(state.attitude.toRotationMatrix());
  velocity_integral_m_.setZero();
  rate_integral_rad_.setZero();
}

void FlightController::takeoff(const VehicleState& state) {
  if (phase_ != FlightPhase::kOff) return;
  reset_holds(state);
  rc_target_.setZero();
  phase_ = FlightPhase::kTakeoff;
}

void FlightController::land(const VehicleState& state) {
  if (phase_ != FlightPhase::kTakeoff && phase_ != FlightPhase::kFlight) return;
  (void)state;
  hold_xy_valid_ = false;  // brake, then hold where it stopped
  phase_ = FlightPhase::kLanding;
}

void FlightController::disarm() {
  phase_ = FlightPhase::kOff;
  rc_target_.setZero();
  velocity_integral_m_.setZero();
  rate_integral_rad_.setZero();
}

void FlightController::set_rc(int a, int b, int c, int d) {
  auto unit = [](int v) { return std::clamp(v, -100, 100) / 100.0; };
  rc_target_ = Eigen::Vector4d(unit(b) * options_.max_horizontal_m_s,
                               -unit(a) * options_.max_horizontal_m_s,  // a: right; W y: left
                               unit(c) * options_.max_vertical_m_s,
                               -unit(d) * options_.max_yaw_rate_deg_s * kDegToRad);
}

Eigen::Vector3d FlightController::velocity_target(const VehicleState& state, double yaw_rad,
                                                  double dt_s) {
  const Eigen::Vector3d& p = state.position_m;
  const Eigen::Vector3d& v = state.velocity_m_s;
  const double kp = options_.position_gain_1_s;
  const double capture = options_.hold_capture_speed_m_s;
  const bool flight = phase_ == FlightPhase::kFlight;

  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  // Horizontal: sticks in flight, else brake then hold.
  if (flight && (rc_target_.x() != 0 || rc_target_.y() != 0)) {
    hold_xy_valid_ = false;
    const Eigen::Rotation2Dd yaw(yaw_rad);
    target.head<2>() = yaw * rc_target_.head<2>();
  } else if (!hold_xy_valid_) {
    if (v.head<2>().norm() < capture) {
      hold_xy_m_ = p.head<2>();
      hold_xy_valid_ = true;
    }
  }
  if (hold_xy_valid_) {
    target.head<2>() = clamp_norm(kp * (hold_xy_m_ - p.head<2>()), options_.max_horizontal_m_s);
  }

  // Vertical.
  const double vmax = options_.max_vertical_m_s;
  switch (phase_) {
    case FlightPhase::kTakeoff:
      target.z() =
          std::clamp(kp * (options_.takeoff_altitude_m - p.z()), -vmax, options_.takeoff_climb_m_s);
      if (std::abs(p.z() - options_.takeoff_altitude_m) < 0.05 && std::abs(v.z()) < 0.15) {
        phase_ = FlightPhase::kFlight;
        hold_z_m_ = options_.takeoff_altitude_m;
        hold_z_valid_ = true;
      }
      break;
    case FlightPhase::kLanding:
      target.z() = -options_.land_descent_m_s;
      break;
    case FlightPhase::kFlight:
      if (rc_target_.z() != 0) {
        hold_z_valid_ = false;
        target.z() = rc_target_.z();
      } else if (!hold_z_valid_ && std::abs(v.z()) < capture) {
        hold_z_m_ = p.z();
        hold_z_valid_ = true;
      }
      if (hold_z_valid_) {
        hold_z_m_ = std::max(hold_z_m_, options_.min_altitude_m);
        target.z() = std::clamp(kp * (hold_z_m_ - p.z()), -vmax, vmax);
      }
      target.z() = std::max(target.z(), std::min(vmax, kp * (options_.min_altitude_m - p.z())));
      break;
    case FlightPhase::kOff:
      break;
  }

  // Yaw: the target turns at the stick rate, never more than 0.5 rad ahead of the drone.
  if (flight && rc_target_.w() != 0) {
    const double ahead = wrap_pi(yaw_target_rad_ + rc_target_.w() * dt_s - yaw_rad);
    yaw_target_rad_ = yaw_rad + std::clamp(ahead, -0.5, 0.5);
  }
  return target;
}

MotorThrusts FlightController::update(const VehicleState& state, double dt_s) {
  if (phase_ == FlightPhase::kOff) return MotorThrusts{};
  const Eigen::Matrix3d r = state.attitude.toRotationMatrix();
  const double yaw = yaw_of(r);
  const double g = vehicle_.gravity_m_s2;

  // Velocity loop (PI), in W.
  const Eigen::Vector3d error = velocity_target(state, yaw, dt_s) - state.velocity_m_s;
  const double ki = options_.velocity_integral_gain_1_s2;
  // The integrator sees the error clipped to +-0.2 m/s: a stick step winds it up only a
  // little (small overshoot), while a steady push (wind) is still integrated away. The climb
  // and the descent are velocity profiles with their own transients: z holds there.
  for (int i = 0; i < 3; ++i) {
    if (i == 2 && phase_ != FlightPhase::kFlight) continue;
    velocity_integral_m_(i) +=
        std::clamp(error(i), -kIntegratorInputM_S, kIntegratorInputM_S) * dt_s;
  }
  if (ki > 0) {
    const double limit = 2.0 / ki;  // the integral term stays within 2 m/s^2 per axis
    velocity_integral_m_ = velocity_integral_m_.cwiseMax(-limit).cwiseMin(limit);
  }
  Eigen::Vector3d accel;
  accel.head<2>() = options_.velocity_gain_1_s * error.head<2>();
  accel.z() = options_.vertical_velocity_gain_1_s * error.z();
  accel += ki * velocity_integral_m_;
  accel.z() = std::clamp(accel.z(), -0.7 * g, 1.0 * g);

  // Thrust vector with the tilt limited.
  Eigen::Vector3d force = vehicle_.mass_kg * (accel + Eigen::Vector3d(0, 0, g));
  const double max_xy = force.z() * std::tan(options_.max_tilt_deg * kDegToRad);
  force.head<2>() = clamp_norm(force.head<2>(), max_xy);
  const Eigen::Vector3d b3 = force.normalized();
  const double thrust =
      std::clamp(force.dot(r.col(2)), 0.0, kRotorCount * vehicle_.max_motor_thrust_n);

  // Desired attitude from the thrust direction and the yaw target.
  const Eigen::Vector3d c1(std::cos(yaw_target_rad_), std::sin(yaw_target_rad_), 0);
  const Eigen::Vector3d b2 = b3.cross(c1).normalized();
  Eigen::Matrix3d rd;
  rd.col(0) = b2.cross(b3);
  rd.col(1) = b2;
  rd.col(2) = b3;
  const Eigen::Matrix3d e = 0.5 * (rd.transpose() * r - r.transpose() * rd);
  const Eigen::Vector3d attitude_error(e(2, 1), e(0, 2), e(1, 0));

  Eigen::Vector3d rate_target(-options_.attitude_gain_1_s * attitude_error.x(),
                              -options_.attitude_gain_1_s * attitude_error.y(),
                              -options_.yaw_gain_1_s * attitude_error.z());
  if (phase_ == FlightPhase::kFlight) rate_target.z() += rc_target_.w();

  // Rate loop: PI (the I learns steady torques: a weak motor, an off-centre mass) with
  // gyroscopic feed-forward.
  const Eigen::Vector3d& w = state.body_rate_rad_s;
  const Eigen::Vector3d j = vehicle_.inertia_kg_m2;
  const Eigen::Vector3d rate_error = rate_target - w;
  const double kri = options_.rate_integral_gain_1_s2;
  if (kri > 0) {
    const double limit = kRateIntegralLimitRad_S2 / kri;
    rate_integral_rad_ = (rate_integral_rad_ + rate_error * dt_s).cwiseMax(-limit).cwiseMin(limit);
  }
  const Eigen::Vector3d alpha = options_.rate_gain_1_s * rate_error + kri * rate_integral_rad_;
  const Eigen::Vector3d torque = j.cwiseProduct(alpha) + w.cross(j.cwiseProduct(w));
  return mix(thrust, torque);
}

MotorThrusts FlightController::mix(double thrust_n, const Eigen::Vector3d& torque_n_m) const {
  const Eigen::Vector4d base =
      mixer_inverse_ * Eigen::Vector4d(thrust_n, torque_n_m.x(), torque_n_m.y(), 0.0);
  const Eigen::Vector4d yaw = mixer_inverse_ * Eigen::Vector4d(0, 0, 0, torque_n_m.z());
  const double max = vehicle_.max_motor_thrust_n;
  // The largest share of the yaw torque that keeps every motor within [0, max].
  double scale = 1.0;
  for (int i = 0; i < kRotorCount; ++i) {
    if (base(i) < 0 || base(i) > max) {
      scale = 0;
      break;
    }
    if (yaw(i) > 0) scale = std::min(scale, (max - base(i)) / yaw(i));
    if (yaw(i) < 0) scale = std::min(scale, -base(i) / yaw(i));
  }
  MotorThrusts out{};
  for (int i = 0; i < kRotorCount; ++i) {
    out[static_cast<std::size_t>(i)] = std::clamp(base(i) + scale * yaw(i), 0.0, max);
  }
  return out;
}

}  // namespace gbdcs::sim
