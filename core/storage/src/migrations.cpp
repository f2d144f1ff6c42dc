#include "migrations.hpp"

#include <array>

#include "gbdcs/storage/storage_options.hpp"

namespace gbdcs::storage::detail {

namespace {

// Times are INTEGER milliseconds since the Unix epoch, UTC (see storage_manager.hpp).
// Enums are stored as their contract strings ("OPEN_PALM", "TAKEOFF", ...), so reordering a
// C++ enum can never reinterpret old rows. Never edit a released step: add a new one.
constexpr std::string_view kInitialSchema = R"sql(
CREATE TABLE users (
  id             INTEGER PRIMARY KEY AUTOINCREMENT,
  username       TEXT    NOT NULL UNIQUE COLLATE NOCASE,
  password_hash  TEXT    NOT NULL,
  theme          TEXT    NOT NULL DEFAULT 'light',
  created_at_ms  INTEGER NOT NULL
);

CREATE TABLE sessions (
  id             INTEGER PRIMARY KEY AUTOINCREMENT,
  user_id        INTEGER REFERENCES users(id) ON DELETE SET NULL,
  drone          TEXT    NOT NULL,
  profile        TEXT    NOT NULL,
  started_at_ms  INTEGER NOT NULL,
  ended_at_ms    INTEGER
);
CREATE INDEX sessions_started ON sessions(started_at_ms);
CREATE INDEX sessions_user ON sessions(user_id);

CREATE TABLE gestures (
  id          INTEGER PRIMARY KEY,
  session_id  INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  ts_ms       INTEGER NOT NULL,
  gesture     TEXT    NOT NULL,
  confidence  REAL    NOT NULL,
  handedness  TEXT    NOT NULL,
  frame_id    INTEGER NOT NULL,
  repeat      INTEGER NOT NULL CHECK (repeat IN (0, 1))
);
CREATE INDEX gestures_session_ts ON gestures(session_id, ts_ms);

-- ts_ms is DroneCommand.issued_at; recorded_at_ms is when the result was logged.
CREATE TABLE commands (
  id              INTEGER PRIMARY KEY,
  session_id      INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  ts_ms           INTEGER NOT NULL,
  recorded_at_ms  INTEGER NOT NULL,
  command_id      INTEGER NOT NULL,
  type            TEXT    NOT NULL,
  source          TEXT    NOT NULL,
  source_id       TEXT    NOT NULL,
  payload         TEXT    CHECK (payload IS NULL OR json_valid(payload)),
  result          TEXT    NOT NULL
);
CREATE INDEX commands_session_ts ON commands(session_id, ts_ms);

CREATE TABLE telemetry (
  id            INTEGER PRIMARY KEY,
  session_id    INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  ts_ms         INTEGER NOT NULL,
  altitude_m    REAL    NOT NULL,
  speed_m_s     REAL    NOT NULL,
  vx_m_s        REAL    NOT NULL,
  vy_m_s        REAL    NOT NULL,
  vz_m_s        REAL    NOT NULL,
  x_m           REAL    NOT NULL,
  y_m           REAL    NOT NULL,
  heading_deg   REAL    NOT NULL,
  battery_pct   REAL    NOT NULL,
  flight_state  TEXT    NOT NULL,
  link          TEXT    NOT NULL
);
CREATE INDEX telemetry_session_ts ON telemetry(session_id, ts_ms);
-- Age-based retention deletes across sessions by time alone.
CREATE INDEX telemetry_ts ON telemetry(ts_ms);

CREATE TABLE alerts (
  id                  INTEGER PRIMARY KEY AUTOINCREMENT,
  session_id          INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  ts_ms               INTEGER NOT NULL,
  severity            TEXT    NOT NULL,
  code                TEXT    NOT NULL,
  cause               TEXT    NOT NULL,
  suggestion          TEXT    NOT NULL,
  acknowledged_at_ms  INTEGER
);
CREATE INDEX alerts_session_ts ON alerts(session_id, ts_ms);

CREATE TABLE config (
  key            TEXT    PRIMARY KEY,
  value          TEXT    NOT NULL CHECK (json_valid(value)),
  updated_at_ms  INTEGER NOT NULL
);
)sql";

// The server's auth: logged-out tokens stay refused until they would have expired anyway;
// who acknowledged an alert.
constexpr std::string_view kServerAuth = R"sql(
CREATE TABLE revoked_tokens (
  jti            TEXT    PRIMARY KEY,
  user_id        INTEGER REFERENCES users(id) ON DELETE CASCADE,
  expires_at_ms  INTEGER NOT NULL,
  revoked_at_ms  INTEGER NOT NULL
);
CREATE INDEX revoked_tokens_expiry ON revoked_tokens(expires_at_ms);
ALTER TABLE alerts ADD COLUMN acknowledged_by INTEGER REFERENCES users(id) ON DELETE SET NULL;
)sql";

constexpr std::array<Migration, 2> kMigrations = {{
    {1, "initial schema", kInitialSchema},
    {2, "server auth: revoked tokens, alert acknowledged_by", kServerAuth},
}};

constexpr std::string_view kCreateMigrationsTable = R"sql(
CREATE TABLE IF NOT EXISTS schema_migrations (
  version        INTEGER PRIMARY KEY,
  name           TEXT    NOT NULL,
  applied_at_ms  INTEGER NOT NULL
))sql";

bool has_table(Connection& db, std::string_view name) {
  Query q = db.query("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?1");
  q->bind(1, name);
  return q->step();
}

}  // namespace

std::span<const Migration> migrations() {
  return kMigrations;
}

int latest_schema_version() {
  return kMigrations.back().version;
}

int applied_schema_version(Connection& db) {
  if (!has_table(db, "schema_migrations")) return 0;
  return static_cast<int>(
      db.scalar_int64("SELECT coalesce(max(version), 0) FROM schema_migrations"));
}

int migrate(Connection& db, const std::string& path, std::int64_t now_ms, bool read_only) {
  const int latest = latest_schema_version();
  int current = applied_schema_version(db);
  if (current > latest) {
    throw StorageError("database " + path + " has schema version " + std::to_string(current) +
                       ", newer than this gbdcs knows (" + std::to_string(latest) +
                       "): run a newer gbdcs, or choose another path with --db");
  }
  if (current == 0 && db.scalar_int64("SELECT count(*) FROM sqlite_master") > 0) {
    throw StorageError("database " + path +
                       " is an SQLite database but not a GBDCS one (it has tables but no "
                       "schema_migrations): choose another path with --db");
  }
  if (current == latest) return current;
  if (read_only) {
    throw StorageError("database " + path + " is at schema version " + std::to_string(current) +
                       " and needs migrating to " + std::to_string(latest) +
                       ", which a read-only open cannot do: open it once without read_only");
  }
  for (const Migration& step : kMigrations) {
    if (step.version <= current) continue;
    try {
      Transaction tx(db);
      db.exec(kCreateMigrationsTable);
      // Another process may have migrated while we waited for the write lock.
      if (applied_schema_version(db) >= step.version) continue;
      db.exec(step.sql);
      Query record = db.query(
          "INSERT INTO schema_migrations (version, name, applied_at_ms) VALUES (?1, ?2, ?3)");
      record->bind(1, step.version);
      record->bind(2, step.name);
      record->bind(3, now_ms);
      record->step();
      tx.commit();
    } catch (const SqliteError& e) {
      throw SqliteError(e.code(), e.system_errno(),
                        "migration " + std::to_string(step.version) + " (" +
                            std::string(step.name) + ") failed: " + e.what());
    }
  }
  return applied_schema_version(db);
}

}  // namespace gbdcs::storage::detail
