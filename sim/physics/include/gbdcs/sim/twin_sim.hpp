// TwinSim: the mutable half of the twin (MuJoCo's mjData): one simulated Tello in its room.
//
// Time    : simulated only. step_to(t_s) runs fixed physics steps (the model's timestep,
//           2 ms) until time_s() reaches t_s; it never goes back. No wall clock anywhere.
// Commands: Tello semantics, answered at once (CommandResult; error texts as a Tello's
//           "error ..." replies): takeoff, land, emergency, rc a b c d, hover (= rc 0 0 0 0).
//           Every command, accepted or not, resets the 15 s no-command timer; when it runs
//           out in the air the twin lands by itself, as a real Tello does.
// Modes   : kLanded -takeoff-> kTakingOff (climbs to ~1 m) -> kFlying -land-> kLanding ->
//           kLanded on touch-down (motors off). emergency: motors off -> kFalling -> kLanded,
//           or kCrashed when it meets the ground faster than crash_speed_m_s (also from any
//           other mode). Battery at 0 % forces a landing. kCrashed refuses every command.
// Frames  : status() reports the contracts' frame: x forward at the start, y RIGHT, z up;
//           heading clockwise from +x seen from above, [0, 360). Body velocities: x forward,
//           y right. z_m is the altitude of the body origin above its resting height (0
//           landed). Inside (mjData, FlightController) the frame is MuJoCo's: y left.
// Contacts: a contact between the drone and a wall or obstacle starts a collision (counted
//           again only after 0.2 s without one); a contact that supports the drone from below
//           (floor or an obstacle's top) is a touch-down, and a crash when the downward speed
//           just before it exceeds crash_speed_m_s.
// Faults  : FaultSchedule (faults.hpp); TwinSim applies battery_jump, wind_gust (xfrc_applied),
//           motor_degraded (thrust factor) and sensor_noise (status() only, seeded by a
//           counter RNG: a pure function of seed and step, so asking twice gives the same).
//           link_loss and telemetry_delay are for the adapter: link_lost(t), telemetry_delay_s(t).
// Determinism: the same model, options, seed and command sequence at the same simulated
//           times give the same states bit for bit.
// Threads : not thread-safe; one owner (the adapter) serialises calls. model()/data() are
//           for the renderer between steps.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <cstdint>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/sim/battery_model.hpp"
#include "gbdcs/sim/faults.hpp"
#include "gbdcs/sim/flight_controller.hpp"
#include "gbdcs/sim/twin_model.hpp"

namespace gbdcs::sim {

struct TwinOptions {
  FlightControllerOptions controller;
  BatteryOptions battery;
  double crash_speed_m_s = 2.0;     // downward speed at touch-down that breaks it
  double auto_land_after_s = 15.0;  // no command for this long in the air -> land
  FaultSchedule faults;

  // {"controller": {...}, "battery": {...}, "crash_speed_m_s": 2, "auto_land_after_s": 15,
  //  "faults": [...]}; absent keys keep defaults; unknown keys throw std::invalid_argument.
  static TwinOptions from_json(const nlohmann::json& doc);
};

enum class TwinMode { kLanded, kTakingOff, kFlying, kLanding, kFalling, kCrashed };
std::string_view to_string(TwinMode m);  // "LANDED", "TAKING_OFF", ...

struct CommandResult {
  bool ok = true;
  std::string error;  // empty when ok
};

struct TwinStatus {
  double time_s = 0;
  double x_m = 0;  // from the start point, x forward at start, y right
  double y_m = 0;
  double z_m = 0;     // altitude above the resting height
  double vx_m_s = 0;  // world (x forward at start, y right, z up)
  double vy_m_s = 0;
  double vz_m_s = 0;
  double body_vx_m_s = 0;  // horizontal velocity in the heading frame: x forward, y right
  double body_vy_m_s = 0;
  double heading_deg = 0;  // [0, 360), clockwise from +x seen from above
  double roll_deg = 0;     // right side down positive
  double pitch_deg = 0;    // nose up positive
  double speed_m_s = 0;    // |v|, 3-D
  double battery_pct = 100;
  double voltage_v = 0;
  double current_a = 0;
  TwinMode mode = TwinMode::kLanded;
  int collisions = 0;
  std::array<double, kRotorCount> motor_thrust_n{};  // actual (after the motor lag), N
  double last_command_age_s = 0;  // simulated seconds since the last command (or the start)
};

class TwinSim {
 public:
  TwinSim(std::shared_ptr<const TwinModel> model, TwinOptions options, std::uint32_t seed);
  ~TwinSim();
  TwinSim(const TwinSim&) = delete;
  TwinSim& operator=(const TwinSim&) = delete;

  void step_to(double t_s);
  double time_s() const;

  CommandResult takeoff();
  CommandResult land();
  CommandResult emergency();
  CommandResult rc(int a, int b, int c, int d);
  CommandResult hover();
  // Any other command a drone hears (a protocol's handshake, queries, settings): it only
  // resets the no-command timer, as a real Tello's 15 s auto-land counts every command.
  void keep_alive();

  TwinStatus status() const;
  TwinMode mode() const { return mode_; }

  const mjModel* model() const;
  mjData* data() { return data_; }
  const mjData* data() const { return data_; }
  const TwinModel& twin_model() const { return *model_; }
  const TwinOptions& options() const { return options_; }
  std::uint32_t seed() const { return seed_; }

  const FaultSchedule& faults() const { return options_.faults; }
  void set_faults(FaultSchedule faults);  // battery jumps already past are not replayed
  bool link_lost(double t_s) const { return options_.faults.link_lost(t_s); }
  double telemetry_delay_s(double t_s) const {
    return options_.faults.telemetry_delay_s(t_s, seed_);
  }

  // One line per MuJoCo warning raised in this state ("<text> (n times)"); empty in a healthy
  // flight. Read from mjData's warning counters.
  std::vector<std::string> mujoco_warnings() const;

 private:
  void step_once();
  void apply_faults(double t_s);
  void update_mode_before_step();
  void scan_contacts(double downward_speed_m_s);
  VehicleState vehicle_state() const;
  void cut_motors();
  CommandResult refuse_if_grounded(const char* what);

  std::shared_ptr<const TwinModel> model_;
  TwinOptions options_;
  std::uint32_t seed_;
  mjData* data_ = nullptr;
  FlightController controller_;
  BatteryModel battery_;
  TwinMode mode_ = TwinMode::kLanded;
  std::int64_t steps_ = 0;
  double last_command_s_ = 0;
  int collisions_ = 0;
  double last_obstacle_contact_s_ = -1e9;
  bool supported_ = true;  // resting on something at the last step
  std::vector<bool> jump_applied_;
  MotorThrusts commanded_n_{};
};

// Physics speed without rendering: flies `sim_seconds` of a take-off, a forward/yaw pattern
// and a hover, and returns simulated seconds per wall-clock second (one thread).
double measure_physics_realtime_factor(std::shared_ptr<const TwinModel> model,
                                       double sim_seconds = 60.0);

}  // namespace gbdcs::sim
