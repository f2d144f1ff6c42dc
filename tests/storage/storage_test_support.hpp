// Shared by the storage tests: unique temporary folders, sample messages, and direct SQLite
// access so the tests check the file itself, not only what StorageManager says about it.
#pragma once

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "gbdcs/contracts/messages.hpp"

namespace gbdcs::storage::testing {

namespace fs = std::filesystem;

// A fresh folder under /tmp, named after the test, removed (whatever its permissions) at the end.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info != nullptr ? std::string(info->test_suite_name()) + "_" + info->name()
                                       : std::string("storage");
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    path_ = fs::temp_directory_path() / ("gbdcs_storage_" + std::to_string(::getpid()) + "_" +
                                         std::to_string(counter++) + "_" + name);
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    for (const auto& entry : fs::recursive_directory_iterator(path_, ec)) {
      fs::permissions(entry.path(), fs::perms::owner_all, fs::perm_options::add, ec);
    }
    fs::permissions(path_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const fs::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

// Direct access to a database file, bypassing StorageManager.
class RawDb {
 public:
  explicit RawDb(const std::string& path) {
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK) {
      std::string message = sqlite3_errmsg(db_);
      sqlite3_close(db_);
      throw std::runtime_error("raw open of " + path + ": " + message);
    }
  }
  ~RawDb() { sqlite3_close(db_); }
  RawDb(const RawDb&) = delete;
  RawDb& operator=(const RawDb&) = delete;

  void exec(const std::string& sql) {
    char* error = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
      std::string message = error != nullptr ? error : "?";
      sqlite3_free(error);
      throw std::runtime_error("raw exec '" + sql + "': " + message);
    }
  }
  // Every row's first column, joined with '\n'.
  std::string text(const std::string& sql) {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
      throw std::runtime_error("raw prepare '" + sql + "': " + sqlite3_errmsg(db_));
    }
    std::string out;
    int rc = 0;
    while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
      const auto* value = sqlite3_column_text(stmt, 0);
      if (!out.empty()) out += "\n";
      out += value != nullptr ? reinterpret_cast<const char*>(value) : "NULL";
    }
    sqlite3_finalize(stmt);
    if (rc != SQLITE_DONE) throw std::runtime_error("raw step '" + sql + "' failed");
    return out;
  }
  std::int64_t integer(const std::string& sql) { return std::stoll(text(sql)); }

 private:
  sqlite3* db_ = nullptr;
};

inline contracts::TelemetryFrame sample_frame(contracts::UtcTime at, int i) {
  contracts::TelemetryFrame f;
  f.timestamp = at;
  f.altitude_m = 1.5 + 0.01 * i;
  f.speed_m_s = 0.25 * i;
  f.vx_m_s = 0.1 * i;
  f.vy_m_s = -0.2;
  f.vz_m_s = 0.05;
  f.x_m = 3.0 + i;
  f.y_m = -4.0;
  f.heading_deg = 359.5;
  f.battery_pct = 87.25 - 0.01 * i;
  f.flight_state = contracts::FlightState::kFlying;
  f.link = contracts::LinkState::kDegraded;
  return f;
}

}  // namespace gbdcs::storage::testing
