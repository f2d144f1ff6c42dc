// Retention: telemetry by age (on the injected clock), sessions by size, oldest first, never an
// open session nor the newest, and the space actually handed back.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "gbdcs/storage/storage_manager.hpp"
#include "storage_test_support.hpp"

namespace gbdcs::storage {
namespace {

using namespace std::chrono_literals;
using contracts::ManualClock;
using testing::RawDb;
using testing::sample_frame;
using testing::TempDir;

constexpr auto kDay = std::chrono::hours(24);

TEST(StorageRetention, DeletesOnlyTelemetryOlderThanTheRetentionDays) {
  TempDir dir;
  ManualClock clock;
  StorageManager db({.path = dir.file("gbdcs.db"), .telemetry_retention_days = 30}, clock);
  const auto t0 = clock.utc_now();
  const auto old_session = db.begin_session(std::nullopt, "twin", "default");
  for (int i = 0; i < 5; ++i)
    ASSERT_TRUE(db.log_telemetry(old_session, sample_frame(t0 + i * 200ms, i)));
  ASSERT_TRUE(db.log_telemetry(old_session, sample_frame(t0 + 2 * kDay, 100)));
  ASSERT_TRUE(db.log_gesture(old_session, contracts::GestureEvent{.timestamp = t0}));
  ASSERT_TRUE(db.end_session(old_session));

  clock.advance(31 * kDay);
  const auto new_session = db.begin_session(std::nullopt, "twin", "default");
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(db.log_telemetry(new_session, sample_frame(clock.utc_now() + i * 200ms, i)));
  }

  const RetentionReport report = db.apply_retention();
  EXPECT_EQ(report.telemetry_rows_deleted, 5);
  EXPECT_EQ(report.sessions_deleted, 0) << "far under the size cap";
  const auto kept = db.telemetry(old_session);
  ASSERT_EQ(kept.size(), 1u) << "29 days old is inside the window";
  EXPECT_EQ(kept[0].timestamp, t0 + 2 * kDay);
  EXPECT_EQ(db.telemetry(new_session).size(), 3u);
  EXPECT_EQ(db.gestures(old_session).size(), 1u) << "age retention is for telemetry only";
  EXPECT_EQ(db.session_count(), 2);

  clock.advance(kDay);  // the 29-day frame is now exactly 30 days old: still kept
  EXPECT_EQ(db.apply_retention().telemetry_rows_deleted, 0);
  clock.advance(1ms);
  EXPECT_EQ(db.apply_retention().telemetry_rows_deleted, 1);
  EXPECT_EQ(db.apply_retention().telemetry_rows_deleted, 0);
}

// Sessions with enough telemetry to span many pages each, laid down one after the other.
std::vector<std::int64_t> fill_sessions(StorageManager& db, ManualClock& clock, int count,
                                        int frames, bool end_them) {
  std::vector<std::int64_t> ids;
  for (int s = 0; s < count; ++s) {
    const auto id = db.begin_session(std::nullopt, "twin", "default");
    for (int i = 0; i < frames; ++i) {
      clock.advance(200ms);
      EXPECT_TRUE(db.log_telemetry(id, sample_frame(clock.utc_now(), i)));
    }
    EXPECT_TRUE(db.log_command(id, contracts::DroneCommand{}, "OK"));
    EXPECT_TRUE(db.log_alert(id, contracts::Alert{}));
    if (end_them) {
      EXPECT_TRUE(db.end_session(id));
    }
    ids.push_back(id);
  }
  return ids;
}

TEST(StorageRetention, SizeCapDeletesTheOldestEndedSessionsFirst) {
  TempDir dir;
  ManualClock clock;
  const std::string path = dir.file("gbdcs.db");
  StorageOptions options{.path = path};
  std::int64_t open_old = 0;
  std::vector<std::int64_t> ended;
  std::int64_t open_new = 0;
  std::int64_t full_size = 0;
  {
    StorageManager db(options, clock);
    open_old = fill_sessions(db, clock, 1, 500, false)[0];  // left open by a crash, say
    ended = fill_sessions(db, clock, 5, 1500, true);
    open_new = fill_sessions(db, clock, 1, 1500, false)[0];
    full_size = db.size_bytes();
  }
  const auto file_before = std::filesystem::file_size(path);

  // Room for roughly half of the ended sessions.
  const std::int64_t per_session = full_size / 7;
  options.max_size_bytes = full_size - per_session * 5 / 2;
  StorageManager db(options, clock);
  const RetentionReport report = db.apply_retention();

  EXPECT_EQ(report.size_before_bytes, full_size);
  EXPECT_LE(report.size_after_bytes, options.max_size_bytes);
  EXPECT_EQ(report.size_after_bytes, db.size_bytes());
  EXPECT_GE(report.sessions_deleted, 2);
  EXPECT_LT(report.sessions_deleted, 5);
  EXPECT_EQ(report.telemetry_rows_deleted, 0);

  // Exactly the oldest `sessions_deleted` ended sessions are gone, with their rows.
  for (std::size_t i = 0; i < ended.size(); ++i) {
    const bool should_be_gone = static_cast<std::int64_t>(i) < report.sessions_deleted;
    EXPECT_EQ(db.get_session(ended[i]).has_value(), !should_be_gone) << "session " << ended[i];
    EXPECT_EQ(db.telemetry(ended[i]).size(), should_be_gone ? 0u : 1500u);
    EXPECT_EQ(db.commands(ended[i]).size(), should_be_gone ? 0u : 1u);
  }
  EXPECT_EQ(db.telemetry(open_old).size(), 500u);
  EXPECT_EQ(db.telemetry(open_new).size(), 1500u);

  // The file itself shrank: freed pages went back to the file system.
  EXPECT_LT(std::filesystem::file_size(path), file_before);
  RawDb raw(path);
  EXPECT_EQ(raw.text("PRAGMA integrity_check"), "ok");
  EXPECT_EQ(raw.integer("SELECT count(*) FROM alerts WHERE session_id NOT IN "
                        "(SELECT id FROM sessions)"),
            0);
}

TEST(StorageRetention, NeverDeletesAnOpenSessionOrTheNewest) {
  TempDir dir;
  ManualClock clock;
  StorageManager db({.path = dir.file("gbdcs.db"), .max_size_bytes = 1}, clock);
  const auto open_old = fill_sessions(db, clock, 1, 300, false)[0];
  const auto ended = fill_sessions(db, clock, 3, 300, true);

  const RetentionReport report = db.apply_retention();
  EXPECT_EQ(report.sessions_deleted, 2);
  EXPECT_LT(report.size_after_bytes, report.size_before_bytes);
  EXPECT_GT(report.size_after_bytes, 1) << "the cap cannot be met; what is protected stays";
  EXPECT_FALSE(db.get_session(ended[0]).has_value());
  EXPECT_FALSE(db.get_session(ended[1]).has_value());
  ASSERT_TRUE(db.get_session(ended[2]).has_value()) << "the newest, though ended";
  EXPECT_EQ(db.telemetry(ended[2]).size(), 300u);
  ASSERT_TRUE(db.get_session(open_old).has_value());
  EXPECT_EQ(db.telemetry(open_old).size(), 300u);

  EXPECT_EQ(db.apply_retention().sessions_deleted, 0) << "nothing more may go";
}

}  // namespace
}  // namespace gbdcs::storage
