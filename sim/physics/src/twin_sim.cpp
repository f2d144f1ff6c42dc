#include "gbdcs/sim/twin_sim.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "counter_rng.hpp"

namespace gbdcs::sim {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kCollisionGapS = 0.2;   // contacts closer than this are one collision
constexpr double kSupportNormalZ = 0.7;  // contact normal this close to vertical: support

CommandResult ok() {
  return {};
}
CommandResult refuse(std::string error) {
  return {false, std::move(error)};
}

double heading_from_yaw(double yaw_rad) {
  double heading = std::fmod(-yaw_rad * kRadToDeg, 360.0);
  if (heading < 0) heading += 360.0;
  return heading >= 360.0 ? 0.0 : heading + 0.0;  // + 0.0: never -0
}

}  // namespace

std::string_view to_string(TwinMode m) {
  switch (m) {
    case TwinMode::kLanded:
      return "LANDED";
    case TwinMode::kTakingOff:
      return "TAKING_OFF";
    case TwinMode::kFlying:
      return "FLYING";
    case TwinMode::kLanding:
      return "LANDING";
    case TwinMode::kFalling:
      return "FALLING";
    case TwinMode::kCrashed:
      return "CRASHED";
  }
  return "?";
}

TwinSim::TwinSim(std::shared_ptr<const TwinModel> model, TwinOptions options, std::uint32_t seed)
    : model_(model ? std::move(model) : throw std::invalid_argument("TwinSim: null model")),
      options_(std::move(options)),
      seed_(seed),
      controller_(model_->vehicle(), options_.controller),
      battery_(options_.battery) {
  if (!(options_.crash_speed_m_s > 0) || !(options_.auto_land_after_s > 0)) {
    throw std::invalid_argument("TwinSim: crash_speed_m_s and auto_land_after_s must be > 0");
  }
  data_ = mj_makeData(model_->mj_model());
  if (data_ == nullptr) throw std::runtime_error("TwinSim: mj_makeData failed");
  jump_applied_.assign(options_.faults.faults().size(), false);
  mj_forward(model_->mj_model(), data_);  // kinematics and contacts of the initial state
}

TwinSim::~TwinSim() {
  mj_deleteData(data_);
}

const mjModel* TwinSim::model() const {
  return model_->mj_model();
}

double TwinSim::time_s() const {
  return static_cast<double>(steps_) * model_->timestep_s();
}

void TwinSim::step_to(double t_s) {
  const double dt = model_->timestep_s();
  const auto target = static_cast<std::int64_t>(std::floor(t_s / dt + 1e-9));
  while (steps_ < target) step_once();
}

VehicleState TwinSim::vehicle_state() const {
  const mjtNum* q = data_->qpos + model_->free_joint_qpos_address();
  const mjtNum* v = data_->qvel + model_->free_joint_dof_address();
  VehicleState s;
  s.position_m = Eigen::Vector3d(q[0], q[1], q[2] - model_->rest_height_m());
  s.attitude = Eigen::Quaterniond(q[3], q[4], q[5], q[6]).normalized();
  s.velocity_m_s = Eigen::Vector3d(v[0], v[1], v[2]);     // free joint: world linear velocity
  s.body_rate_rad_s = Eigen::Vector3d(v[3], v[4], v[5]);  // free joint: body angular velocity
  return s;
}

void TwinSim::apply_faults(double t_s) {
  const auto& faults = options_.faults.faults();
  for (std::size_t i = 0; i < faults.size(); ++i) {
    if (faults[i].type == FaultType::kBatteryJump && !jump_applied_[i] &&
        t_s >= faults[i].start_s) {
      battery_.set_pct(faults[i].battery_pct);
      jump_applied_[i] = true;
    }
  }
  const auto wind = options_.faults.wind_force_n(t_s);
  mjtNum* xfrc = data_->xfrc_applied + 6 * model_->drone_body_id();
  xfrc[0] = wind[0];
  xfrc[1] = -wind[1];  // contracts' y right -> MuJoCo's y left
  xfrc[2] = wind[2];
}

void TwinSim::cut_motors() {
  controller_.disarm();
  for (const int motor : model_->motor_actuator_ids()) data_->ctrl[motor] = 0;
  commanded_n_ = {};
}

void TwinSim::update_mode_before_step() {
  const bool airborne = mode_ == TwinMode::kTakingOff || mode_ == TwinMode::kFlying;
  if (!airborne) return;
  const bool idle = time_s() - last_command_s_ >= options_.auto_land_after_s;
  if (idle || battery_.empty()) {
    controller_.land(vehicle_state());
    mode_ = TwinMode::kLanding;
  }
}

