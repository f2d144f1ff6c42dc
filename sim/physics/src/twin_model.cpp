#include "gbdcs/sim/twin_model.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <stdexcept>

#ifndef GBDCS_TWIN_MODEL_PATH
#error "GBDCS_TWIN_MODEL_PATH must be defined by the build (sim/physics/CMakeLists.txt)"
#endif

namespace gbdcs::sim {
namespace {

void on_mujoco_warning(const char* message) {
  std::fprintf(stderr, "MuJoCo warning: %s\n", message);
}

// MuJoCo's default error handler exits the process; a twin must not take its host down.
[[noreturn]] void on_mujoco_error(const char* message) {
  throw std::runtime_error(std::string("MuJoCo error: ") + message);
}

void install_mujoco_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_warning = on_mujoco_warning;
    mju_user_error = on_mujoco_error;
  });
}

bool near(double a, double b) {
  return std::abs(a - b) < 1e-9;
}

}  // namespace

std::string TwinModel::default_model_path() {
  if (const char* env = std::getenv("GBDCS_TWIN_MODEL"); env != nullptr && *env != '\0') {
    return env;
  }
  return GBDCS_TWIN_MODEL_PATH;
}

int TwinModel::require_id(int type, const char* name, const char* what) const {
  const int id = mj_name2id(model_, type, name);
  if (id < 0) {
    throw std::runtime_error("TwinModel: '" + path_ + "' has no " + what + " named '" + name + "'");
  }
  return id;
}

TwinModel::TwinModel(const std::string& mjcf_path) : path_(mjcf_path) {
  install_mujoco_handlers();
  char error[1024] = "";
  model_ = mj_loadXML(path_.c_str(), nullptr, error, sizeof error);
  if (model_ == nullptr) {
    throw std::runtime_error("TwinModel: cannot load '" + path_ +
                             "': " + (error[0] != '\0' ? error : "unknown MuJoCo error"));
  }
  if (error[0] != '\0') std::fprintf(stderr, "MuJoCo warning: %s: %s\n", path_.c_str(), error);

  try {
    const mjModel* m = model_;
    auto fail = [&](const std::string& problem) {
      throw std::runtime_error("TwinModel: '" + path_ + "': " + problem);
    };
    drone_body_ = require_id(mjOBJ_BODY, "drone", "body");
    if (m->body_jntnum[drone_body_] != 1 ||
        m->jnt_type[m->body_jntadr[drone_body_]] != mjJNT_FREE) {
      fail("body 'drone' must have exactly one joint, a free joint");
    }
    const int joint = m->body_jntadr[drone_body_];
    qpos_adr_ = m->jnt_qposadr[joint];
    dof_adr_ = m->jnt_dofadr[joint];
    floor_geom_ = require_id(mjOBJ_GEOM, "floor", "geom");
    chase_camera_ = require_id(mjOBJ_CAMERA, "chase", "camera");
    onboard_camera_ = require_id(mjOBJ_CAMERA, "onboard", "camera");

    const mjtNum* ipos = m->body_ipos + 3 * drone_body_;
    const mjtNum* iquat = m->body_iquat + 4 * drone_body_;
    if (!near(ipos[0], 0) || !near(ipos[1], 0) || !near(ipos[2], 0) || !near(iquat[0], 1)) {
      fail(
          "body 'drone' needs its centre of mass at its origin and principal axes along its "
          "axes (<inertial pos=\"0 0 0\" diaginertia=...>)");
    }
    vehicle_.mass_kg = m->body_subtreemass[drone_body_];
    vehicle_.inertia_kg_m2 =
        Eigen::Vector3d(m->body_inertia[3 * drone_body_], m->body_inertia[3 * drone_body_ + 1],
                        m->body_inertia[3 * drone_body_ + 2]);
    vehicle_.gravity_m_s2 = -m->opt.gravity[2];

    for (int i = 0; i < kRotorCount; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const std::string site_name = "rotor" + std::to_string(i);
      const std::string motor_name = "motor" + std::to_string(i);
      const int site = require_id(mjOBJ_SITE, site_name.c_str(), "site");
      const int motor = require_id(mjOBJ_ACTUATOR, motor_name.c_str(), "actuator");
      rotor_sites_[k] = site;
      motors_[k] = motor;
      if (m->site_bodyid[site] != drone_body_ || !near(m->site_quat[4 * site], 1)) {
        fail("site '" + site_name + "' must be on body 'drone', aligned with its axes");
      }
      vehicle_.rotor_xy_m[k] = Eigen::Vector2d(m->site_pos[3 * site], m->site_pos[3 * site + 1]);
      const mjtNum* gear = m->actuator_gear + 6 * motor;
      if (m->actuator_trntype[motor] != mjTRN_SITE || m->actuator_trnid[2 * motor] != site ||
          !near(gear[0], 0) || !near(gear[1], 0) || !near(gear[2], 1) || !near(gear[3], 0) ||
          !near(gear[4], 0) || m->actuator_gaintype[motor] != mjGAIN_FIXED ||
          !near(m->actuator_gainprm[mjNGAIN * motor], 1) ||
          m->actuator_biastype[motor] != mjBIAS_NONE || !m->actuator_ctrllimited[motor]) {
        fail("actuator '" + motor_name + "' must act on site '" + site_name +
             "' with gear=\"0 0 1 0 0 k\", gain 1, no bias and a ctrlrange");
      }
      vehicle_.yaw_torque_per_thrust_m[k] = gear[5];
      vehicle_.max_motor_thrust_n = m->actuator_ctrlrange[2 * motor + 1];
      vehicle_.motor_time_constant_s =
          m->actuator_dyntype[motor] == mjDYN_FILTER ? m->actuator_dynprm[mjNDYN * motor] : 0.0;
    }
    rest_height_m_ = m->qpos0[qpos_adr_ + 2];
  } catch (...) {
    mj_deleteModel(model_);
    throw;
  }
}

TwinModel::~TwinModel() {
  mj_deleteModel(model_);
}

bool TwinModel::is_drone_geom(int geom_id) const {
  return geom_id >= 0 && geom_id < model_->ngeom &&
         model_->body_rootid[model_->geom_bodyid[geom_id]] == drone_body_;
}

}  // namespace gbdcs::sim
