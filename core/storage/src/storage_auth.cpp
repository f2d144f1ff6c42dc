// StorageManager: what the server's auth needs beyond the initial schema (migration 2):
// users by id, revoked tokens (logout), and alert acknowledgements with who made them.
#include "gbdcs/storage/storage_manager.hpp"
#include "row_helpers.hpp"
#include "sqlite_connection.hpp"

namespace gbdcs::storage {

using detail::decode_enum;
using detail::from_ms;
using detail::Query;
using detail::to_ms;

std::optional<UserRecord> StorageManager::find_user_by_id(std::int64_t user_id) const {
  return detail::locked_read(mutex_, options_.path, "user", [&]() -> std::optional<UserRecord> {
    Query q = db_->query(
        "SELECT id, username, password_hash, theme, created_at_ms FROM users WHERE id = ?1");
    q->bind(1, user_id);
    if (!q->step()) return std::nullopt;
    return detail::user_from_row(q);
  });
}

void StorageManager::revoke_token(std::string_view jti, std::optional<std::int64_t> user_id,
                                  contracts::UtcTime expires_at) {
  checked_write("revoke a token", [&] {
    Query q = db_->query(
        "INSERT INTO revoked_tokens (jti, user_id, expires_at_ms, revoked_at_ms) "
        "VALUES (?1, ?2, ?3, ?4) ON CONFLICT (jti) DO NOTHING");
    q->bind(1, jti);
    q->bind(2, user_id);
    q->bind(3, to_ms(expires_at));
    q->bind(4, now_ms());
    q->step();
  });
}

bool StorageManager::is_token_revoked(std::string_view jti) const {
  return detail::locked_read(mutex_, options_.path, "revoked tokens", [&] {
    Query q = db_->query("SELECT 1 FROM revoked_tokens WHERE jti = ?1");
    q->bind(1, jti);
    return q->step();
  });
}

std::int64_t StorageManager::purge_revoked_tokens() {
  std::int64_t count = 0;
  checked_write("purge expired revoked tokens", [&] {
    Query q = db_->query("DELETE FROM revoked_tokens WHERE expires_at_ms < ?1");
    q->bind(1, now_ms());
    q->step();
    count = db_->changes();
  });
  return count;
}

std::optional<AlertRecord> StorageManager::find_alert(std::int64_t alert_id) const {
  return detail::locked_read(mutex_, options_.path, "alert", [&]() -> std::optional<AlertRecord> {
    Query q = db_->query(
        "SELECT id, ts_ms, severity, code, cause, suggestion, acknowledged_at_ms FROM alerts "
        "WHERE id = ?1");
    q->bind(1, alert_id);
    if (!q->step()) return std::nullopt;
    AlertRecord r;
    r.alert.id = q->int64(0);
    r.alert.timestamp = from_ms(q->int64(1));
    r.alert.severity =
        decode_enum(&contracts::severity_from_string, q->text(2), "alerts", "severity");
    r.alert.code = q->text(3);
    r.alert.cause = q->text(4);
    r.alert.suggestion = q->text(5);
    r.acknowledged_at = from_ms(q->optional_int64(6));
    return r;
  });
}

bool StorageManager::acknowledge_alert_by(std::int64_t alert_id,
                                          std::optional<std::int64_t> user_id) {
  bool exists = false;
  checked_write("acknowledge alert " + std::to_string(alert_id), [&] {
    {
      Query q = db_->query(
          "UPDATE alerts SET acknowledged_at_ms = ?2, acknowledged_by = ?3 "
          "WHERE id = ?1 AND acknowledged_at_ms IS NULL");
      q->bind(1, alert_id);
      q->bind(2, now_ms());
      q->bind(3, user_id);
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

}  // namespace gbdcs::storage
