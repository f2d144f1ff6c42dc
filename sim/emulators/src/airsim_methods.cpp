#include <algorithm>
#include <cmath>
#include <numbers>

#include "airsim_emulator_impl.hpp"

// The method table: each AirSim multirotor method the emulator covers, applied to the twin,
// and the MultirotorState it reports (NED). The wire is airsim_emulator.cpp's.

namespace gbdcs::sim {

using namespace airsim_emulator_detail;

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

const msgpack::object* field(const msgpack::object& map, const char* key) {
  if (map.type != msgpack::type::MAP) return nullptr;
  for (std::uint32_t i = 0; i < map.via.map.size; ++i) {
    const auto& kv = map.via.map.ptr[i];
    if (kv.key.type == msgpack::type::STR &&
        std::string_view(kv.key.via.str.ptr, kv.key.via.str.size) == key) {
      return &kv.val;
    }
  }
  return nullptr;
}

void pack_vector(Packer& p, double x, double y, double z) {
  p.pack_map(3);
  p.pack(std::string("x_val"));
  p.pack_float(static_cast<float>(x));
  p.pack(std::string("y_val"));
  p.pack_float(static_cast<float>(y));
  p.pack(std::string("z_val"));
  p.pack_float(static_cast<float>(z));
}

void pack_state(Packer& p, const TwinStatus& s) {
  // NED: x forward at start (north), y right (east), z down; yaw clockwise.
  const double yaw = s.heading_deg * kDegToRad / 2, pitch = s.pitch_deg * kDegToRad / 2,
               roll = s.roll_deg * kDegToRad / 2;
  const double cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch), sp = std::sin(pitch),
               cr = std::cos(roll), sr = std::sin(roll);
  p.pack_map(9);
  p.pack(std::string("collision"));
  p.pack_map(8);
  p.pack(std::string("has_collided"));
  p.pack(s.collisions > 0);
  p.pack(std::string("normal"));
  pack_vector(p, 0, 0, 0);
  p.pack(std::string("impact_point"));
  pack_vector(p, 0, 0, 0);
  p.pack(std::string("position"));
  pack_vector(p, s.x_m, s.y_m, -s.z_m);
  p.pack(std::string("penetration_depth"));
  p.pack_float(0);
  p.pack(std::string("time_stamp"));
  p.pack_uint64(0);
  p.pack(std::string("object_name"));
  p.pack(std::string(""));
  p.pack(std::string("object_id"));
  p.pack_int(-1);
  p.pack(std::string("kinematics_estimated"));
  p.pack_map(6);
  p.pack(std::string("position"));
  pack_vector(p, s.x_m, s.y_m, -s.z_m);
  p.pack(std::string("orientation"));
  p.pack_map(4);
  p.pack(std::string("w_val"));
  p.pack_float(static_cast<float>(cr * cp * cy + sr * sp * sy));
  p.pack(std::string("x_val"));
  p.pack_float(static_cast<float>(sr * cp * cy - cr * sp * sy));
  p.pack(std::string("y_val"));
  p.pack_float(static_cast<float>(cr * sp * cy + sr * cp * sy));
  p.pack(std::string("z_val"));
  p.pack_float(static_cast<float>(cr * cp * sy - sr * sp * cy));
  p.pack(std::string("linear_velocity"));
  pack_vector(p, s.vx_m_s, s.vy_m_s, -s.vz_m_s);
  p.pack(std::string("angular_velocity"));
  pack_vector(p, 0, 0, 0);
  p.pack(std::string("linear_acceleration"));
  pack_vector(p, 0, 0, 0);
  p.pack(std::string("angular_acceleration"));
  pack_vector(p, 0, 0, 0);
  p.pack(std::string("gps_location"));
  p.pack_map(3);  // a fixed home; ~1.1e-5 deg per metre north
  p.pack(std::string("latitude"));
  p.pack_double(47.641468 + s.x_m / 111320.0);
  p.pack(std::string("longitude"));
  p.pack_double(-122.140165 + s.y_m / 75000.0);
  p.pack(std::string("altitude"));
  p.pack_float(static_cast<float>(122.0 + s.z_m));
  p.pack(std::string("timestamp"));
  p.pack_uint64(static_cast<std::uint64_t>(s.time_s * 1e9));
  p.pack(std::string("landed_state"));
  p.pack_int(s.mode == TwinMode::kLanded || s.mode == TwinMode::kCrashed ? 0 : 1);
  p.pack(std::string("rc_data"));
  p.pack_map(2);
  p.pack(std::string("is_initialized"));
  p.pack(false);
  p.pack(std::string("is_valid"));
  p.pack(false);
  p.pack(std::string("ready"));
  p.pack(s.mode != TwinMode::kCrashed);
  p.pack(std::string("ready_message"));
  p.pack(std::string(s.mode == TwinMode::kCrashed ? "crashed" : ""));
  p.pack(std::string("can_arm"));
  p.pack(s.mode != TwinMode::kCrashed);
}

