// FailsafeMonitor: the safety state machine. Plain logic on an injected Clock.
//
// Inputs : on_telemetry(frame)        every TelemetryFrame (inline observer)
//          note_operator_input()      a gesture event or key from the operator
//          on_vision_health(ok, why)  the vision pipeline's health
//          start()                    the drone is connected: the link timer starts
//          tick()                     evaluate the timers (call often: every frame / 50 ms)
// Outputs: commands (source failsafe, source_id = alert code) to the CommandSink, alerts to
//          the AlertSink, take-off inhibits to the InhibitSink.
// Rules (defaults in FailsafeOptions):
//   LINK_LOSS          no telemetry for > link_timeout_s (2 s), or a frame with link LOST:
//                      HOVER + CRITICAL alert, once per episode; LINK_RESTORED when frames
//                      come back.
//   IDLE_HOVER         FLYING and no operator input for > idle_timeout_s (3 s): HOVER + INFO
//                      alert "Idle – hovering", once until the operator acts again.
//   BATTERY_LOW        battery < battery_warn_pct (30 %): WARNING once.
//   BATTERY_CRITICAL   battery < battery_land_pct (15 %): LAND if airborne + CRITICAL alert,
//                      take-off inhibited until the battery is above it again.
//   VISION_UNHEALTHY   vision reports unhealthy: HOVER if flying + alert (CRITICAL when
//                      flying, WARNING on the ground), take-off inhibited; VISION_RESTORED.
// Thread-safe; sinks are called without the monitor's lock held.
#pragma once

#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::telemetry {

struct FailsafeOptions {
  double link_timeout_s = 2.0;
  double idle_timeout_s = 3.0;
  double battery_warn_pct = 30.0;
  double battery_land_pct = 15.0;

  static FailsafeOptions from_json(const nlohmann::json& doc);  // throws std::invalid_argument
};

struct FailsafeSinks {
  std::function<void(const contracts::DroneCommand&)> command;
  std::function<void(const contracts::Alert&)> alert;
  // (reason, active): a take-off inhibit set or cleared
  std::function<void(const std::string&, bool)> inhibit;
};

class FailsafeMonitor {
 public:
  FailsafeMonitor(const contracts::Clock& clock, FailsafeSinks sinks, FailsafeOptions options = {});

  void start();
  void stop();
  void on_telemetry(const contracts::TelemetryFrame& frame);
  void note_operator_input();
  void on_vision_health(bool healthy, const std::string& reason);
  void tick();

  bool link_lost() const;
  bool idle_hovering() const;
  bool battery_critical() const;
  bool vision_healthy() const;

 private:
  struct Outbox {
    std::vector<contracts::DroneCommand> commands;
    std::vector<contracts::Alert> alerts;
    std::vector<std::pair<std::string, bool>> inhibits;
  };
  void evaluate_timers_locked(Outbox& out);
  void command_locked(Outbox& out, contracts::CommandType type, const std::string& code);
  void alert_locked(Outbox& out, contracts::Severity severity, const std::string& code,
                    const std::string& cause, const std::string& suggestion);
  void flush(Outbox& out);

  const contracts::Clock& clock_;
  FailsafeSinks sinks_;
  FailsafeOptions options_;
  mutable std::mutex mutex_;
  bool started_ = false;
  contracts::Duration last_telemetry_{0};
  contracts::Duration last_input_{0};
  std::optional<contracts::Duration> flying_since_;
  contracts::FlightState state_ = contracts::FlightState::kInit;
  double battery_pct_ = 100;
  bool link_lost_ = false;
  bool idle_ = false;
  bool battery_low_ = false;
  bool battery_critical_ = false;
  bool vision_healthy_ = true;
};

// Alert codes raised by the core (documented in docs/ALERTS.md).
namespace alert_code {
inline constexpr const char* kLinkLoss = "LINK_LOSS";
inline constexpr const char* kLinkRestored = "LINK_RESTORED";
inline constexpr const char* kIdleHover = "IDLE_HOVER";
inline constexpr const char* kBatteryLow = "BATTERY_LOW";
inline constexpr const char* kBatteryCritical = "BATTERY_CRITICAL";
inline constexpr const char* kVisionUnhealthy = "VISION_UNHEALTHY";
inline constexpr const char* kVisionRestored = "VISION_RESTORED";
}  // namespace alert_code

inline constexpr const char* kBatteryInhibit =
    "battery critical (charge or swap the battery before flying)";
inline constexpr const char* kVisionInhibit =
    "vision is not healthy (check the camera and that a hand is visible)";

}  // namespace gbdcs::telemetry
