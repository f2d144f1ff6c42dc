// FlightController alone: mixer, rc semantics and closed-loop behaviour on a plain rigid body
// integrated here (no MuJoCo), with the same first-order motor lag as the model.
#include "gbdcs/sim/flight_controller.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

namespace gbdcs::sim {
namespace {

constexpr double kDt = 0.002;

// A rigid quadrotor: thrust along body z at the rotor hubs, yaw reaction torques, a floor at 0.
struct RigidBody {
  VehicleParams p = VehicleParams::tello();
  VehicleState s;
  MotorThrusts motor{};

  void step(const MotorThrusts& command) {
    double thrust = 0;
    Eigen::Vector3d torque = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < motor.size(); ++i) {
      motor[i] += (command[i] - motor[i]) * kDt / p.motor_time_constant_s;
      thrust += motor[i];
      torque += Eigen::Vector3d(p.rotor_xy_m[i].y() * motor[i], -p.rotor_xy_m[i].x() * motor[i],
                                p.yaw_torque_per_thrust_m[i] * motor[i]);
    }
    const Eigen::Matrix3d r = s.attitude.toRotationMatrix();
    Eigen::Vector3d accel = r.col(2) * thrust / p.mass_kg - Eigen::Vector3d(0, 0, p.gravity_m_s2);
    const Eigen::Vector3d& w = s.body_rate_rad_s;
    const Eigen::Vector3d j = p.inertia_kg_m2;
    const Eigen::Vector3d wdot = (torque - w.cross(j.cwiseProduct(w))).cwiseQuotient(j);
    s.velocity_m_s += accel * kDt;
    s.position_m += s.velocity_m_s * kDt;
    s.body_rate_rad_s += wdot * kDt;
    const Eigen::Vector3d dtheta = s.body_rate_rad_s * kDt;
    if (dtheta.norm() > 0) {
      s.attitude =
          (s.attitude * Eigen::Quaterniond(Eigen::AngleAxisd(dtheta.norm(), dtheta.normalized())))
              .normalized();
    }
    if (s.position_m.z() < 0) {  // the floor
      s.position_m.z() = 0;
      s.velocity_m_s.setZero();
      s.body_rate_rad_s.setZero();
    }
  }
};

double yaw_of(const VehicleState& s) {
  const Eigen::Matrix3d r = s.attitude.toRotationMatrix();
  return std::atan2(r(1, 0), r(0, 0));
}

void run(FlightController& fc, RigidBody& body, double seconds) {
  for (int i = 0; i < static_cast<int>(std::lround(seconds / kDt)); ++i) {
    body.step(fc.update(body.s, kDt));
  }
}

TEST(FlightControllerMixer, HoverThrustIsSharedEqually) {
  const VehicleParams p = VehicleParams::tello();
  FlightController fc(p, {});
  const MotorThrusts f = fc.mix(p.mass_kg * p.gravity_m_s2, Eigen::Vector3d::Zero());
  for (const double fi : f) EXPECT_NEAR(fi, p.mass_kg * p.gravity_m_s2 / 4, 1e-12);
}

TEST(FlightControllerMixer, TorquesGoToTheRightMotors) {
  FlightController fc(VehicleParams::tello(), {});
  // +x torque lifts the left side (y left): rotors 0 (front-left) and 3 (rear-left) push more.
  MotorThrusts f = fc.mix(0.8, Eigen::Vector3d(1e-3, 0, 0));
  EXPECT_GT(f[0], f[1]);
  EXPECT_GT(f[3], f[2]);
  // +y torque pitches the nose down: the rear rotors push more.
  f = fc.mix(0.8, Eigen::Vector3d(0, 1e-3, 0));
  EXPECT_GT(f[2], f[1]);
  EXPECT_GT(f[3], f[0]);
  // +z (counter-clockwise) torque: rotors whose reaction torque is +z (1 and 3) push more.
  f = fc.mix(0.8, Eigen::Vector3d(0, 0, 1e-4));
  EXPECT_GT(f[1], f[0]);
  EXPECT_GT(f[3], f[2]);
}

TEST(FlightControllerMixer, YawGivesWayWhenAMotorSaturates) {
  const VehicleParams p = VehicleParams::tello();
  FlightController fc(p, {});
  const double thrust = p.mass_kg * p.gravity_m_s2;
  const MotorThrusts f = fc.mix(thrust, Eigen::Vector3d(0, 0, 1.0));  // absurd yaw demand
  double sum = 0;
  for (const double fi : f) {
    EXPECT_GE(fi, 0.0);
    EXPECT_LE(fi, p.max_motor_thrust_n);
    sum += fi;
  }
  EXPECT_NEAR(sum, thrust, 1e-9);  // collective kept: it still holds its altitude
}

TEST(FlightControllerRc, TelloSticksMapToBodyTargets) {
  FlightControllerOptions o;
  o.max_horizontal_m_s = 2.0;
  FlightController fc(VehicleParams::tello(), o);
  fc.set_rc(50, 25, -100, 100);
  const Eigen::Vector4d t = fc.rc_target();
  EXPECT_DOUBLE_EQ(t(0), 0.5);                              // b forward
  EXPECT_DOUBLE_EQ(t(1), -1.0);                             // a right = -y (y is left)
  EXPECT_DOUBLE_EQ(t(2), -0.8);                             // c down
  EXPECT_NEAR(t(3), -100 * std::numbers::pi / 180, 1e-12);  // d clockwise = -z rate
  fc.set_rc(500, 0, 0, 0);                                  // clamped
  EXPECT_DOUBLE_EQ(fc.rc_target()(1), -2.0);
}

TEST(FlightControllerLoop, OffMeansNoThrust) {
  FlightController fc(VehicleParams::tello(), {});
  RigidBody body;
  for (const double f : fc.update(body.s, kDt)) EXPECT_EQ(f, 0.0);
}

TEST(FlightControllerLoop, TakesOffToOneMetreAndHolds) {
  FlightController fc(VehicleParams::tello(), {});
  RigidBody body;
  fc.takeoff(body.s);
  EXPECT_EQ(fc.phase(), FlightPhase::kTakeoff);
  run(fc, body, 5.0);
  EXPECT_EQ(fc.phase(), FlightPhase::kFlight);
  EXPECT_NEAR(body.s.position_m.z(), 1.0, 0.05);
  run(fc, body, 5.0);
  EXPECT_NEAR(body.s.position_m.z(), 1.0, 0.02);
  EXPECT_NEAR(body.s.position_m.head<2>().norm(), 0.0, 0.02);
}

TEST(FlightControllerLoop, ForwardStickTracksTheVelocityInTheHeadingFrame) {
  FlightController fc(VehicleParams::tello(), {});
  RigidBody body;
  // Start turned 90 degrees counter-clockwise: forward is world +y.
  body.s.attitude =
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()));
  fc.takeoff(body.s);
  run(fc, body, 5.0);
  fc.set_rc(0, 100, 0, 0);
  run(fc, body, 3.0);
  EXPECT_NEAR(body.s.velocity_m_s.y(), 1.0, 0.05);
  EXPECT_NEAR(body.s.velocity_m_s.x(), 0.0, 0.05);
  EXPECT_NEAR(body.s.position_m.z(), 1.0, 0.05);
  fc.set_rc(0, 0, 0, 0);
  run(fc, body, 3.0);
  EXPECT_LT(body.s.velocity_m_s.norm(), 0.02);  // braked and holding
}

