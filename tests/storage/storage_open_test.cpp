// Opening: migrations, refusing what must be refused with a message that says what to do, and
// the options loader.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "gbdcs/storage/storage_manager.hpp"
#include "storage_test_support.hpp"

namespace gbdcs::storage {
namespace {

using namespace std::chrono_literals;
using contracts::ManualClock;
using ::testing::HasSubstr;
using testing::RawDb;
using testing::sample_frame;
using testing::TempDir;

// The StorageError's message, or a failure if opening did not throw one.
std::string open_error(const StorageOptions& options, const contracts::Clock& clock) {
  try {
    StorageManager db(options, clock);
  } catch (const StorageError& e) {
    return e.what();
  }
  ADD_FAILURE() << "opening " << options.path << " did not throw StorageError";
  return {};
}

void write_random_bytes(const std::string& path, std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::ofstream out(path, std::ios::binary);
  for (std::size_t i = 0; i < count; ++i) out.put(static_cast<char>(rng() & 0xff));
}

TEST(StorageOpen, MigrationsAreAppliedOnceAndReopenKeepsData) {
  TempDir dir;
  ManualClock clock;
  const StorageOptions options{.path = dir.file("gbdcs.db")};
  std::int64_t session = 0;
  int version = 0;
  {
    StorageManager db(options, clock);
    version = db.schema_version();
    session = db.begin_session(std::nullopt, "twin", "default");
    ASSERT_TRUE(db.log_telemetry(session, sample_frame(clock.utc_now(), 1)));
  }
  std::string applied_before;
  {
    RawDb raw(options.path);
    applied_before = raw.text("SELECT version || ':' || applied_at_ms FROM schema_migrations");
    EXPECT_EQ(raw.integer("SELECT count(*) FROM schema_migrations"), version);
  }
  clock.advance(1h);
  for (int reopen = 0; reopen < 2; ++reopen) {
    StorageManager db(options, clock);
    EXPECT_EQ(db.schema_version(), version);
    EXPECT_EQ(db.telemetry(session).size(), 1u);
  }
  RawDb raw(options.path);
  EXPECT_EQ(raw.text("SELECT version || ':' || applied_at_ms FROM schema_migrations"),
            applied_before);
  EXPECT_EQ(raw.text("PRAGMA foreign_key_check"), "");
}

TEST(StorageOpen, RefusesADatabaseNewerThanTheCode) {
  TempDir dir;
  ManualClock clock;
  const StorageOptions options{.path = dir.file("gbdcs.db")};
  int version = 0;
  {
    StorageManager db(options, clock);
    version = db.schema_version();
  }
  RawDb(options.path)
      .exec("INSERT INTO schema_migrations (version, name, applied_at_ms) VALUES (" +
            std::to_string(version + 1) + ", 'from the future', 0)");
  const std::string message = open_error(options, clock);
  EXPECT_THAT(message, HasSubstr(options.path));
  EXPECT_THAT(message, HasSubstr("newer"));
  EXPECT_THAT(message, HasSubstr(std::to_string(version + 1)));
}

TEST(StorageOpen, RefusesAnotherApplicationsSqliteDatabase) {
  TempDir dir;
  ManualClock clock;
  const std::string path = dir.file("other.db");
  {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(raw, "CREATE TABLE users (x)", nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(raw);
  }
  const std::string message = open_error({.path = path}, clock);
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr("not a GBDCS one"));
}

TEST(StorageOpen, GarbageFileIsNotADatabase) {
  TempDir dir;
  ManualClock clock;
  const std::string path = dir.file("garbage.db");
  write_random_bytes(path, 8192, 1234);
  const std::string message = open_error({.path = path}, clock);
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr("is not a valid GBDCS database"));
  EXPECT_THAT(message, HasSubstr("move it aside"));
  EXPECT_EQ(std::filesystem::file_size(path), 8192u) << "a refused file is left untouched";
}

TEST(StorageOpen, DamagedPagesAreRefused) {
  TempDir dir;
  ManualClock clock;
  const std::string path = dir.file("damaged.db");
  {
    StorageManager db({.path = path}, clock);
    const auto s = db.begin_session(std::nullopt, "twin", "default");
    for (int i = 0; i < 2000; ++i)
      ASSERT_TRUE(db.log_telemetry(s, sample_frame(clock.utc_now(), i)));
  }
  std::int64_t page_size = 0;
  {
    RawDb raw(path);
    ASSERT_EQ(raw.text("PRAGMA integrity_check"), "ok");
    page_size = raw.integer("PRAGMA page_size");
  }
  // Keep page 1 (header and schema) intact so only the deeper check can notice.
  std::mt19937 rng(99);
  std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
  file.seekp(page_size * 3);
  for (std::int64_t i = 0; i < page_size * 6; ++i) file.put(static_cast<char>(rng() & 0xff));
  file.close();

  const std::string message = open_error({.path = path}, clock);
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr("move it aside"));
}

