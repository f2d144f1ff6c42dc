// Crash safety and a full disk, on `gbdcs serve` as operators run it (the twin, the real vision
// worker on the demo timeline, SQLite on a temp file):
// - SIGKILL in the middle of a recorded flight: every row that was committed before the kill
//   (read from the database just before it, and everything the dashboard saw on /ws/live) is
//   there afterwards, PRAGMA integrity_check is ok, and the server starts again on the file.
// - The disk fills up mid-flight (RLIMIT_FSIZE lowered on the running server with prlimit(2):
//   the write() that would grow a file fails with EFBIG, as on a full volume): the server
//   raises STORAGE_DISK_FULL naming the cause and the fix, healthz says so, the flight goes on
//   (the failsafe still hovers the drone when the worker dies), nothing stored earlier is lost;
//   once space is back (the limit lifted) writes resume and STORAGE_RECOVERED is raised.
#include <gmock/gmock.h>
#include <sqlite3.h>
#include <sys/resource.h>

#include <cstring>
#include <map>
#include <set>

#include "serve_process_support.hpp"

namespace gbdcs::server::testing {
namespace {

// Every row of the four flight logs, one string per row, by table.
using Rows = std::map<std::string, std::set<std::string>>;
const std::vector<std::string> kTables = {"gestures", "commands", "telemetry", "alerts"};

class Db {
 public:
  explicit Db(const std::string& path) {
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      throw std::runtime_error(std::string("open ") + path + ": " + sqlite3_errmsg(db_));
    }
    sqlite3_busy_timeout(db_, 5000);
  }
  ~Db() { sqlite3_close(db_); }
  std::vector<std::string> rows(const std::string& sql) {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
      throw std::runtime_error(sql + ": " + sqlite3_errmsg(db_));
    }
    std::vector<std::string> out;
    while (sqlite3_step(stmt) == SQLITE_ROW) {
      std::string row;
      for (int c = 0; c < sqlite3_column_count(stmt); ++c) {
        const auto* text = sqlite3_column_text(stmt, c);
        row += (text ? reinterpret_cast<const char*>(text) : "NULL") + std::string("|");
      }
      out.push_back(row);
    }
    sqlite3_finalize(stmt);
    return out;
  }
  Rows snapshot() {
    Rows all;
    for (const auto& t : kTables) {
      all[t];
      for (auto& r : rows("SELECT * FROM " + t + " ORDER BY id")) all[t].insert(std::move(r));
    }
    return all;
  }
  std::int64_t count(const std::string& sql) {
    auto r = rows(sql);
    return r.empty() ? 0 : std::stoll(r[0]);
  }

 private:
  sqlite3* db_ = nullptr;
};

// What the dashboard saw: each row it was told about, by its key in the database.
struct Seen {
  std::set<std::string> telemetry_ts, gesture_ts;
  std::set<std::int64_t> command_ids, alert_ids;
  bool flying = false;
  void note(const json& m) {
    const auto type = m.value("type", "");
    const auto& d = m["data"];
    if (type == "telemetry") {
      telemetry_ts.insert(d["timestamp"].get<std::string>());
      if (d["flight_state"] == "FLYING") flying = true;
    }
    if (type == "gesture") gesture_ts.insert(d["timestamp"].get<std::string>());
    if (type == "command") command_ids.insert(d["command"]["id"].get<std::int64_t>());
    if (type == "alert" && d.value("id", 0) > 0) alert_ids.insert(d["id"].get<std::int64_t>());
  }
};

std::string ms_of(const std::string& utc) {
  return std::to_string(contracts::parse_utc(utc).time_since_epoch().count());
}

void expect_seen_rows_stored(Db& db, const Seen& seen) {
  for (const auto& ts : seen.telemetry_ts) {
    EXPECT_GE(db.count("SELECT count(*) FROM telemetry WHERE ts_ms = " + ms_of(ts)), 1) << ts;
  }
  for (const auto& ts : seen.gesture_ts) {
    EXPECT_GE(db.count("SELECT count(*) FROM gestures WHERE ts_ms = " + ms_of(ts)), 1) << ts;
  }
  for (auto id : seen.command_ids) {
    EXPECT_GE(db.count("SELECT count(*) FROM commands WHERE command_id = " + std::to_string(id)), 1) << id;
  }
  for (auto id : seen.alert_ids) {
    EXPECT_EQ(db.count("SELECT count(*) FROM alerts WHERE id = " + std::to_string(id)), 1) << id;
  }
}

