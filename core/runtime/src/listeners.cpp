#include "gbdcs/runtime/listeners.hpp"

#include <cstdio>
#include <ostream>

#include "gbdcs/contracts/codec.hpp"

namespace gbdcs::runtime {

StorageListener::StorageListener(storage::StorageManager& storage, std::int64_t session_id,
                                 ErrorHandler on_error)
    : storage_(storage), session_id_(session_id), on_error_(std::move(on_error)) {}

void StorageListener::check(const storage::WriteResult& result, const char* what) {
  if (result.ok) return;
  {
    std::lock_guard lock(mutex_);
    ++failures_;
  }
  if (on_error_) on_error_(std::string("storage: could not record ") + what + ": " + result.error);
}

void StorageListener::on_gesture(const contracts::GestureEvent& event) {
  check(storage_.log_gesture(session_id_, event), "a gesture");
}

void StorageListener::on_command(const contracts::DroneCommand& command,
                                 const std::string& outcome) {
  check(storage_.log_command(session_id_, command, outcome), "a command");
}

void StorageListener::on_alert(const contracts::Alert& alert) {
  auto result = storage_.log_alert(session_id_, alert);
  check(result, "an alert");
}

void StorageListener::on_telemetry(const contracts::TelemetryFrame& frame) {
  check(storage_.log_telemetry(session_id_, frame), "telemetry");
}

std::uint64_t StorageListener::failures() const {
  std::lock_guard lock(mutex_);
  return failures_;
}

ConsoleListener::ConsoleListener(std::ostream& out, ConsoleOptions options)
    : out_(out), options_(options) {}

void ConsoleListener::write(const std::string& line) {
  std::lock_guard lock(mutex_);
  out_ << line << '\n';
  out_.flush();
}

namespace {
std::string fixed(double v, int decimals = 2) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}
}  // namespace

void ConsoleListener::on_gesture(const contracts::GestureEvent& e) {
  if (!options_.gestures) return;
  if (options_.json) {
    write(nlohmann::json{{"gesture", contracts::to_json(e)}}.dump());
    return;
  }
  write(contracts::format_utc(e.timestamp) + " gesture   " + std::string(to_string(e.gesture)) +
        (e.repeat ? " (held)" : "") + " confidence " + fixed(e.confidence));
}

void ConsoleListener::on_command(const contracts::DroneCommand& c, const std::string& outcome) {
  if (!options_.commands) return;
  if (options_.json) {
    write(nlohmann::json{{"command", contracts::to_json(c)}, {"outcome", outcome}}.dump());
    return;
  }
  std::string line = contracts::format_utc(c.issued_at) + " command   " +
                     std::string(to_string(c.type)) + " from " + std::string(to_string(c.source));
  if (!c.source_id.empty()) line += " (" + c.source_id + ")";
  if (c.payload) {
    line += " vx=" + fixed(c.payload->vx_m_s) + " vy=" + fixed(c.payload->vy_m_s) +
            " vz=" + fixed(c.payload->vz_m_s) + " yaw=" + fixed(c.payload->yaw_rate_deg_s, 0) +
            "deg/s for " + fixed(c.payload->duration_s, 1) + "s";
  }
  write(line + " -> " + outcome);
}

void ConsoleListener::on_alert(const contracts::Alert& a) {
  if (!options_.alerts) return;
  if (options_.json) {
    write(nlohmann::json{{"alert", contracts::to_json(a)}}.dump());
    return;
  }
  write(contracts::format_utc(a.timestamp) + " ALERT     " + std::string(to_string(a.severity)) +
        " " + a.code + ": " + a.cause + " — " + a.suggestion);
}

void ConsoleListener::on_telemetry(const contracts::TelemetryFrame& f) {
  if (!options_.telemetry) return;
  if (options_.json) {
    write(nlohmann::json{{"telemetry", contracts::to_json(f)}}.dump());
    return;
  }
  write(contracts::format_utc(f.timestamp) + " telemetry " +
        std::string(to_string(f.flight_state)) + " alt=" + fixed(f.altitude_m) +
        "m x=" + fixed(f.x_m) + "m y=" + fixed(f.y_m) + "m hdg=" + fixed(f.heading_deg, 0) +
        "deg speed=" + fixed(f.speed_m_s) + "m/s battery=" + fixed(f.battery_pct, 1) +
        "% link=" + std::string(to_string(f.link)));
}

}  // namespace gbdcs::runtime
