// kill -9 in the middle of logging: everything a log_* call returned ok for is in the file,
// and the file is intact.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <set>

#include "gbdcs/storage/storage_manager.hpp"
#include "storage_test_support.hpp"

namespace gbdcs::storage {
namespace {

using namespace std::chrono_literals;
using contracts::ManualClock;
using testing::RawDb;
using testing::sample_frame;
using testing::TempDir;

constexpr std::size_t kAcksBeforeKill = 300;
constexpr int kPollTimeoutMs = 60'000;

// The child: opens the database, reports the session id, then logs without end, reporting
// each row's index once its log_* call has returned ok. Never returns.
[[noreturn]] void write_until_killed(const std::string& path, int report_fd) {
  try {
    ManualClock clock;
    StorageManager db({.path = path}, clock);
    const std::int64_t session = db.begin_session(std::nullopt, "twin", "crash");
    if (::write(report_fd, &session, sizeof session) != sizeof session) ::_exit(2);
    for (std::int64_t i = 0;; ++i) {
      clock.advance(10ms);
      // Alternate tables, so the kill can land in either kind of write.
      const bool ok =
          i % 2 == 0
              ? db.log_telemetry(session, sample_frame(clock.utc_now(), static_cast<int>(i))).ok
              : db.log_gesture(session,
                               contracts::GestureEvent{.frame_id = i, .timestamp = clock.utc_now()})
                    .ok;
      if (!ok) ::_exit(3);
      if (::write(report_fd, &i, sizeof i) != sizeof i) ::_exit(4);
    }
  } catch (...) {
    ::_exit(5);
  }
}

// Reads one int64 from the pipe; false on end of file or timeout.
bool read_report(int fd, std::int64_t& value) {
  pollfd pfd{fd, POLLIN, 0};
  if (::poll(&pfd, 1, kPollTimeoutMs) <= 0) return false;
  char buf[sizeof value];
  std::size_t got = 0;
  while (got < sizeof buf) {
    const ssize_t n = ::read(fd, buf + got, sizeof buf - got);
    if (n <= 0) return false;
    got += static_cast<std::size_t>(n);
  }
  std::memcpy(&value, buf, sizeof value);
  return true;
}

TEST(StorageCrash, EveryAcknowledgedRowSurvivesKillNine) {
  TempDir dir;
  const std::string path = dir.file("crash/gbdcs.db");
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(fds[0]);
    write_until_killed(path, fds[1]);
  }
  ::close(fds[1]);

  std::int64_t session = 0;
  ASSERT_TRUE(read_report(fds[0], session)) << "the child did not start writing";
  std::set<std::int64_t> acknowledged;
  std::int64_t index = 0;
  while (acknowledged.size() < kAcksBeforeKill && read_report(fds[0], index)) {
    acknowledged.insert(index);
  }
  ASSERT_EQ(acknowledged.size(), kAcksBeforeKill) << "the child stopped early";
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
      << "the child exited by itself (status " << status << ") instead of being killed";
  // Reports written before the kill are still in the pipe.
  while (read_report(fds[0], index)) acknowledged.insert(index);
  ::close(fds[0]);

  {
    RawDb raw(path);  // recovers the WAL left behind
    EXPECT_EQ(raw.text("PRAGMA integrity_check"), "ok");
  }
  ManualClock clock;
  StorageManager db({.path = path}, clock);
  std::set<std::int64_t> stored;
  for (const auto& frame : db.telemetry(session)) {
    stored.insert(static_cast<std::int64_t>(frame.x_m - 3.0 + 0.5));  // sample_frame: x_m = 3 + i
  }
  for (const auto& event : db.gestures(session)) stored.insert(event.frame_id);

  for (std::int64_t i : acknowledged) EXPECT_TRUE(stored.contains(i)) << "row " << i << " lost";
  // At most the one write in flight at the kill may be there without its report.
  EXPECT_LE(stored.size(), acknowledged.size() + 1);
  const std::int64_t last = *acknowledged.rbegin();
  EXPECT_EQ(static_cast<std::int64_t>(acknowledged.size()), last + 1) << "reports are gapless";
}

}  // namespace
}  // namespace gbdcs::storage
