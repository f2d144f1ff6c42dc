// FlightController: a Tello-like cascaded controller. Pure (Eigen only): no MuJoCo, no clock.
//
// Frame W : world, x forward at the start, y LEFT, z up (right-handed; MuJoCo's frame).
//           position z is the altitude above the resting height (0 when landed).
// Frame B : body, x forward, y left, z up; rotors in the x-y plane of B.
// Inputs  : VehicleState each update (W position/velocity, body-to-world attitude, B rates);
//           commands takeoff() / land() / disarm() / set_rc(a, b, c, d).
//           rc uses Tello semantics, each -100...100: a right(+)/left, b forward(+)/back,
//           c up(+)/down, d yaw clockwise seen from above(+).
// Output  : update() -> four motor thrusts in N, each clamped to [0, max_motor_thrust_n].
// Cascade : rc -> body-yaw-frame velocity target (or position hold when all sticks are 0:
//           brake to a stop, then hold where it stopped) -> velocity PI -> acceleration ->
//           thrust vector (tilt limited) -> desired attitude (Lee et al. SO(3) error) ->
//           body-rate PI with gyroscopic feed-forward -> torques -> mixer (yaw gives way
//           first when a motor saturates).
// Phases  : kOff (motors off) -takeoff-> kTakeoff (climb to takeoff_altitude_m, hold x/y)
//           -> kFlight (rc) -land-> kLanding (descend at land_descent_m_s, hold x/y) until the
//           caller sees the touch-down and calls disarm(). rc is stored during take-off and
//           applies once it reaches kFlight.
// Options : FlightControllerOptions below; defaults in the struct, JSON keys = member names.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <nlohmann/json_fwd.hpp>
#include <string_view>

namespace gbdcs::sim {

inline constexpr int kRotorCount = 4;
using MotorThrusts = std::array<double, kRotorCount>;  // N, rotor order of the model

// The airframe as the controller needs it. TwinModel fills it from the MJCF so the mixer
// always matches the model; tello() is the same airframe for tests without MuJoCo.
struct VehicleParams {
  double mass_kg = 0.08;
  Eigen::Vector3d inertia_kg_m2{6.82e-5, 7.52e-5, 1.211e-4};  // principal, about B axes
  double gravity_m_s2 = 9.81;
  std::array<Eigen::Vector2d, kRotorCount> rotor_xy_m{};  // hub positions in B
  // Reaction torque about B z per newton of thrust (m); sign = direction of the torque.
  std::array<double, kRotorCount> yaw_torque_per_thrust_m{};
  double max_motor_thrust_n = 0.45;
  double motor_time_constant_s = 0.025;

  static VehicleParams tello();  // matches sim/models/quadrotor.xml
};

struct FlightControllerOptions {
  double max_horizontal_m_s = 1.0;  // rc a/b = +-100
  double max_vertical_m_s = 0.8;    // rc c = +-100
  double max_yaw_rate_deg_s = 100;  // rc d = +-100
  double takeoff_altitude_m = 1.0;
  double takeoff_climb_m_s = 0.8;
  double land_descent_m_s = 0.5;
  double min_altitude_m = 0.2;  // in kFlight rc down stops here (Tello keeps off the floor)
  double max_tilt_deg = 25;
  double position_gain_1_s = 1.5;  // m/s of velocity target per m of position error
  double velocity_gain_1_s = 3.5;  // m/s^2 per m/s
  double velocity_integral_gain_1_s2 = 1.5;
  double vertical_velocity_gain_1_s = 5.0;
  double attitude_gain_1_s = 9.0;  // rad/s of rate target per rad of roll/pitch error
  double yaw_gain_1_s = 4.0;
  double rate_gain_1_s = 25.0;            // rad/s^2 per rad/s of rate error
  double rate_integral_gain_1_s2 = 50.0;  // rad/s^2 per rad of integrated rate error
  double hold_capture_speed_m_s = 0.1;    // braking ends and the hold is taken below this

  // Absent keys keep their defaults; unknown keys or wrong types throw std::invalid_argument.
  static FlightControllerOptions from_json(const nlohmann::json& doc);
};

struct VehicleState {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();          // W; z = altitude
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();        // W
  Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity();  // B -> W
  Eigen::Vector3d body_rate_rad_s = Eigen::Vector3d::Zero();     // B
};

enum class FlightPhase { kOff, kTakeoff, kFlight, kLanding };
std::string_view to_string(FlightPhase p);

class FlightController {
 public:
  FlightController(VehicleParams vehicle, FlightControllerOptions options);

  void takeoff(const VehicleState& state);  // from kOff; resets the integrators
  void land(const VehicleState& state);     // from kTakeoff or kFlight
  void disarm();                            // any phase -> kOff, motors to 0 at once
  // Each -100...100 (the caller validates; values are clamped here).
  void set_rc(int a, int b, int c, int d);

  MotorThrusts update(const VehicleState& state, double dt_s);

  FlightPhase phase() const { return phase_; }
  const VehicleParams& vehicle() const { return vehicle_; }
  const FlightControllerOptions& options() const { return options_; }

  // Body-yaw-frame velocity target from the sticks: x forward, y left, z up (m/s), and the
  // yaw rate about W z (rad/s, counter-clockwise positive).
  Eigen::Vector4d rc_target() const { return rc_target_; }

  // Thrust and torques in B -> motor thrusts; yaw torque gives way first, then clamping.
  MotorThrusts mix(double thrust_n, const Eigen::Vector3d& torque_n_m) const;

 private:
  Eigen::Vector3d velocity_target(const VehicleState& state, double yaw_rad, double dt_s);
  void reset_holds(const VehicleState& state);

  VehicleParams vehicle_;
  FlightControllerOptions options_;
  Eigen::Matrix4d mixer_inverse_;  // [T, tau_x, tau_y, tau_z] -> thrusts
  FlightPhase phase_ = FlightPhase::kOff;
  Eigen::Vector4d rc_target_ = Eigen::Vector4d::Zero();
  bool hold_xy_valid_ = false;
  bool hold_z_valid_ = false;
  Eigen::Vector2d hold_xy_m_ = Eigen::Vector2d::Zero();
  double hold_z_m_ = 0;
  double yaw_target_rad_ = 0;
  Eigen::Vector3d velocity_integral_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d rate_integral_rad_ = Eigen::Vector3d::Zero();
};

}  // namespace gbdcs::sim
