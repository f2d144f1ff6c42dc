// Writes that fail are reported, counted and survived; files the process may not write are
// refused at open. The tests run as root in CI, where chmod stops nothing, so each failure
// here is one that genuinely happens to root too (read-only open, a lock held elsewhere, a
// broken foreign key), or runs in a child that has dropped to an unprivileged user.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <functional>
#include <vector>

#include "gbdcs/storage/storage_manager.hpp"
#include "storage_test_support.hpp"

namespace gbdcs::storage {
namespace {

using contracts::ManualClock;
using ::testing::HasSubstr;
using testing::RawDb;
using testing::sample_frame;
using testing::TempDir;

constexpr uid_t kNobody = 65534;

TEST(StorageWriteFailure, ReadOnlyOpenReportsEveryFailedWriteAndKeepsEarlierRows) {
  TempDir dir;
  ManualClock clock;
  const std::string path = dir.file("gbdcs.db");
  std::int64_t session = 0;
  {
    StorageManager db({.path = path}, clock);
    session = db.begin_session(std::nullopt, "twin", "default");
    for (int i = 0; i < 3; ++i)
      ASSERT_TRUE(db.log_telemetry(session, sample_frame(clock.utc_now(), i)));
  }

  StorageManager db({.path = path, .read_only = true}, clock);
  std::vector<std::string> reported;
  db.set_error_handler([&](const std::string& message) { reported.push_back(message); });
  EXPECT_EQ(db.telemetry(session).size(), 3u) << "reads still work";

  const auto result = db.log_gesture(session, contracts::GestureEvent{});
  EXPECT_FALSE(result);
  EXPECT_FALSE(result.ok);
  EXPECT_EQ(result.row_id, 0);
  EXPECT_THAT(result.error, HasSubstr(path));
  EXPECT_THAT(result.error, HasSubstr("readonly"));
  EXPECT_EQ(db.write_failures(), 1);
  ASSERT_EQ(reported.size(), 1u);
  EXPECT_EQ(reported[0], result.error);

  EXPECT_FALSE(db.log_telemetry(session, sample_frame(clock.utc_now(), 9)));
  EXPECT_THROW(db.create_user("alice", "h"), StorageError);
  EXPECT_EQ(db.write_failures(), 3) << "writes that throw are counted too";
  EXPECT_EQ(reported.size(), 3u);

  StorageManager writable({.path = path}, clock);
  const auto rows = writable.telemetry(session);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[2].x_m, sample_frame(clock.utc_now(), 2).x_m);
  EXPECT_TRUE(writable.gestures(session).empty());
}

TEST(StorageWriteFailure, ALockHeldByAnotherProcessFailsTheWriteUntilReleased) {
  TempDir dir;
  ManualClock clock;
  const std::string path = dir.file("gbdcs.db");
  StorageManager db({.path = path, .busy_timeout_ms = 0}, clock);
  const auto session = db.begin_session(std::nullopt, "twin", "default");
  ASSERT_TRUE(db.log_telemetry(session, sample_frame(clock.utc_now(), 0)));

  RawDb other(path);
  other.exec("BEGIN EXCLUSIVE");
  const auto blocked = db.log_telemetry(session, sample_frame(clock.utc_now(), 1));
  EXPECT_FALSE(blocked);
  EXPECT_THAT(blocked.error, HasSubstr("locked"));
  EXPECT_EQ(db.write_failures(), 1);
  other.exec("COMMIT");

  EXPECT_TRUE(db.log_telemetry(session, sample_frame(clock.utc_now(), 2)));
  EXPECT_EQ(db.telemetry(session).size(), 2u);
  EXPECT_EQ(db.write_failures(), 1);
}

TEST(StorageWriteFailure, AnUnknownSessionIsAReportedConstraintFailure) {
  TempDir dir;
  ManualClock clock;
  StorageManager db({.path = dir.file("gbdcs.db")}, clock);
  int calls = 0;
  db.set_error_handler([&](const std::string&) { ++calls; });
  const auto result = db.log_alert(4242, contracts::Alert{});
  EXPECT_FALSE(result);
  EXPECT_THAT(result.error, HasSubstr("FOREIGN KEY"));
  EXPECT_THAT(result.error, HasSubstr("4242"));
  EXPECT_EQ(db.write_failures(), 1);
  EXPECT_EQ(calls, 1);
}

// On a nearly full disk a write that reuses freed space succeeds between failing ones; the
// episode (and the operator's alert) must not flap with it. It ends once writes have
// succeeded for kWriteRecoveryHold with no failure between.
TEST(StorageWriteFailure, AFailingEpisodeEndsOnlyAfterWritesSucceedForTheHold) {
  TempDir dir;
  ManualClock clock;
  StorageManager db({.path = dir.file("gbdcs.db")}, clock);
  const auto session = db.begin_session(std::nullopt, "twin", "default");
  ASSERT_TRUE(db.write_health().ok);
  int frame = 0;
  const auto write_ok = [&] {
    return bool(db.log_telemetry(session, sample_frame(clock.utc_now(), frame++)));
  };
  const auto write_fails = [&] { return !db.log_alert(4242, contracts::Alert{}); };

  ASSERT_TRUE(write_fails());
  EXPECT_FALSE(db.write_health().ok);
  ASSERT_TRUE(write_ok());
  EXPECT_FALSE(db.write_health().ok) << "one success does not end the episode";
  clock.advance(kWriteRecoveryHold / 2);
  ASSERT_TRUE(write_fails());
  clock.advance(kWriteRecoveryHold / 2);
  ASSERT_TRUE(write_ok());
  EXPECT_FALSE(db.write_health().ok) << "the failure between restarted the hold";
  EXPECT_EQ(db.write_health().episodes, 1);
  EXPECT_EQ(db.write_health().episode_failures, 2);

  clock.advance(kWriteRecoveryHold);
  ASSERT_TRUE(write_ok());
  EXPECT_TRUE(db.write_health().ok) << "writes succeeded for the hold";
  EXPECT_EQ(db.write_health().episodes, 1);
  EXPECT_EQ(db.telemetry(session).size(), 3u);

  ASSERT_TRUE(write_fails());
  EXPECT_EQ(db.write_health().episodes, 2) << "a later failure starts a new episode";
}

TEST(StorageWriteFailure, AHandlerThatWritesAndFailsAgainDoesNotRecurse) {
  TempDir dir;
  ManualClock clock;
  StorageManager db({.path = dir.file("gbdcs.db")}, clock);
  int calls = 0;
  db.set_error_handler([&](const std::string&) {
    ++calls;
    // An observer that records the failure as an alert, which fails the same way.
    EXPECT_FALSE(db.log_alert(-1, contracts::Alert{}));
  });
  EXPECT_FALSE(db.log_gesture(-1, contracts::GestureEvent{}));
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(db.write_failures(), 2);
}

// Runs `attempt` in a child process that can no longer write as root would, and returns what
// it returned. When the tests already run unprivileged, runs it here.
std::string as_unprivileged_user(const std::function<std::string()>& attempt) {
  if (::geteuid() != 0) return attempt();
  int fds[2];
  if (::pipe(fds) != 0) return "pipe failed";
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(fds[0]);
    std::string out;
    if (::setgid(kNobody) != 0 || ::setuid(kNobody) != 0) {
      out = "SKIP: cannot drop privileges";
    } else {
      try {
        out = attempt();
      } catch (const std::exception& e) {
        out = std::string("unexpected exception: ") + e.what();
      }
    }
    const ssize_t written = ::write(fds[1], out.data(), out.size());
    ::_exit(written == static_cast<ssize_t>(out.size()) ? 0 : 1);
  }
  ::close(fds[1]);
  std::string out;
  char buf[512];
  ssize_t n = 0;
  while ((n = ::read(fds[0], buf, sizeof buf)) > 0) out.append(buf, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  return out;
}

std::string open_message(const std::string& path) {
  ManualClock clock;
  try {
    StorageManager db({.path = path}, clock);
  } catch (const StorageError& e) {
    return e.what();
  }
  return "opened";
}

TEST(StorageWriteFailure, AReadOnlyFileIsRefusedAtOpen) {
  TempDir dir;
  const std::string path = dir.file("gbdcs.db");
  {
    ManualClock clock;
    StorageManager db({.path = path}, clock);
  }
  namespace fs = std::filesystem;
  fs::permissions(dir.path(), fs::perms::all);  // others may create the -wal and -shm files
  fs::permissions(path, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  const std::string message = as_unprivileged_user([&] { return open_message(path); });
  if (message.starts_with("SKIP")) GTEST_SKIP() << message;
  EXPECT_THAT(message, HasSubstr("cannot write"));
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr("check the permissions or choose another path with --db"));
}

TEST(StorageWriteFailure, AReadOnlyFolderIsRefusedAtOpen) {
  TempDir dir;
  namespace fs = std::filesystem;
  fs::create_directories(dir.file("locked"));
  fs::permissions(dir.file("locked"), fs::perms::owner_all | fs::perms::group_read |
                                          fs::perms::group_exec | fs::perms::others_read |
                                          fs::perms::others_exec);
  const std::string path = dir.file("locked/gbdcs.db");
  const std::string message = as_unprivileged_user([&] { return open_message(path); });
  if (message.starts_with("SKIP")) GTEST_SKIP() << message;
  EXPECT_THAT(message, HasSubstr("cannot write"));
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace gbdcs::storage
