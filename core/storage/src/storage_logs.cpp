// StorageManager: the per-session logs (gestures, commands, telemetry, alerts) and their
// read-back. Each log_* is one autocommitted INSERT on a cached statement.
#include <nlohmann/json.hpp>

#include "gbdcs/contracts/codec.hpp"
#include "gbdcs/storage/storage_manager.hpp"
#include "row_helpers.hpp"
#include "sqlite_connection.hpp"

namespace gbdcs::storage {

using detail::decode_enum;
using detail::from_ms;
using detail::Query;
using detail::to_ms;

namespace {

// enum -> its contract name, as the schema stores it.
template <class E>
std::string_view name_of(E value) {
  return contracts::to_string(value);
}

}  // namespace

// ---- writes ---------------------------------------------------------------------------

WriteResult StorageManager::log_gesture(std::int64_t session_id,
                                        const contracts::GestureEvent& event) {
  return guarded_write("log a gesture", session_id, [&] {
    Query q = db_->query(
        "INSERT INTO gestures (session_id, ts_ms, gesture, confidence, handedness, frame_id, "
        "repeat) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)");
    q->bind(1, session_id);
    q->bind(2, to_ms(event.timestamp));
    q->bind(3, name_of(event.gesture));
    q->bind(4, event.confidence);
    q->bind(5, name_of(event.handedness));
    q->bind(6, event.frame_id);
    q->bind(7, event.repeat);
    q->step();
    return db_->last_insert_rowid();
  });
}

WriteResult StorageManager::log_command(std::int64_t session_id,
                                        const contracts::DroneCommand& command,
                                        std::string_view result) {
  return guarded_write("log a command", session_id, [&] {
    std::optional<std::string> payload;
    if (command.payload) payload = contracts::to_json(*command.payload).dump();
    Query q = db_->query(
        "INSERT INTO commands (session_id, ts_ms, recorded_at_ms, command_id, type, source, "
        "source_id, payload, result) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)");
    q->bind(1, session_id);
    q->bind(2, to_ms(command.issued_at));
    q->bind(3, now_ms());
    q->bind(4, command.id);
    q->bind(5, name_of(command.type));
    q->bind(6, name_of(command.source));
    q->bind(7, std::string_view(command.source_id));
    q->bind(8, payload);
    q->bind(9, result);
    q->step();
    return db_->last_insert_rowid();
  });
}

WriteResult StorageManager::log_telemetry(std::int64_t session_id,
                                          const contracts::TelemetryFrame& frame) {
  return guarded_write("log telemetry", session_id, [&] {
    Query q = db_->query(
        "INSERT INTO telemetry (session_id, ts_ms, altitude_m, speed_m_s, vx_m_s, vy_m_s, "
        "vz_m_s, x_m, y_m, heading_deg, battery_pct, flight_state, link) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13)");
    q->bind(1, session_id);
    q->bind(2, to_ms(frame.timestamp));
    q->bind(3, frame.altitude_m);
    q->bind(4, frame.speed_m_s);
    q->bind(5, frame.vx_m_s);
    q->bind(6, frame.vy_m_s);
    q->bind(7, frame.vz_m_s);
    q->bind(8, frame.x_m);
    q->bind(9, frame.y_m);
    q->bind(10, frame.heading_deg);
    q->bind(11, frame.battery_pct);
    q->bind(12, name_of(frame.flight_state));
    q->bind(13, name_of(frame.link));
    q->step();
    return db_->last_insert_rowid();
  });
}

WriteResult StorageManager::log_alert(std::int64_t session_id, const contracts::Alert& alert) {
  return guarded_write("log an alert", session_id, [&] {
    Query q = db_->query(
        "INSERT INTO alerts (session_id, ts_ms, severity, code, cause, suggestion) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
    q->bind(1, session_id);
    q->bind(2, to_ms(alert.timestamp));
    q->bind(3, name_of(alert.severity));
    q->bind(4, std::string_view(alert.code));
    q->bind(5, std::string_view(alert.cause));
    q->bind(6, std::string_view(alert.suggestion));
    q->step();
    return db_->last_insert_rowid();
  });
}

bool StorageManager::acknowledge_alert(std::int64_t alert_id) {
  bool exists = false;
  checked_write("acknowledge alert " + std::to_string(alert_id), [&] {
    {
      Query q = db_->query(
          "UPDATE alerts SET acknowledged_at_ms = ?2 WHERE id = ?1 AND acknowledged_at_ms IS NULL");
      q->bind(1, alert_id);
      q->bind(2, now_ms());
      q->step();
      exists = db_->changes() > 0;
    }
    if (!exists) {
      Query q = db_->query("SELECT 1 FROM alerts WHERE id = ?1");
      q->bind(1, alert_id);
      exists = q->step();
    }
  });
  return exists;
}

// ---- reads ----------------------------------------------------------------------------

std::vector<contracts::GestureEvent> StorageManager::gestures(std::int64_t session_id) const {
  return detail::locked_read(mutex_, options_.path, "gestures", [&] {
    Query q = db_->query(
        "SELECT ts_ms, gesture, confidence, handedness, frame_id, repeat FROM gestures "
        "WHERE session_id = ?1 ORDER BY ts_ms, id");
    q->bind(1, session_id);
    std::vector<contracts::GestureEvent> out;
    while (q->step()) {
      contracts::GestureEvent e;
      e.timestamp = from_ms(q->int64(0));
      e.gesture = decode_enum(&contracts::gesture_from_string, q->text(1), "gestures", "gesture");
      e.confidence = q->real(2);
      e.handedness =
          decode_enum(&contracts::handedness_from_string, q->text(3), "gestures", "handedness");
      e.frame_id = q->int64(4);
      e.repeat = q->int64(5) != 0;
      out.push_back(e);
    }
    return out;
  });
}

std::vector<CommandRecord> StorageManager::commands(std::int64_t session_id) const {
  return detail::locked_read(mutex_, options_.path, "commands", [&] {
    Query q = db_->query(
        "SELECT ts_ms, recorded_at_ms, command_id, type, source, source_id, payload, result "
        "FROM commands WHERE session_id = ?1 ORDER BY ts_ms, id");
    q->bind(1, session_id);
    std::vector<CommandRecord> out;
    while (q->step()) {
      CommandRecord r;
      r.command.issued_at = from_ms(q->int64(0));
      r.recorded_at = from_ms(q->int64(1));
      r.command.id = q->int64(2);
      r.command.type =
          decode_enum(&contracts::command_type_from_string, q->text(3), "commands", "type");
      r.command.source =
          decode_enum(&contracts::command_source_from_string, q->text(4), "commands", "source");
      r.command.source_id = q->text(5);
      if (auto payload = q->optional_text(6)) {
        r.command.payload = contracts::motion_payload_from_json(nlohmann::json::parse(*payload));
      }
      r.result = q->text(7);
      out.push_back(std::move(r));
    }
    return out;
  });
}

std::vector<contracts::TelemetryFrame> StorageManager::telemetry(
    std::int64_t session_id, std::optional<std::int64_t> limit) const {
  return detail::locked_read(mutex_, options_.path, "telemetry", [&] {
    Query q = db_->query(
        "SELECT ts_ms, altitude_m, speed_m_s, vx_m_s, vy_m_s, vz_m_s, x_m, y_m, heading_deg, "
        "battery_pct, flight_state, link FROM telemetry WHERE session_id = ?1 "
        "ORDER BY ts_ms, id LIMIT ?2");
    q->bind(1, session_id);
    q->bind(2, limit ? std::max<std::int64_t>(0, *limit) : std::int64_t{-1});  // -1: no limit
    std::vector<contracts::TelemetryFrame> out;
    while (q->step()) {
      contracts::TelemetryFrame f;
      f.timestamp = from_ms(q->int64(0));
      f.altitude_m = q->real(1);
      f.speed_m_s = q->real(2);
      f.vx_m_s = q->real(3);
      f.vy_m_s = q->real(4);
      f.vz_m_s = q->real(5);
      f.x_m = q->real(6);
      f.y_m = q->real(7);
      f.heading_deg = q->real(8);
      f.battery_pct = q->real(9);
      f.flight_state = decode_enum(&contracts::flight_state_from_string, q->text(10), "telemetry",
                                   "flight_state");
      f.link = decode_enum(&contracts::link_state_from_string, q->text(11), "telemetry", "link");
      out.push_back(f);
    }
    return out;
  });
}

std::vector<AlertRecord> StorageManager::alerts(std::int64_t session_id) const {
  return detail::locked_read(mutex_, options_.path, "alerts", [&] {
    Query q = db_->query(
        "SELECT id, ts_ms, severity, code, cause, suggestion, acknowledged_at_ms FROM alerts "
        "WHERE session_id = ?1 ORDER BY ts_ms, id");
    q->bind(1, session_id);
    std::vector<AlertRecord> out;
    while (q->step()) {
      AlertRecord r;
      r.alert.id = q->int64(0);
      r.alert.timestamp = from_ms(q->int64(1));
      r.alert.severity =
          decode_enum(&contracts::severity_from_string, q->text(2), "alerts", "severity");
      r.alert.code = q->text(3);
      r.alert.cause = q->text(4);
      r.alert.suggestion = q->text(5);
      r.acknowledged_at = from_ms(q->optional_int64(6));
      out.push_back(std::move(r));
    }
    return out;
  });
}

}  // namespace gbdcs::storage
