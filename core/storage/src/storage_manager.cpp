// StorageManager: opening, users, sessions, configuration and the write-failure plumbing.
// The logs live in storage_logs.cpp, retention in retention.cpp.
#include "gbdcs/storage/storage_manager.hpp"

#include <algorithm>
#include <filesystem>
#include <utility>

#include "migrations.hpp"
#include "open_errors.hpp"
#include "row_helpers.hpp"
#include "sqlite_connection.hpp"

namespace gbdcs::storage {

using detail::from_ms;
using detail::Query;

namespace {

constexpr std::string_view kInMemoryPath = ":memory:";

constexpr std::string_view kSessionSummarySelect = R"sql(
SELECT s.id, s.user_id, s.drone, s.profile, s.started_at_ms, s.ended_at_ms,
       (SELECT count(*) FROM commands c WHERE c.session_id = s.id),
       (SELECT count(*) FROM alerts a WHERE a.session_id = s.id)
FROM sessions s)sql";

SessionSummary read_summary(detail::Statement& row, std::int64_t now_ms) {
  SessionSummary s;
  s.id = row.int64(0);
  s.user_id = row.optional_int64(1);
  s.drone = row.text(2);
  s.profile = row.text(3);
  const std::int64_t started_ms = row.int64(4);
  const auto ended_ms = row.optional_int64(5);
  s.started_at = from_ms(started_ms);
  s.ended_at = from_ms(ended_ms);
  const std::int64_t duration_ms =
      std::max<std::int64_t>(0, ended_ms.value_or(now_ms) - started_ms);
  s.duration_s = static_cast<double>(duration_ms) / 1000.0;
  s.command_count = row.int64(6);
  s.alert_count = row.int64(7);
  return s;
}

}  // namespace

StorageManager::StorageManager(StorageOptions options, const contracts::Clock& clock)
    : options_(std::move(options)), clock_(clock) {
  if (options_.path.empty()) {
    throw StorageError("no database path given: set storage.path or pass --db");
  }
  if (options_.path != kInMemoryPath && !options_.read_only) {
    detail::create_parent_directories(options_.path);
  }
  if (options_.read_only && !std::filesystem::exists(options_.path)) {
    throw StorageError("database " + options_.path +
                       " does not exist (a read-only open never creates one): check the path "
                       "or choose another path with --db");
  }
  try {
    open_connection();
  } catch (const detail::SqliteError& e) {
    db_.reset();
    throw detail::open_error(options_.path, e);
  }
}

StorageManager::~StorageManager() = default;

void StorageManager::open_connection() {
  const std::string& path = options_.path;
  db_ = std::make_unique<detail::Connection>(path, options_.read_only);
  db_->set_busy_timeout(options_.busy_timeout_ms);
  // The first read of page 1 is where SQLite notices a file that is not a database.
  const std::int64_t page_count = db_->scalar_int64("PRAGMA page_count");
  if (!options_.read_only) {
    // Asked for read-write but the file refused (e.g. mode 0444 for a non-root user).
    if (db_->is_read_only()) throw detail::cannot_write_error(path, "the file is read-only");
    // Only possible before the first table exists; lets retention give space back.
    if (page_count == 0) db_->exec("PRAGMA auto_vacuum = INCREMENTAL");
    if (path != kInMemoryPath) {
      const std::string mode = db_->scalar_text("PRAGMA journal_mode = WAL");
      if (mode != "wal") {
        throw detail::cannot_write_error(path,
                                         "cannot switch to WAL journal mode, still '" + mode + "'");
      }
    }
    // FULL: with WAL, a commit is on disk when the call returns, so kill -9 or power loss
    // loses nothing that was reported written.
    db_->exec("PRAGMA synchronous = FULL");
  }
  db_->exec("PRAGMA foreign_keys = ON");

  {
    Query check = db_->query("PRAGMA quick_check");
    std::string problems;
    while (check->step()) {
      const std::string line = check->text(0);
      if (line == "ok") continue;
      if (!problems.empty()) problems += "; ";
      problems += line;
    }
    if (!problems.empty()) {
      throw detail::not_a_database_error(path, "quick_check: " + problems.substr(0, 300));
    }
  }
  schema_version_ = detail::migrate(*db_, path, now_ms(), options_.read_only);
}

// ---- write plumbing -------------------------------------------------------------------