void TwinSim::step_once() {
  const mjModel* m = model_->mj_model();
  const double dt = m->opt.timestep;
  const double t = time_s();
  apply_faults(t);
  update_mode_before_step();

  const MotorThrusts thrust = controller_.update(vehicle_state(), dt);
  if (mode_ == TwinMode::kTakingOff && controller_.phase() == FlightPhase::kFlight) {
    mode_ = TwinMode::kFlying;
  }
  commanded_n_ = thrust;
  const auto& motors = model_->motor_actuator_ids();
  for (std::size_t i = 0; i < motors.size(); ++i) {
    const double factor = options_.faults.motor_factor(static_cast<int>(i), t);
    data_->ctrl[motors[i]] =
        std::clamp(thrust[i] * factor, 0.0, model_->vehicle().max_motor_thrust_n);
  }

  const double downward_m_s = -data_->qvel[model_->free_joint_dof_address() + 2];
  mj_step(m, data_);
  ++steps_;
  data_->time = time_s();  // no drift from summing the timestep

  scan_contacts(downward_m_s);
  MotorThrusts actual{};
  for (std::size_t i = 0; i < motors.size(); ++i) actual[i] = data_->actuator_force[motors[i]];
  battery_.step(dt, actual);
}

void TwinSim::scan_contacts(double downward_speed_m_s) {
  bool support = false;
  bool obstacle = false;
  for (int i = 0; i < data_->ncon; ++i) {
    const mjContact& c = data_->contact[i];
    const bool drone1 = model_->is_drone_geom(c.geom1);
    const bool drone2 = model_->is_drone_geom(c.geom2);
    if (drone1 == drone2) continue;
    const int other = drone1 ? c.geom2 : c.geom1;
    // frame[0..2] is the normal, pointing from geom1 to geom2.
    const double up_on_drone = drone2 ? c.frame[2] : -c.frame[2];
    const bool supports = up_on_drone > kSupportNormalZ;
    support = support || supports;
    if (other != model_->floor_geom_id() && !supports) obstacle = true;
  }

  const double t = time_s();
  if (obstacle) {
    if (t - last_obstacle_contact_s_ > kCollisionGapS) ++collisions_;
    last_obstacle_contact_s_ = t;
  }
  const bool touchdown = support && !supported_;
  supported_ = support;
  if (mode_ == TwinMode::kCrashed) return;
  if (touchdown && downward_speed_m_s > options_.crash_speed_m_s) {
    cut_motors();
    mode_ = TwinMode::kCrashed;
    return;
  }
  if (support && (mode_ == TwinMode::kLanding || mode_ == TwinMode::kFalling)) {
    cut_motors();
    mode_ = TwinMode::kLanded;
  }
}

CommandResult TwinSim::takeoff() {
  last_command_s_ = time_s();
  switch (mode_) {
    case TwinMode::kLanded:
      if (battery_.empty()) return refuse("battery low");
      controller_.takeoff(vehicle_state());
      mode_ = TwinMode::kTakingOff;
      return ok();
    case TwinMode::kTakingOff:
    case TwinMode::kFlying:
      return refuse("already flying");
    case TwinMode::kLanding:
      return refuse("landing");
    case TwinMode::kFalling:
      return refuse("motors stopped");
    case TwinMode::kCrashed:
      return refuse("crashed");
  }
  return refuse("unknown mode");
}

CommandResult TwinSim::land() {
  last_command_s_ = time_s();
  switch (mode_) {
    case TwinMode::kTakingOff:
    case TwinMode::kFlying:
      controller_.land(vehicle_state());
      mode_ = TwinMode::kLanding;
      return ok();
    case TwinMode::kLanding:
      return ok();
    case TwinMode::kLanded:
      return refuse("not flying");
    case TwinMode::kFalling:
      return refuse("motors stopped");
    case TwinMode::kCrashed:
      return refuse("crashed");
  }
  return refuse("unknown mode");
}

CommandResult TwinSim::emergency() {
  last_command_s_ = time_s();
  if (mode_ == TwinMode::kTakingOff || mode_ == TwinMode::kFlying || mode_ == TwinMode::kLanding) {
    cut_motors();
    mode_ = supported_ ? TwinMode::kLanded : TwinMode::kFalling;
  }
  return ok();  // a Tello answers "ok" to emergency whatever its state
}

CommandResult TwinSim::rc(int a, int b, int c, int d) {
  last_command_s_ = time_s();
  for (const int v : {a, b, c, d}) {
    if (v < -100 || v > 100) return refuse("rc values must be within -100...100");
  }
  switch (mode_) {
    case TwinMode::kTakingOff:
    case TwinMode::kFlying:
      controller_.set_rc(a, b, c, d);
      return ok();
    case TwinMode::kLanding:
      return refuse("landing");
    case TwinMode::kLanded:
      return refuse("not flying");
    case TwinMode::kFalling:
      return refuse("motors stopped");
    case TwinMode::kCrashed:
      return refuse("crashed");
  }
  return refuse("unknown mode");
}

