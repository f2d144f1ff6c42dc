// Faults injected into the twin, scheduled on the SIMULATED clock (seconds since the sim
// started). A fault is active for start_s <= t < start_s + duration_s (duration_s absent:
// to the end of the run); battery_jump happens once, at start_s.
//
//   type             parameters (JSON keys)                                applied by
//   link_loss        -                                                     the adapter:
//                                                                          link_lost(t)
//   telemetry_delay  delay_ms, jitter_ms (uniform +-, seeded, >= 0 total)   the adapter:
//                                                                          telemetry_delay_s
//   battery_jump     battery_pct (the charge jumps to it)                   TwinSim
//   wind_gust        force_n [x, y, z] (N, contracts' world frame: x forward
//                    at start, y right, z up), on the drone's centre of mass TwinSim
//   motor_degraded   motor (0 front-left, 1 front-right, 2 rear-right,
//                    3 rear-left), thrust_factor (0...1)                   TwinSim
//   sensor_noise     position_sigma_m, velocity_sigma_m_s, heading_sigma_deg TwinSim, on
//                    (Gaussian, seeded; on the reported status only)       status() only
//
// JSON: {"faults": [ {"type": "wind_gust", "start_s": 4, "duration_s": 1,
//                     "force_n": [0.2, 0, 0]}, ... ]} or the bare array. Strict: an unknown
// type, an unknown key for that type, or a wrong value throws std::invalid_argument naming
// the fault's index and the key.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gbdcs::sim {

enum class FaultType {
  kLinkLoss,
  kTelemetryDelay,
  kBatteryJump,
  kWindGust,
  kMotorDegraded,
  kSensorNoise,
};
std::string_view to_string(FaultType t);  // "link_loss", ...
std::optional<FaultType> fault_type_from_string(std::string_view s);

struct Fault {
  FaultType type = FaultType::kLinkLoss;
  double start_s = 0;
  double duration_s = std::numeric_limits<double>::infinity();
  // Parameters: only those of `type` are read.
  double delay_ms = 0;
  double jitter_ms = 0;
  double battery_pct = 0;
  std::array<double, 3> force_n{};  // x forward, y right, z up
  int motor = 0;
  double thrust_factor = 1;
  double position_sigma_m = 0;
  double velocity_sigma_m_s = 0;
  double heading_sigma_deg = 0;

  bool active(double t_s) const { return t_s >= start_s && t_s < start_s + duration_s; }
};

struct SensorNoise {
  double position_sigma_m = 0;
  double velocity_sigma_m_s = 0;
  double heading_sigma_deg = 0;
  bool any() const {
    return position_sigma_m > 0 || velocity_sigma_m_s > 0 || heading_sigma_deg > 0;
  }
};

class FaultSchedule {
 public:
  FaultSchedule() = default;
  explicit FaultSchedule(std::vector<Fault> faults);  // validates; throws std::invalid_argument

  static FaultSchedule from_json(const nlohmann::json& doc);
  static FaultSchedule from_json_text(std::string_view text);  // malformed JSON -> invalid_argument
  static FaultSchedule load(const std::string& path);          // + unreadable file
  nlohmann::json to_json() const;

  const std::vector<Fault>& faults() const { return faults_; }
  bool empty() const { return faults_.empty(); }

  // Queries at simulated time t_s (overlapping faults combine as noted).
  bool link_lost(double t_s) const;
  // Largest active delay_ms plus its jitter: a uniform draw in [-jitter, +jitter] that is a
  // pure function of (seed, t in whole ms), so repeated queries agree; never below 0.
  double telemetry_delay_s(double t_s, std::uint32_t seed) const;
  std::array<double, 3> wind_force_n(double t_s) const;  // sum of active gusts
  double motor_factor(int motor, double t_s) const;      // product of active factors
  SensorNoise sensor_noise(double t_s) const;            // largest active sigmas

 private:
  std::vector<Fault> faults_;
};

}  // namespace gbdcs::sim