void expect_intact(const std::string& path, const Rows& before) {
  Db db(path);
  EXPECT_EQ(db.rows("PRAGMA integrity_check"), std::vector<std::string>{"ok|"});
  const auto after = db.snapshot();
  for (const auto& [table, rows] : before) {
    std::size_t missing = 0;
    for (const auto& r : rows) missing += after.at(table).count(r) ? 0 : 1;
    EXPECT_EQ(missing, 0u) << table << ": " << missing << " of " << rows.size()
                           << " committed rows are gone";
  }
}

// Reads /ws/live until `done` says so (or 60 s pass without it), noting every row seen.
template <class Done>
bool read_until(WsClient& ws, Seen& seen, Done done, double timeout_s = 90) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < until) {
    auto m = ws.next(20);
    if (!m) return false;
    seen.note(*m);
    if (done(*m)) return true;
  }
  return false;
}

TEST(ServeCrash, SigkillMidFlightLosesNoCommittedRowAndTheServerStartsAgain) {
  TempDir dir;
  const std::string db_path = (dir.path() / "gbdcs.db").string();
  Seen seen;
  Rows before;
  std::int64_t session = 0;
  {
    ServeProcess serve(db_path, {"--adapter", "twin"});
    ASSERT_GT(serve.port, 0);
    WsClient ws;
    ws.connect(serve.port, "/ws/live?token=" + register_and_login(serve.port));
    ASSERT_TRUE(read_until(ws, seen, [&](const json&) { return seen.flying; }));
    // An alert to keep: the worker dies, the server hovers and says so.
    const auto workers = serve.children();
    ASSERT_EQ(workers.size(), 1u);
    ASSERT_EQ(kill(workers[0], SIGKILL), 0);
    ASSERT_TRUE(read_until(ws, seen, [](const json& m) {
      return m["type"] == "alert" && m["data"]["code"] == "VISION_WORKER_LOST";
    }));
    // Keep flying (the restarted worker replays the timeline) while rows keep coming.
    const auto telemetry_then = seen.telemetry_ts.size();
    ASSERT_TRUE(read_until(ws, seen, [&](const json&) { return seen.telemetry_ts.size() >= telemetry_then + 20; }));
    session = http_call(serve.port, "GET", "/api/v1/healthz").doc()["drone"]["session_id"].get<std::int64_t>();
    before = Db(db_path).snapshot();
    // Still writing when the kill comes: read on until one more row lands, then kill.
    ASSERT_TRUE(read_until(ws, seen, [](const json& m) { return m["type"] == "telemetry"; }));
    const int status = serve.stop(SIGKILL);
    ASSERT_TRUE(WIFSIGNALED(status));
  }
  ASSERT_FALSE(before.at("telemetry").empty());
  ASSERT_FALSE(before.at("commands").empty());
  ASSERT_FALSE(before.at("gestures").empty());
  ASSERT_FALSE(before.at("alerts").empty());
  expect_intact(db_path, before);
  {
    Db db(db_path);
    expect_seen_rows_stored(db, seen);
  }
  std::printf("kept after kill -9: %zu telemetry, %zu commands, %zu gestures, %zu alerts\n",
              before["telemetry"].size(), before["commands"].size(), before["gestures"].size(),
              before["alerts"].size());

  // The server starts again on the same file, ends the session the crash left open and serves
  // its record.
  ServeProcess again(db_path, {"--adapter", "twin", "--no-worker"});
  ASSERT_GT(again.port, 0);
  const auto token = register_and_login(again.port, false);
  const auto detail = http_call(again.port, "GET", "/api/v1/sessions/" + std::to_string(session), {}, token);
  ASSERT_EQ(detail.status, 200) << detail.body;
  const auto doc = detail.doc();
  EXPECT_FALSE(doc["session"]["ended_at"].is_null()) << doc["session"].dump();
  EXPECT_GE(doc["commands"].size(), before["commands"].size());
  EXPECT_GE(doc["alerts"].size(), before["alerts"].size());
  EXPECT_EQ(again.stop(SIGTERM), 0);
  expect_intact(db_path, before);
}

// Lowers (or lifts, with RLIM_INFINITY) the largest file the server may write.
void set_file_size_limit(pid_t pid, rlim_t bytes) {
  rlimit limit{};
  ASSERT_EQ(prlimit(pid, RLIMIT_FSIZE, nullptr, &limit), 0);
  limit.rlim_cur = bytes;
  if (bytes == RLIM_INFINITY) limit.rlim_max = RLIM_INFINITY;
  ASSERT_EQ(prlimit(pid, RLIMIT_FSIZE, &limit, nullptr), 0) << std::strerror(errno);
}