WriteResult StorageManager::guarded_write(std::string_view what, std::int64_t session_id,
                                          const std::function<std::int64_t()>& write) {
  WriteResult result;
  detail::WriteFailureKind kind;
  try {
    std::lock_guard lock(mutex_);
    result.row_id = write();
  } catch (const detail::SqliteError& e) {
    kind = detail::classify_write_failure(options_.path, e);
    result.ok = false;
    result.row_id = 0;
    result.error = "cannot " + std::string(what) + " for session " + std::to_string(session_id) +
                   " in " + options_.path + ": " + e.what() +
                   (kind.suggestion.empty() ? "" : " (" + kind.suggestion + ")");
  } catch (const std::exception& e) {
    result.ok = false;
    result.row_id = 0;
    result.error = "cannot " + std::string(what) + " for session " + std::to_string(session_id) +
                   " in " + options_.path + ": " + e.what();
  }
  if (!result.ok) {
    report_failure(result.error, kind.suggestion, kind.disk_full);
  } else {
    note_write_ok();
  }
  return result;
}

void StorageManager::checked_write(std::string_view what, const std::function<void()>& write) {
  std::string error;
  detail::WriteFailureKind kind;
  try {
    {
      std::lock_guard lock(mutex_);
      write();
    }
    note_write_ok();
    return;
  } catch (const detail::SqliteError& e) {
    kind = detail::classify_write_failure(options_.path, e);
    error = "cannot " + std::string(what) + " in " + options_.path + ": " + e.what() +
            (kind.suggestion.empty() ? "" : " (" + kind.suggestion + ")");
  } catch (const std::exception& e) {
    error = "cannot " + std::string(what) + " in " + options_.path + ": " + e.what();
  }
  report_failure(error, kind.suggestion, kind.disk_full);
  throw StorageError(error);
}

void StorageManager::note_write_ok() {
  std::lock_guard lock(health_mutex_);
  if (health_.ok) return;
  const contracts::Duration now = clock_.now();
  if (!first_ok_) first_ok_ = now;
  if (now - *first_ok_ >= kWriteRecoveryHold) {
    health_.ok = true;
    first_ok_.reset();
  }
}

WriteHealth StorageManager::write_health() const {
  std::lock_guard lock(health_mutex_);
  return health_;
}

void StorageManager::report_failure(const std::string& message, const std::string& suggestion,
                                    bool disk_full) {
  write_failures_.fetch_add(1);
  {
    std::lock_guard lock(health_mutex_);
    if (health_.ok) {  // a new episode: remember its first failure
      health_.ok = false;
      health_.error = message;
      health_.suggestion = suggestion;
      health_.disk_full = disk_full;
      health_.episode_failures = 0;
      ++health_.episodes;
    }
    ++health_.failures;
    ++health_.episode_failures;
    first_ok_.reset();
  }
  // A handler that logs to this store and fails again must not recurse without end.
  thread_local bool in_handler = false;
  if (in_handler) return;
  std::function<void(const std::string&)> handler;
  {
    std::lock_guard lock(handler_mutex_);
    handler = error_handler_;
  }
  if (!handler) return;
  in_handler = true;
  try {
    handler(message);
  } catch (...) {
    // The log_* calls promise not to throw; a faulty handler must not break that promise.
  }
  in_handler = false;
}

void StorageManager::set_error_handler(std::function<void(const std::string&)> handler) {
  std::lock_guard lock(handler_mutex_);
  error_handler_ = std::move(handler);
}

std::int64_t StorageManager::now_ms() const {
  return detail::to_ms(clock_.utc_now());
}

std::string StorageManager::path() const {
  return options_.path;
}

int StorageManager::schema_version() const {
  return schema_version_;
}

// ---- users ----------------------------------------------------------------------------

std::optional<std::int64_t> StorageManager::create_user(std::string_view username,
                                                        std::string_view password_hash) {
  std::optional<std::int64_t> id;
  checked_write("create user '" + std::string(username) + "'", [&] {
    Query q = db_->query(
        "INSERT INTO users (username, password_hash, created_at_ms) VALUES (?1, ?2, ?3) "
        "ON CONFLICT (username) DO NOTHING");
    q->bind(1, username);
    q->bind(2, password_hash);
    q->bind(3, now_ms());
    q->step();
    if (db_->changes() > 0) id = db_->last_insert_rowid();
  });
  return id;
}

std::optional<UserRecord> StorageManager::find_user(std::string_view username) const {
  return detail::locked_read(mutex_, options_.path, "user", [&]() -> std::optional<UserRecord> {
    Query q = db_->query(
        "SELECT id, username, password_hash, theme, created_at_ms FROM users WHERE username = ?1");
    q->bind(1, username);
    if (!q->step()) return std::nullopt;
    return detail::user_from_row(q);
  });
}

bool StorageManager::set_user_theme(std::int64_t user_id, std::string_view theme) {
  bool found = false;
  checked_write("set the theme of user " + std::to_string(user_id), [&] {
    Query q = db_->query("UPDATE users SET theme = ?2 WHERE id = ?1");
    q->bind(1, user_id);
    q->bind(2, theme);
    q->step();
    found = db_->changes() > 0;
  });
  return found;
}

