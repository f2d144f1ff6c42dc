#include "gbdcs/telemetry/failsafe_monitor.hpp"

#include "gbdcs/contracts/json_options.hpp"

#include <cmath>
#include <stdexcept>

namespace gbdcs::telemetry {

using contracts::CommandType;
using contracts::FlightState;
using contracts::Severity;

FailsafeOptions FailsafeOptions::from_json(const nlohmann::json& doc) {
  FailsafeOptions o;
  const std::string owner = "failsafe options";
  contracts::JsonOptionReader r(doc, owner);
  r.read("link_timeout_s", o.link_timeout_s);
  r.read("idle_timeout_s", o.idle_timeout_s);
  r.read("battery_warn_pct", o.battery_warn_pct);
  r.read("battery_land_pct", o.battery_land_pct);
  r.finish();
  contracts::require(o.link_timeout_s > 0, owner, "link_timeout_s", "must be positive");
  contracts::require(o.idle_timeout_s > 0, owner, "idle_timeout_s", "must be positive");
  contracts::require(o.battery_land_pct > 0 && o.battery_land_pct < o.battery_warn_pct &&
                         o.battery_warn_pct <= 100,
                     owner, "battery_land_pct",
                     "must be positive and below battery_warn_pct (which is at most 100)");
  return o;
}

FailsafeMonitor::FailsafeMonitor(const contracts::Clock& clock, FailsafeSinks sinks,
                                 FailsafeOptions options)
    : clock_(clock), sinks_(std::move(sinks)), options_(options) {}

void FailsafeMonitor::start() {
  std::lock_guard lock(mutex_);
  started_ = true;
  last_telemetry_ = clock_.now();
  last_input_ = last_telemetry_;
}

void FailsafeMonitor::stop() {
  std::lock_guard lock(mutex_);
  started_ = false;
}

void FailsafeMonitor::command_locked(Outbox& out, CommandType type, const std::string& code) {
  contracts::DroneCommand c;
  c.type = type;
  c.source = contracts::CommandSource::kFailsafe;
  c.source_id = code;
  c.issued_at = clock_.utc_now();
  out.commands.push_back(c);
}

void FailsafeMonitor::alert_locked(Outbox& out, Severity severity, const std::string& code,
                                   const std::string& cause, const std::string& suggestion) {
  contracts::Alert a;
  a.severity = severity;
  a.code = code;
  a.cause = cause;
  a.suggestion = suggestion;
  a.timestamp = clock_.utc_now();
  out.alerts.push_back(a);
}

void FailsafeMonitor::flush(Outbox& out) {
  // Alerts first: the operator learns why before the drone reacts.
  for (const auto& a : out.alerts) {
    if (sinks_.alert) sinks_.alert(a);
  }
  for (const auto& [reason, active] : out.inhibits) {
    if (sinks_.inhibit) sinks_.inhibit(reason, active);
  }
  for (const auto& c : out.commands) {
    if (sinks_.command) sinks_.command(c);
  }
}

static bool airborne(FlightState s) { return s == FlightState::kFlying || s == FlightState::kLanding; }

void FailsafeMonitor::on_telemetry(const contracts::TelemetryFrame& frame) {
  Outbox out;
  {
    std::lock_guard lock(mutex_);
    const auto now = clock_.now();
    last_telemetry_ = now;
    if (frame.flight_state == FlightState::kFlying && state_ != FlightState::kFlying) {
      flying_since_ = now;
    } else if (frame.flight_state != FlightState::kFlying) {
      flying_since_.reset();
      idle_ = false;
    }
    state_ = frame.flight_state;

    if (frame.link == contracts::LinkState::kLost) {
      if (!link_lost_) {
        link_lost_ = true;
        alert_locked(out, Severity::kCritical, alert_code::kLinkLoss,
                     "the drone reports its link as lost",
                     "hovering; move closer to the drone or check its Wi-Fi/radio, land if it "
                     "does not recover");
        if (airborne(state_)) command_locked(out, CommandType::kHover, alert_code::kLinkLoss);
      }
    } else if (link_lost_) {
      link_lost_ = false;
      alert_locked(out, Severity::kInfo, alert_code::kLinkRestored, "telemetry is back",
                   "check the drone's position before giving the next command");
    }

    battery_pct_ = frame.battery_pct;
    if (battery_pct_ < options_.battery_land_pct) {
      if (!battery_critical_) {
        battery_critical_ = true;
        battery_low_ = true;
        alert_locked(out, Severity::kCritical, alert_code::kBatteryCritical,
                     "battery at " + std::to_string(static_cast<int>(std::floor(battery_pct_))) +
                         " %, below the auto-land threshold",
                     "landing now; charge or swap the battery before flying again");
        out.inhibits.emplace_back(kBatteryInhibit, true);
        if (state_ == FlightState::kFlying) {
          command_locked(out, CommandType::kLand, alert_code::kBatteryCritical);
        }
      }
    } else if (battery_critical_) {
      battery_critical_ = false;
      out.inhibits.emplace_back(kBatteryInhibit, false);
    }
    if (battery_pct_ < options_.battery_warn_pct && !battery_low_) {
      battery_low_ = true;
      alert_locked(out, Severity::kWarning, alert_code::kBatteryLow,
                   "battery at " + std::to_string(static_cast<int>(std::floor(battery_pct_))) +
                       " %",
                   "finish the flight and land soon");
    } else if (battery_pct_ >= options_.battery_warn_pct + 2.0) {
      battery_low_ = false;  // 2 % hysteresis so a noisy reading does not re-alert
    }
    evaluate_timers_locked(out);
  }
  flush(out);
}

void FailsafeMonitor::note_operator_input() {
  std::lock_guard lock(mutex_);
  last_input_ = clock_.now();
  idle_ = false;
}

void FailsafeMonitor::on_vision_health(bool healthy, const std::string& reason) {
  Outbox out;
  {
    std::lock_guard lock(mutex_);
    if (healthy == vision_healthy_) return;
    vision_healthy_ = healthy;
    if (!healthy) {
      const bool flying = state_ == FlightState::kFlying;
      alert_locked(out, flying ? Severity::kCritical : Severity::kWarning,
                   alert_code::kVisionUnhealthy,
                   "vision is not healthy: " + (reason.empty() ? std::string("unknown") : reason),
                   flying ? "hovering; use the keyboard or land, and check the camera"
                          : "take-off is locked until the camera works; check it is connected");
      out.inhibits.emplace_back(kVisionInhibit, true);
      if (flying) command_locked(out, CommandType::kHover, alert_code::kVisionUnhealthy);
    } else {
      alert_locked(out, Severity::kInfo, alert_code::kVisionRestored, "vision is healthy again",
                   "gestures are recognised again");
      out.inhibits.emplace_back(kVisionInhibit, false);
    }
  }
  flush(out);
}

void FailsafeMonitor::tick() {
  Outbox out;
  {
    std::lock_guard lock(mutex_);
    evaluate_timers_locked(out);
  }
  flush(out);
}

void FailsafeMonitor::evaluate_timers_locked(Outbox& out) {
  if (!started_) return;
  const auto now = clock_.now();
  const double since_telemetry_s = contracts::to_seconds(now - last_telemetry_);
  if (since_telemetry_s > options_.link_timeout_s && !link_lost_) {
    link_lost_ = true;
    alert_locked(out, Severity::kCritical, alert_code::kLinkLoss,
                 "no telemetry from the drone for " +
                     std::to_string(static_cast<int>(since_telemetry_s * 1000)) + " ms",
                 "hovering; check the drone is powered and in range, then its Wi-Fi/radio");
    if (airborne(state_)) command_locked(out, CommandType::kHover, alert_code::kLinkLoss);
  }
  if (state_ == FlightState::kFlying && flying_since_ && !idle_ && !link_lost_) {
    const auto since = std::max(last_input_, *flying_since_);
    if (contracts::to_seconds(now - since) > options_.idle_timeout_s) {
      idle_ = true;
      alert_locked(out, Severity::kInfo, alert_code::kIdleHover,
                   "Idle – hovering: no gesture for " +
                       std::to_string(static_cast<int>(options_.idle_timeout_s)) + " s",
                   "show a gesture to continue, or a fist to land");
      command_locked(out, CommandType::kHover, alert_code::kIdleHover);
    }
  }
}

bool FailsafeMonitor::link_lost() const {
  std::lock_guard lock(mutex_);
  return link_lost_;
}
bool FailsafeMonitor::idle_hovering() const {
  std::lock_guard lock(mutex_);
  return idle_;
}
bool FailsafeMonitor::battery_critical() const {
  std::lock_guard lock(mutex_);
  return battery_critical_;
}
bool FailsafeMonitor::vision_healthy() const {
  std::lock_guard lock(mutex_);
  return vision_healthy_;
}

}  // namespace gbdcs::telemetry
