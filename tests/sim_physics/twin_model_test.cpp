#include "gbdcs/sim/twin_model.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace gbdcs::sim {
namespace {

using ::testing::HasSubstr;

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

std::string load_error(const std::string& path) {
  try {
    TwinModel model(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(TwinModel, LoadsTheTelloClassQuadrotor) {
  const TwinModel model;
  EXPECT_EQ(model.path(), TwinModel::default_model_path());
  const VehicleParams& v = model.vehicle();
  EXPECT_NEAR(v.mass_kg, 0.08, 1e-12);
  EXPECT_NEAR(v.inertia_kg_m2.z(), 1.211e-4, 1e-12);
  EXPECT_NEAR(v.gravity_m_s2, 9.81, 1e-12);
  EXPECT_NEAR(v.max_motor_thrust_n, 0.45, 1e-12);
  EXPECT_NEAR(v.motor_time_constant_s, 0.025, 1e-12);
  const VehicleParams tello = VehicleParams::tello();
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_TRUE(v.rotor_xy_m[i].isApprox(tello.rotor_xy_m[i])) << "rotor " << i;
    EXPECT_EQ(v.yaw_torque_per_thrust_m[i], tello.yaw_torque_per_thrust_m[i]) << "rotor " << i;
  }
  // Diagonal pairs spin the same way.
  EXPECT_EQ(v.yaw_torque_per_thrust_m[0], v.yaw_torque_per_thrust_m[2]);
  EXPECT_EQ(v.yaw_torque_per_thrust_m[1], v.yaw_torque_per_thrust_m[3]);
  EXPECT_EQ(v.yaw_torque_per_thrust_m[0], -v.yaw_torque_per_thrust_m[1]);
  EXPECT_NEAR(model.rest_height_m(), 0.0205, 1e-12);
  EXPECT_GE(model.chase_camera_id(), 0);
  EXPECT_GE(model.onboard_camera_id(), 0);
  EXPECT_GE(model.timestep_s(), 0.002);
  EXPECT_LE(model.timestep_s(), 0.005);
  EXPECT_FALSE(model.is_drone_geom(model.floor_geom_id()));
}

TEST(TwinModel, MalformedFileIsAClearError) {
  const std::string path = write_temp("gbdcs_broken.xml", "<mujoco><worldbody><body></mujoco>");
  const std::string error = load_error(path);
  EXPECT_THAT(error, HasSubstr("TwinModel: cannot load '" + path + "': "));
  EXPECT_THAT(error, HasSubstr("XML"));  // MuJoCo's own message follows
  std::remove(path.c_str());
}

TEST(TwinModel, MissingFileIsAClearError) {
  EXPECT_THAT(load_error("/nonexistent/quadrotor.xml"),
              HasSubstr("TwinModel: cannot load '/nonexistent/quadrotor.xml'"));
}

TEST(TwinModel, MissingElementIsNamed) {
  std::ifstream in(TwinModel::default_model_path());
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  xml.replace(xml.find("name=\"motor3\""), 13, "name=\"motorX\"");
  const std::string path = write_temp("gbdcs_no_motor3.xml", xml);
  EXPECT_THAT(load_error(path), HasSubstr("has no actuator named 'motor3'"));
  std::remove(path.c_str());
}

}  // namespace
}  // namespace gbdcs::sim