TEST(FlightControllerLoop, YawStickTurnsClockwiseAtTheConfiguredRate) {
  FlightController fc(VehicleParams::tello(), {});
  RigidBody body;
  fc.takeoff(body.s);
  run(fc, body, 5.0);
  const double before = yaw_of(body.s);
  fc.set_rc(0, 0, 0, 50);  // 50 deg/s clockwise
  run(fc, body, 1.0);
  const double turned_deg = -(yaw_of(body.s) - before) * 180 / std::numbers::pi;
  EXPECT_NEAR(turned_deg, 50.0, 7.5);
}

TEST(FlightControllerLoop, LandDescendsAtTheConfiguredRate) {
  FlightController fc(VehicleParams::tello(), {});
  RigidBody body;
  fc.takeoff(body.s);
  run(fc, body, 5.0);
  fc.land(body.s);
  EXPECT_EQ(fc.phase(), FlightPhase::kLanding);
  run(fc, body, 1.0);
  EXPECT_NEAR(body.s.velocity_m_s.z(), -0.5, 0.05);
  fc.disarm();
  EXPECT_EQ(fc.phase(), FlightPhase::kOff);
  for (const double f : fc.update(body.s, kDt)) EXPECT_EQ(f, 0.0);
}

TEST(FlightControllerLoop, DownStickStopsAtTheMinimumAltitude) {
  FlightController fc(VehicleParams::tello(), {});
  RigidBody body;
  fc.takeoff(body.s);
  run(fc, body, 5.0);
  fc.set_rc(0, 0, -100, 0);
  run(fc, body, 4.0);
  EXPECT_NEAR(body.s.position_m.z(), fc.options().min_altitude_m, 0.05);
}

TEST(FlightControllerOptions, JsonIsStrict) {
  const auto o = FlightControllerOptions::from_json(
      nlohmann::json{{"max_horizontal_m_s", 2.5}, {"max_yaw_rate_deg_s", 90}});
  EXPECT_DOUBLE_EQ(o.max_horizontal_m_s, 2.5);
  EXPECT_DOUBLE_EQ(o.max_yaw_rate_deg_s, 90);
  EXPECT_DOUBLE_EQ(o.max_vertical_m_s, 0.8);
  try {
    FlightControllerOptions::from_json(nlohmann::json{{"max_speed", 1}});
    FAIL() << "unknown key accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'max_speed' is not a known option"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(FlightControllerOptions::from_json(nlohmann::json{{"max_tilt_deg", 80}}),
               std::invalid_argument);
}

}  // namespace
}  // namespace gbdcs::sim
