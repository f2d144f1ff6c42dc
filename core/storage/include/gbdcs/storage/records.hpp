// The rows StorageManager hands back, and the results of its writes and of retention.
// Times are contracts::UtcTime (milliseconds since the Unix epoch, UTC), as stored.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::storage {

// The outcome of a log_* call. A failed write is never silent: `error` says what failed and
// why, and the manager also counts it and calls its error handler.
struct WriteResult {
  bool ok = true;
  std::string error;
  std::int64_t row_id = 0;  // the inserted row's id when ok (for alerts: the id to acknowledge)
  explicit operator bool() const { return ok; }
};

struct UserRecord {
  std::int64_t id = 0;
  std::string username;
  std::string password_hash;  // opaque to storage (libsodium's string, produced by the server)
  std::string theme = "light";
  contracts::UtcTime created_at{};
};

struct SessionSummary {
  std::int64_t id = 0;
  std::optional<std::int64_t> user_id;
  std::string drone;
  std::string profile;
  contracts::UtcTime started_at{};
  std::optional<contracts::UtcTime> ended_at;  // empty while the session is open
  double duration_s = 0;  // to ended_at, or to the clock's utc_now() while open
  std::int64_t command_count = 0;
  std::int64_t alert_count = 0;
};

// A logged command. command.issued_at is when it was issued; recorded_at is when it was
// logged with its result (the injected clock's utc_now()).
struct CommandRecord {
  contracts::DroneCommand command;
  std::string result;
  contracts::UtcTime recorded_at{};
};

// A logged alert. alert.id is the storage row id (the one acknowledge_alert takes), not the id
// the alert carried when it was logged: in-memory ids restart with the process.
struct AlertRecord {
  contracts::Alert alert;
  std::optional<contracts::UtcTime> acknowledged_at;
};

// Whether writes currently succeed, for health checks and alerts. A failing episode starts
// with the first failed write and ends once writes have succeeded for kWriteRecoveryHold
// (2 s) with no failure between.
inline constexpr contracts::Duration kWriteRecoveryHold = std::chrono::seconds(2);

struct WriteHealth {
  bool ok = true;               // no failing episode (none yet, or the last one has ended)
  bool disk_full = false;       // the failing writes ran out of space (ENOSPC, EFBIG, SQLITE_FULL)
  std::string error;            // the first failure of the current (or last) episode
  std::string suggestion;       // the fix for that failure, for an operator
  std::int64_t failures = 0;    // every failed write since open
  std::int64_t episode_failures = 0;  // failed writes in the current (or last) episode
  std::int64_t episodes = 0;    // how many failing episodes began since open
};

struct RetentionReport {
  std::int64_t telemetry_rows_deleted = 0;  // by age
  std::int64_t sessions_deleted = 0;        // by size, with all their rows
  std::int64_t size_before_bytes = 0;       // live data: (page_count - freelist_count) * page_size
  std::int64_t size_after_bytes = 0;
};

}  // namespace gbdcs::storage
