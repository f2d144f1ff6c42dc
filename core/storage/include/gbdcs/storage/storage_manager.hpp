// StorageManager: the SQLite store of users, sessions, gesture/command/telemetry/alert logs and
// configuration.
//
// Inputs:   GestureEvent, DroneCommand (+ result), TelemetryFrame, Alert, each for a session;
//           users and config from the server.
// Outputs:  the same read back per session; session summaries, newest first.
// Options:  StorageOptions (storage_options.hpp): path, max_size_bytes (250 MiB),
//           telemetry_retention_days (30), read_only, busy_timeout_ms (5000).
// Time:     every timestamp is the injected Clock's utc_now() or the message's own time,
//           stored as INTEGER milliseconds since the Unix epoch (UTC) in `*_ms` columns:
//           exact round trip, cheap ordering and retention arithmetic. For a human reading the
//           file: strftime('%Y-%m-%dT%H:%M:%fZ', ts_ms / 1000.0, 'unixepoch').
// Errors:   opening throws StorageError naming the path, the cause and the fix (not a database,
//           corrupt, newer schema, cannot write, cannot open). log_* never throw: a failed write
//           returns a WriteResult that is not ok, is counted in write_failures() and goes to the
//           error handler; the process keeps running. Other writes and reads throw StorageError
//           (and a failed write among them is counted and reported the same way).
//           A full disk (ENOSPC, a file-size limit's EFBIG, SQLITE_FULL) is named as such,
//           with the fix "free disk space"; write_health() tells whether writes fail now.
//           A failing episode ends once writes have succeeded for kWriteRecoveryHold (injected
//           clock) with no failure between: a nearly full disk, where a write that reuses
//           freed space succeeds between failing ones, stays one episode instead of flapping.
// Durability: WAL, synchronous=FULL, every write commits on its own: a kill -9 loses nothing
//           that a call already returned as ok.
// Threads:  every method may be called from any thread; one mutex serialises the connection.
//           The error handler runs outside it, so it may call back into the manager.
//
// Example:
//   contracts::SteadyClock clock;
//   StorageManager db({.path = "var/gbdcs.db"}, clock);
//   auto session = db.begin_session(std::nullopt, "twin", "default");
//   if (auto r = db.log_telemetry(session, frame); !r) { /* already counted and reported */ }
//   db.end_session(session);
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/contracts/messages.hpp"
#include "gbdcs/storage/records.hpp"
#include "gbdcs/storage/storage_options.hpp"

namespace gbdcs::storage {

namespace detail {
class Connection;
}

class StorageManager {
 public:
  // Opens or creates the database and migrates it to schema_version(). Throws StorageError.
  StorageManager(StorageOptions options, const contracts::Clock& clock);
  ~StorageManager();
  StorageManager(const StorageManager&) = delete;
  StorageManager& operator=(const StorageManager&) = delete;

  // ---- users (usernames compare case-insensitively) ----
  std::optional<std::int64_t> create_user(std::string_view username,
                                          std::string_view password_hash);  // nullopt: name taken
  std::optional<UserRecord> find_user(std::string_view username) const;
  bool set_user_theme(std::int64_t user_id, std::string_view theme);  // false: no such user
  std::optional<UserRecord> find_user_by_id(std::int64_t user_id) const;

  // ---- revoked tokens (server logout; storage_auth.cpp) ----
  // Records a token id as revoked until expires_at (then purge_revoked_tokens may drop it).
  void revoke_token(std::string_view jti, std::optional<std::int64_t> user_id,
                    contracts::UtcTime expires_at);
  bool is_token_revoked(std::string_view jti) const;
  std::int64_t purge_revoked_tokens();  // drops those expired by the clock's utc_now()
  // The alert's session and acknowledgement, by the id acknowledge_alert takes.
  std::optional<AlertRecord> find_alert(std::int64_t alert_id) const;
  // As acknowledge_alert, also recording who (a user id).
  bool acknowledge_alert_by(std::int64_t alert_id, std::optional<std::int64_t> user_id);

  // ---- sessions ----
  std::int64_t begin_session(std::optional<std::int64_t> user_id, std::string drone,
                             std::string profile);
  bool end_session(std::int64_t session_id);  // false: unknown or already ended
  // Ends every session still open (left so by a crash) at its last logged row; call at start-up
  // before begin_session, so retention can reclaim them. Returns how many were ended.
  std::int64_t end_open_sessions();
  std::vector<SessionSummary> list_sessions(std::int64_t limit, std::int64_t offset = 0) const;
  std::optional<SessionSummary> get_session(std::int64_t session_id) const;
  std::int64_t session_count() const;

  // ---- logs: each commits on its own; never throws ----
  WriteResult log_gesture(std::int64_t session_id, const contracts::GestureEvent& event);
  WriteResult log_command(std::int64_t session_id, const contracts::DroneCommand& command,
                          std::string_view result);
  WriteResult log_telemetry(std::int64_t session_id, const contracts::TelemetryFrame& frame);
  WriteResult log_alert(std::int64_t session_id, const contracts::Alert& alert);  // row_id = id
  bool acknowledge_alert(std::int64_t alert_id);  // false: no such alert; keeps the first time

  // ---- read back, oldest first ----
  std::vector<contracts::GestureEvent> gestures(std::int64_t session_id) const;
  std::vector<CommandRecord> commands(std::int64_t session_id) const;
  std::vector<contracts::TelemetryFrame> telemetry(
      std::int64_t session_id, std::optional<std::int64_t> limit = std::nullopt) const;
  std::vector<AlertRecord> alerts(std::int64_t session_id) const;

  // ---- configuration: JSON values by key ----
  void put_config(std::string_view key, const nlohmann::json& value);
  std::optional<nlohmann::json> get_config(std::string_view key) const;

  // ---- retention and health ----
  // Deletes telemetry older than telemetry_retention_days, then the oldest ended sessions
  // (never an open one, never the newest) while size_bytes() > max_size_bytes, then returns
  // the freed pages to the file system.
  RetentionReport apply_retention();
  std::int64_t size_bytes() const;  // live data: (page_count - freelist_count) * page_size
  int schema_version() const;
  std::string path() const;
  std::int64_t write_failures() const { return write_failures_.load(); }
  // Failing or not, since when, and why (with the fix). Cheap: poll it from a health loop.
  WriteHealth write_health() const;
  void set_error_handler(std::function<void(const std::string&)> handler);

 private:
  void open_connection();
  // For log_*: runs `write` (returning the new row id) under the mutex; reports, never throws.
  WriteResult guarded_write(std::string_view what, std::int64_t session_id,
                            const std::function<std::int64_t()>& write);
  // For the other writes: the same, but the failure is then thrown as StorageError.
  void checked_write(std::string_view what, const std::function<void()>& write);
  // call without holding mutex_; `suggestion` is the fix an operator should apply
  void report_failure(const std::string& message, const std::string& suggestion = {},
                      bool disk_full = false);
  void note_write_ok();
  std::int64_t now_ms() const;
  std::int64_t live_size_locked() const;

  StorageOptions options_;
  const contracts::Clock& clock_;
  mutable std::mutex mutex_;  // guards db_
  std::unique_ptr<detail::Connection> db_;
  int schema_version_ = 0;
  std::atomic<std::int64_t> write_failures_{0};
  mutable std::mutex health_mutex_;  // guards health_ and first_ok_
  WriteHealth health_;
  std::optional<contracts::Duration> first_ok_;  // first success since the episode's last failure
  std::mutex handler_mutex_;
  std::function<void(const std::string&)> error_handler_;
};

}  // namespace gbdcs::storage