TEST(StorageOpen, AFolderInPlaceOfTheFileCannotBeOpened) {
  TempDir dir;
  ManualClock clock;
  const std::string path = dir.file("is_a_folder.db");
  std::filesystem::create_directories(path);
  const std::string message = open_error({.path = path}, clock);
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr("--db"));
}

TEST(StorageOpen, AFileInPlaceOfTheParentFolderCannotBeOpened) {
  TempDir dir;
  ManualClock clock;
  std::ofstream(dir.file("plain_file")) << "x";
  const std::string path = dir.file("plain_file/gbdcs.db");
  const std::string message = open_error({.path = path}, clock);
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr("cannot create folder"));
}

TEST(StorageOpen, ReadOnlyOpenOfAMissingFileFails) {
  TempDir dir;
  ManualClock clock;
  const std::string path = dir.file("missing/gbdcs.db");
  const std::string message = open_error({.path = path, .read_only = true}, clock);
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr("does not exist"));
  EXPECT_FALSE(std::filesystem::exists(dir.file("missing")));
}

TEST(StorageOptionsJson, DefaultsAndEveryKey) {
  const StorageOptions defaults = storage_options_from_json(nlohmann::json::object());
  EXPECT_EQ(defaults.path, "var/gbdcs.db");
  EXPECT_EQ(defaults.max_size_bytes, 250LL * 1024 * 1024);
  EXPECT_EQ(defaults.telemetry_retention_days, 30);
  EXPECT_FALSE(defaults.read_only);

  const auto options = storage_options_from_json({{"path", "/data/x.db"},
                                                  {"max_size_bytes", 1048576},
                                                  {"telemetry_retention_days", 7},
                                                  {"read_only", true},
                                                  {"busy_timeout_ms", 0}});
  EXPECT_EQ(options.path, "/data/x.db");
  EXPECT_EQ(options.max_size_bytes, 1048576);
  EXPECT_EQ(options.telemetry_retention_days, 7);
  EXPECT_TRUE(options.read_only);
  EXPECT_EQ(options.busy_timeout_ms, 0);
}

TEST(StorageOptionsJson, RejectsUnknownKeysAndBadValues) {
  auto message_for = [](const nlohmann::json& doc) -> std::string {
    try {
      storage_options_from_json(doc);
    } catch (const StorageError& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_THAT(message_for({{"max_size_mb", 5}}),
              HasSubstr("'max_size_mb' is not a storage option"));
  EXPECT_THAT(message_for({{"max_size_mb", 5}}), HasSubstr("max_size_bytes"));
  EXPECT_THAT(message_for({{"path", 5}}), HasSubstr("'path'"));
  EXPECT_THAT(message_for({{"path", ""}}), HasSubstr("non-empty"));
  EXPECT_THAT(message_for({{"max_size_bytes", 0}}), HasSubstr("'max_size_bytes'"));
  EXPECT_THAT(message_for({{"max_size_bytes", 1.5}}), HasSubstr("integer"));
  EXPECT_THAT(message_for({{"max_size_bytes", 18446744073709551615ULL}}), HasSubstr("at most"));
  EXPECT_THAT(message_for({{"telemetry_retention_days", -1}}), HasSubstr("between"));
  EXPECT_THAT(message_for({{"read_only", "yes"}}), HasSubstr("true or false"));
  EXPECT_THAT(message_for(nlohmann::json::array()), HasSubstr("JSON object"));
}

}  // namespace
}  // namespace gbdcs::storage
