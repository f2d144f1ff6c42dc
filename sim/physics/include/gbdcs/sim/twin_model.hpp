// TwinModel: the immutable half of the twin (MuJoCo's mjModel), loaded once from MJCF and
// shared (std::shared_ptr<const TwinModel>) by any number of TwinSim states and renderers.
//
// Input   : an MJCF path; default_model_path() is sim/models/quadrotor.xml of the source tree
//           (compiled in; the GBDCS_TWIN_MODEL environment variable overrides the default).
// Needs   : body "drone" (with a free joint), geom "floor", sites "rotor0".."rotor3" on the
//           drone, site actuators "motor0".."motor3" (gear z 1, gear yaw = reaction torque
//           per N), cameras "chase" and "onboard".
// Errors  : an unreadable or malformed file -> std::runtime_error
//           "TwinModel: cannot load '<path>': <MuJoCo's message>"; a missing name ->
//           std::runtime_error naming the file and the element.
// MuJoCo  : the first TwinModel installs process-wide MuJoCo handlers: warnings go to stderr
//           ("MuJoCo warning: ..."), errors throw std::runtime_error ("MuJoCo error: ...")
//           instead of exiting the process. Per-state warning counts: TwinSim::mujoco_warnings.
// Threads : immutable after construction; safe to share between threads.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <string>

#include "gbdcs/sim/flight_controller.hpp"

namespace gbdcs::sim {

class TwinModel {
 public:
  static std::string default_model_path();

  explicit TwinModel(const std::string& mjcf_path = default_model_path());
  ~TwinModel();
  TwinModel(const TwinModel&) = delete;
  TwinModel& operator=(const TwinModel&) = delete;

  const mjModel* mj_model() const { return model_; }
  const std::string& path() const { return path_; }

  int drone_body_id() const { return drone_body_; }
  int free_joint_qpos_address() const { return qpos_adr_; }  // x y z qw qx qy qz
  int free_joint_dof_address() const { return dof_adr_; }    // vx vy vz (world) wx wy wz (body)
  int floor_geom_id() const { return floor_geom_; }
  const std::array<int, kRotorCount>& rotor_site_ids() const { return rotor_sites_; }
  const std::array<int, kRotorCount>& motor_actuator_ids() const { return motors_; }
  int chase_camera_id() const { return chase_camera_; }
  int onboard_camera_id() const { return onboard_camera_; }
  bool is_drone_geom(int geom_id) const;

  // The airframe read from the model: mass, inertia, rotor layout, yaw coefficients,
  // thrust limit, motor time constant, gravity.
  const VehicleParams& vehicle() const { return vehicle_; }
  // Height of the drone's body origin when it rests on the floor (its initial qpos z): the
  // zero of TwinStatus::z_m.
  double rest_height_m() const { return rest_height_m_; }
  double timestep_s() const { return model_->opt.timestep; }

 private:
  int require_id(int type, const char* name, const char* what) const;

  std::string path_;
  mjModel* model_ = nullptr;
  int drone_body_ = -1;
  int qpos_adr_ = -1;
  int dof_adr_ = -1;
  int floor_geom_ = -1;
  std::array<int, kRotorCount> rotor_sites_{};
  std::array<int, kRotorCount> motors_{};
  int chase_camera_ = -1;
  int onboard_camera_ = -1;
  VehicleParams vehicle_;
  double rest_height_m_ = 0;
};

}  // namespace gbdcs::sim
