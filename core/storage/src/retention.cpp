// StorageManager: retention (by age, then by size) and the size measure it works against.
#include <optional>

#include "gbdcs/storage/storage_manager.hpp"
#include "row_helpers.hpp"
#include "sqlite_connection.hpp"

namespace gbdcs::storage {

using detail::Query;

namespace {

constexpr std::int64_t kMsPerDay = 24LL * 60 * 60 * 1000;

}  // namespace

std::int64_t StorageManager::live_size_locked() const {
  // Free pages are space SQLite will reuse, so they do not count towards the cap.
  const std::int64_t pages = db_->scalar_int64("PRAGMA page_count");
  const std::int64_t free_pages = db_->scalar_int64("PRAGMA freelist_count");
  return (pages - free_pages) * db_->scalar_int64("PRAGMA page_size");
}

std::int64_t StorageManager::size_bytes() const {
  return detail::locked_read(mutex_, options_.path, "the database size",
                             [&] { return live_size_locked(); });
}

RetentionReport StorageManager::apply_retention() {
  RetentionReport report;
  checked_write("delete old telemetry", [&] {
    report.size_before_bytes = live_size_locked();
    Query q = db_->query("DELETE FROM telemetry WHERE ts_ms < ?1");
    q->bind(1, now_ms() - options_.telemetry_retention_days * kMsPerDay);
    q->step();
    report.telemetry_rows_deleted = db_->changes();
  });

  // One session per step, each its own transaction and lock, so logging goes on in between.
  for (;;) {
    bool deleted = false;
    checked_write("delete the oldest session", [&] {
      if (live_size_locked() <= options_.max_size_bytes) return;
      std::optional<std::int64_t> victim;
      {
        // Open sessions are being written; the newest is the one an operator looks at.
        Query q = db_->query(
            "SELECT id FROM sessions WHERE ended_at_ms IS NOT NULL AND id <> "
            "(SELECT id FROM sessions ORDER BY started_at_ms DESC, id DESC LIMIT 1) "
            "ORDER BY started_at_ms, id LIMIT 1");
        if (q->step()) victim = q->int64(0);
      }
      if (!victim) return;
      Query del = db_->query("DELETE FROM sessions WHERE id = ?1");  // children cascade
      del->bind(1, *victim);
      del->step();
      deleted = true;
    });
    if (!deleted) break;
    ++report.sessions_deleted;
  }

  checked_write("reclaim free space", [&] {
    // Gives the free pages back to the file system, then folds the WAL into the main file
    // and truncates it, so the file on disk shrinks now rather than at some later checkpoint.
    db_->exec("PRAGMA incremental_vacuum");
    db_->exec("PRAGMA wal_checkpoint(TRUNCATE)");
    report.size_after_bytes = live_size_locked();
  });
  return report;
}

}  // namespace gbdcs::storage