TEST(ServeDiskFull, WritesFailClearlyTheFlightGoesOnAndNothingEarlierIsLost) {
  TempDir dir;
  const std::string db_path = (dir.path() / "gbdcs.db").string();
  Seen seen;
  ServeProcess serve(db_path, {"--adapter", "twin"});
  ASSERT_GT(serve.port, 0);
  WsClient ws;
  ws.connect(serve.port, "/ws/live?token=" + register_and_login(serve.port));
  ASSERT_TRUE(read_until(ws, seen, [&](const json&) { return seen.flying; }));

  // The volume is nearly full: the files may not grow past a few pages more than now.
  namespace fs = std::filesystem;
  const auto size_of = [](const std::string& p) { return fs::exists(p) ? fs::file_size(p) : 0; };
  const auto biggest = std::max(size_of(db_path), size_of(db_path + "-wal"));
  set_file_size_limit(serve.pid, static_cast<rlim_t>(biggest + 16 * 1024));
  const Rows before_full = Db(db_path).snapshot();

  json full_alert;
  ASSERT_TRUE(read_until(ws, seen, [&](const json& m) {
    if (m["type"] == "alert" && m["data"]["code"] == "STORAGE_DISK_FULL") full_alert = m["data"];
    return !full_alert.is_null();
  })) << "no STORAGE_DISK_FULL alert";
  EXPECT_EQ(full_alert["severity"], "WARNING");
  EXPECT_THAT(full_alert["cause"].get<std::string>(), ::testing::HasSubstr(db_path));
  EXPECT_THAT(full_alert["suggestion"].get<std::string>(), ::testing::HasSubstr("free disk space"));
  const auto health = http_call(serve.port, "GET", "/api/v1/healthz").doc();
  EXPECT_TRUE(contracts::violations("api_health", health).empty()) << health.dump();
  EXPECT_EQ(health["status"], "degraded");
  EXPECT_EQ(health["db"]["writable"], false);
  EXPECT_EQ(health["db"]["disk_full"], true);
  EXPECT_THAT(health["db"]["suggestion"].get<std::string>(), ::testing::HasSubstr("free disk space"));
  EXPECT_FALSE(serve.log_lines("\"storage_failing\"").empty()) << "the failure is logged";

  // The flight goes on: the worker dies, the failsafe still hovers the drone, telemetry flows.
  const auto workers = serve.children();
  ASSERT_EQ(workers.size(), 1u);
  ASSERT_EQ(kill(workers[0], SIGKILL), 0);
  bool hover = false, lost = false;
  ASSERT_TRUE(read_until(ws, seen, [&](const json& m) {
    if (m["type"] == "command" && m["data"]["command"]["type"] == "HOVER" &&
        m["data"]["command"]["source"] == "failsafe" && m["data"]["outcome"] == "OK") {
      hover = true;
    }
    if (m["type"] == "alert" && m["data"]["code"] == "VISION_WORKER_LOST") lost = true;
    return hover && lost;
  }));
  const auto telemetry_then = seen.telemetry_ts.size();
  ASSERT_TRUE(read_until(ws, seen, [&](const json&) { return seen.telemetry_ts.size() >= telemetry_then + 5; }));
  EXPECT_EQ(http_call(serve.port, "GET", "/api/v1/healthz").doc()["db"]["writable"], false);

  // Space comes back: writes resume and the operator is told.
  set_file_size_limit(serve.pid, RLIM_INFINITY);
  ASSERT_TRUE(read_until(ws, seen, [](const json& m) {
    return m["type"] == "alert" && m["data"]["code"] == "STORAGE_RECOVERED";
  }));
  const auto healthy = http_call(serve.port, "GET", "/api/v1/healthz").doc();
  EXPECT_EQ(healthy["db"]["writable"], true) << healthy.dump();
  EXPECT_GT(healthy["db"]["write_failures"].get<std::int64_t>(), 0);
  const auto session = healthy["drone"]["session_id"].get<std::int64_t>();
  EXPECT_EQ(serve.stop(SIGTERM), 0);

  expect_intact(db_path, before_full);
  Db db(db_path);
  EXPECT_GT(db.count("SELECT count(*) FROM alerts WHERE code = 'STORAGE_RECOVERED' AND session_id = " +
                     std::to_string(session)),
            0)
      << "rows are recorded again after recovery";
}

}  // namespace
}  // namespace gbdcs::server::testing