int stick(double value, double maximum) {
  if (maximum <= 0) return 0;
  return static_cast<int>(std::clamp(std::round(100.0 * value / maximum), -100.0, 100.0));
}

}  // namespace

void AirSimEmulator::Impl::check_vehicle(const Args& args, std::uint32_t i) const {
  const auto name = args.string(i);
  if (!name.empty() && name != options.vehicle) {
    throw CallError("Vehicle API for '" + name + "' is not available (the twin's AirSim "
                    "emulator has '" + options.vehicle + "')");
  }
}

void AirSimEmulator::Impl::require_control() const {
  if (!api_control) {
    throw CallError("Vehicle cannot be controlled because EnableApiControl(true) was not "
                    "called");
  }
}

void AirSimEmulator::Impl::cancel_task_locked() {
  if (task) respond_bool(task->session, task->msgid, false);
  task.reset();
}

void AirSimEmulator::Impl::call_locked(TwinSim& sim, const std::shared_ptr<Session>& s, std::uint32_t id,
                 const std::string& m, const Args& args) {
  const double t = sim.time_s();
  if (m == "ping") {
    args.expect(0);
    return respond_bool(s, id, true);
  }
  if (m == "getServerVersion" || m == "getMinRequiredClientVersion") {
    args.expect(0);
    return respond(s, id, nullptr, [](Packer& p) { p.pack_int(1); });
  }
  if (m == "getMultirotorState") {
    args.expect(1);
    check_vehicle(args, 0);
    const auto status = sim.status();
    return respond(s, id, nullptr, [&](Packer& p) { pack_state(p, status); });
  }
  sim.keep_alive();
  if (m == "enableApiControl") {
    args.expect(2);
    check_vehicle(args, 1);
    api_control = args.boolean(0);
    return respond(s, id, nullptr, [](Packer& p) { p.pack_nil(); });
  }
  if (m == "isApiControlEnabled") {
    args.expect(1);
    check_vehicle(args, 0);
    return respond_bool(s, id, api_control);
  }
  if (m == "armDisarm") {
    args.expect(2);
    check_vehicle(args, 1);
    require_control();
    const bool arm = args.boolean(0);
    if (!arm && sim.mode() != TwinMode::kLanded && sim.mode() != TwinMode::kCrashed) {
      cancel_task_locked();
      sim.emergency();  // disarm in the air: motors off
    }
    armed = arm && sim.mode() != TwinMode::kCrashed;
    return respond_bool(s, id, arm == armed);
  }
  if (m == "takeoff") {
    args.expect(2);
    check_vehicle(args, 1);
    require_control();
    const double timeout = args.number(0);
    if (!armed) throw CallError("takeoff: the vehicle is not armed (call armDisarm(true))");
    const auto r = sim.takeoff();
    if (!r.ok) throw CallError("takeoff: " + r.error);
    cancel_task_locked();
    task = Task{s, id, Kind::kTakeoff, t + timeout};
    return;
  }
  if (m == "land") {
    args.expect(2);
    check_vehicle(args, 1);
    require_control();
    const double timeout = args.number(0);
    const auto r = sim.land();
    if (!r.ok) throw CallError("land: " + r.error);
    cancel_task_locked();
    task = Task{s, id, Kind::kLand, t + timeout};
    return;
  }
  if (m == "hover" || m == "cancelLastTask") {
    args.expect(1);
    check_vehicle(args, 0);
    require_control();
    cancel_task_locked();
    const auto mode = sim.mode();
    if (mode == TwinMode::kFlying || mode == TwinMode::kTakingOff) sim.hover();
    if (m == "hover") return respond_bool(s, id, true);
    return respond(s, id, nullptr, [](Packer& p) { p.pack_nil(); });
  }
  if (m == "moveByVelocityBodyFrame") {
    args.expect(7);
    check_vehicle(args, 6);
    require_control();
    const double vx = args.number(0), vy = args.number(1), vz = args.number(2);
    const double duration = args.number(3);
    const double drivetrain = args.number(4);
    const auto& yaw_mode = args.at(5);
    const auto* is_rate = field(yaw_mode, "is_rate");
    const auto* rate = field(yaw_mode, "yaw_or_rate");
    if (!is_rate || is_rate->type != msgpack::type::BOOLEAN || !rate ||
        (rate->type != msgpack::type::FLOAT32 && rate->type != msgpack::type::FLOAT64 &&
         rate->type != msgpack::type::POSITIVE_INTEGER &&
         rate->type != msgpack::type::NEGATIVE_INTEGER)) {
      throw CallError("moveByVelocityBodyFrame: yaw_mode must be a map {is_rate, yaw_or_rate}");
    }
    if (!is_rate->via.boolean) {
      throw CallError("moveByVelocityBodyFrame: yaw_mode.is_rate false (an absolute yaw) is "
                      "not supported by the twin's AirSim emulator");
    }
    if (drivetrain != 0 && drivetrain != 1) {
      throw CallError("moveByVelocityBodyFrame: drivetrain must be 0 or 1");
    }
    if (!(duration >= 0)) throw CallError("moveByVelocityBodyFrame: duration must be >= 0");
    const double yaw_rate = rate->type == msgpack::type::POSITIVE_INTEGER
                                ? static_cast<double>(rate->via.u64)
                                : rate->type == msgpack::type::NEGATIVE_INTEGER
                                      ? static_cast<double>(rate->via.i64)
                                      : rate->via.f64;
    const auto& c = sim.options().controller;
    const auto r = sim.rc(stick(vy, c.max_horizontal_m_s), stick(vx, c.max_horizontal_m_s),
                          stick(-vz, c.max_vertical_m_s), stick(yaw_rate, c.max_yaw_rate_deg_s));
    if (!r.ok) throw CallError("moveByVelocityBodyFrame: " + r.error);
    cancel_task_locked();
    task = Task{s, id, Kind::kMove, t + duration};
    return;
  }
  throw CallError("rpclib: server could not find function '" + m + "' with argument count " +
                  std::to_string(args.size()) + ".");
}

void AirSimEmulator::Impl::on_step(TwinSim& sim, double t) {
  std::lock_guard lock(mutex);
  if (!task) return;
  const auto mode = sim.mode();
  const bool lost = link_lost || sim.link_lost(t);
  std::optional<bool> outcome;
  switch (task->kind) {
    case Kind::kTakeoff:
      if (mode == TwinMode::kFlying) outcome = true;
      else if (mode != TwinMode::kTakingOff || t > task->deadline_s) outcome = false;
      break;
    case Kind::kLand:
      if (mode == TwinMode::kLanded) outcome = true;
      else if (mode != TwinMode::kLanding || t > task->deadline_s) outcome = false;
      break;
    case Kind::kMove:
      if (t + 1e-9 >= task->deadline_s) {
        if (mode == TwinMode::kFlying || mode == TwinMode::kTakingOff) sim.hover();
        outcome = true;
      } else if (mode != TwinMode::kFlying && mode != TwinMode::kTakingOff) {
        outcome = false;
      }
      break;
  }
  if (!outcome) return;
  if (!lost) respond_bool(task->session, task->msgid, *outcome);
  task.reset();
}

}  // namespace gbdcs::sim