// ---- sessions -------------------------------------------------------------------------

std::int64_t StorageManager::begin_session(std::optional<std::int64_t> user_id, std::string drone,
                                           std::string profile) {
  std::int64_t id = 0;
  checked_write("begin a session", [&] {
    Query q = db_->query(
        "INSERT INTO sessions (user_id, drone, profile, started_at_ms) VALUES (?1, ?2, ?3, ?4)");
    q->bind(1, user_id);
    q->bind(2, std::string_view(drone));
    q->bind(3, std::string_view(profile));
    q->bind(4, now_ms());
    q->step();
    id = db_->last_insert_rowid();
  });
  return id;
}

bool StorageManager::end_session(std::int64_t session_id) {
  bool ended = false;
  checked_write("end session " + std::to_string(session_id), [&] {
    Query q = db_->query(
        "UPDATE sessions SET ended_at_ms = max(started_at_ms, ?2) "
        "WHERE id = ?1 AND ended_at_ms IS NULL");
    q->bind(1, session_id);
    q->bind(2, now_ms());
    q->step();
    ended = db_->changes() > 0;
  });
  return ended;
}

std::int64_t StorageManager::end_open_sessions() {
  std::int64_t count = 0;
  checked_write("end the sessions left open", [&] {
    // The last thing a crashed session logged is the best estimate of when it ended.
    db_->exec(R"sql(
UPDATE sessions SET ended_at_ms = max(started_at_ms,
    coalesce((SELECT max(ts_ms) FROM telemetry t WHERE t.session_id = sessions.id), 0),
    coalesce((SELECT max(ts_ms) FROM gestures g WHERE g.session_id = sessions.id), 0),
    coalesce((SELECT max(recorded_at_ms) FROM commands c WHERE c.session_id = sessions.id), 0),
    coalesce((SELECT max(ts_ms) FROM alerts a WHERE a.session_id = sessions.id), 0))
WHERE ended_at_ms IS NULL)sql");
    count = db_->changes();
  });
  return count;
}

std::vector<SessionSummary> StorageManager::list_sessions(std::int64_t limit,
                                                          std::int64_t offset) const {
  return detail::locked_read(mutex_, options_.path, "sessions", [&] {
    static const std::string sql = std::string(kSessionSummarySelect) +
                                   " ORDER BY s.started_at_ms DESC, s.id DESC LIMIT ?1 OFFSET ?2";
    Query q = db_->query(sql);
    q->bind(1, std::max<std::int64_t>(0, limit));
    q->bind(2, std::max<std::int64_t>(0, offset));
    const std::int64_t now = now_ms();
    std::vector<SessionSummary> out;
    while (q->step()) out.push_back(read_summary(*q, now));
    return out;
  });
}

std::optional<SessionSummary> StorageManager::get_session(std::int64_t session_id) const {
  return detail::locked_read(
      mutex_, options_.path, "session", [&]() -> std::optional<SessionSummary> {
        static const std::string sql = std::string(kSessionSummarySelect) + " WHERE s.id = ?1";
        Query q = db_->query(sql);
        q->bind(1, session_id);
        if (!q->step()) return std::nullopt;
        return read_summary(*q, now_ms());
      });
}

std::int64_t StorageManager::session_count() const {
  return detail::locked_read(mutex_, options_.path, "the session count",
                             [&] { return db_->scalar_int64("SELECT count(*) FROM sessions"); });
}

// ---- configuration --------------------------------------------------------------------

void StorageManager::put_config(std::string_view key, const nlohmann::json& value) {
  // Serialise before taking the lock: it is the slow part, and it throws on invalid UTF-8.
  std::string text;
  try {
    text = value.dump();
  } catch (const nlohmann::json::exception& e) {
    throw StorageError("config '" + std::string(key) + "' cannot be stored: " + e.what());
  }
  checked_write("store config '" + std::string(key) + "'", [&] {
    Query q = db_->query(
        "INSERT INTO config (key, value, updated_at_ms) VALUES (?1, ?2, ?3) "
        "ON CONFLICT (key) DO UPDATE SET value = excluded.value, "
        "updated_at_ms = excluded.updated_at_ms");
    q->bind(1, key);
    q->bind(2, std::string_view(text));
    q->bind(3, now_ms());
    q->step();
  });
}

std::optional<nlohmann::json> StorageManager::get_config(std::string_view key) const {
  return detail::locked_read(mutex_, options_.path, "config '" + std::string(key) + "'",
                             [&]() -> std::optional<nlohmann::json> {
                               Query q = db_->query("SELECT value FROM config WHERE key = ?1");
                               q->bind(1, key);
                               if (!q->step()) return std::nullopt;
                               return nlohmann::json::parse(q->text(0));
                             });
}

}  // namespace gbdcs::storage