void TwinSim::keep_alive() { last_command_s_ = time_s(); }

CommandResult TwinSim::hover() {
  return rc(0, 0, 0, 0);
}

TwinStatus TwinSim::status() const {
  const VehicleState s = vehicle_state();
  const Eigen::Matrix3d r = s.attitude.toRotationMatrix();
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  const double t = time_s();

  // MuJoCo's frame (y left, yaw counter-clockwise) -> the contracts' (y right, clockwise).
  Eigen::Vector3d position(s.position_m.x(), -s.position_m.y(), s.position_m.z());
  Eigen::Vector3d velocity(s.velocity_m_s.x(), -s.velocity_m_s.y(), s.velocity_m_s.z());
  double heading = heading_from_yaw(yaw);

  const SensorNoise noise = options_.faults.sensor_noise(t);
  if (noise.any()) {
    const auto step = static_cast<std::uint64_t>(steps_);
    for (std::uint32_t i = 0; i < 3; ++i) {
      position(i) += noise.position_sigma_m * detail::counter_gaussian(seed_, step, i);
      velocity(i) += noise.velocity_sigma_m_s * detail::counter_gaussian(seed_, step, 3 + i);
    }
    heading += noise.heading_sigma_deg * detail::counter_gaussian(seed_, step, 6);
    heading = std::fmod(std::fmod(heading, 360.0) + 360.0, 360.0);
  }

  TwinStatus out;
  out.time_s = t;
  out.x_m = position.x();
  out.y_m = position.y();
  out.z_m = position.z();
  out.vx_m_s = velocity.x();
  out.vy_m_s = velocity.y();
  out.vz_m_s = velocity.z();
  // Heading frame, clockwise heading h: forward = (cos h, sin h) in (x, y right).
  const double h = heading / kRadToDeg;
  out.body_vx_m_s = std::cos(h) * velocity.x() + std::sin(h) * velocity.y();
  out.body_vy_m_s = -std::sin(h) * velocity.x() + std::cos(h) * velocity.y();
  out.heading_deg = heading;
  out.roll_deg = std::atan2(r(2, 1), r(2, 2)) * kRadToDeg;
  out.pitch_deg = std::asin(std::clamp(r(2, 0), -1.0, 1.0)) * kRadToDeg;
  out.speed_m_s = velocity.norm();
  out.battery_pct = battery_.pct();
  out.voltage_v = battery_.voltage_v();
  out.current_a = battery_.current_a();
  out.mode = mode_;
  out.collisions = collisions_;
  const auto& motors = model_->motor_actuator_ids();
  for (std::size_t i = 0; i < motors.size(); ++i) {
    out.motor_thrust_n[i] = data_->actuator_force[motors[i]];
  }
  out.last_command_age_s = t - last_command_s_;
  return out;
}

void TwinSim::set_faults(FaultSchedule faults) {
  options_.faults = std::move(faults);
  const auto& list = options_.faults.faults();
  jump_applied_.assign(list.size(), false);
  for (std::size_t i = 0; i < list.size(); ++i) {
    jump_applied_[i] = list[i].type == FaultType::kBatteryJump && list[i].start_s < time_s();
  }
}

std::vector<std::string> TwinSim::mujoco_warnings() const {
  std::vector<std::string> out;
  for (int i = 0; i < mjNWARNING; ++i) {
    const mjWarningStat& w = data_->warning[i];
    if (w.number > 0) {
      out.push_back(std::string(mju_warningText(i, w.lastinfo)) + " (" + std::to_string(w.number) +
                    " times)");
    }
  }
  return out;
}

double measure_physics_realtime_factor(std::shared_ptr<const TwinModel> model, double sim_seconds) {
  TwinSim sim(std::move(model), TwinOptions{}, 1);
  const auto start = std::chrono::steady_clock::now();
  sim.takeoff();
  // Out and back along x with a little yaw, a command every 3 s (no auto-land).
  const int pattern[4][4] = {{0, 50, 0, 20}, {0, 0, 0, 0}, {0, -50, 0, -20}, {0, 0, 0, 0}};
  int k = 0;
  for (double t = 5.0; t < sim_seconds; t += 3.0, ++k) {
    sim.step_to(t);
    const auto& p = pattern[k % 4];
    sim.rc(p[0], p[1], p[2], p[3]);
  }
  sim.step_to(sim_seconds);
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return sim.time_s() / std::max(wall_s, 1e-9);
}

}  // namespace gbdcs::sim
