// StorageOptions: where the database lives and how much of it to keep.
//
// Options (JSON keys are the field names; unknown keys are refused):
//   path                      string  "var/gbdcs.db"  database file; parent folders are created.
//                                                     ":memory:" gives a private in-memory db.
//   max_size_bytes            integer 250 MiB         retention deletes the oldest ended
//                                                     sessions while the live data exceeds this
//   telemetry_retention_days  integer 30              telemetry older than this is deleted
//   read_only                 bool    false           open without writing (inspection tools);
//                                                     every write then fails and is reported
//   busy_timeout_ms           integer 5000            how long to wait on another process's lock
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace gbdcs::storage {

// Every failure to open, migrate, read or write (outside the log_* calls, which report
// through WriteResult instead). what() names the path, the cause and the fix.
class StorageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct StorageOptions {
  std::string path = "var/gbdcs.db";
  std::int64_t max_size_bytes = 250LL * 1024 * 1024;
  int telemetry_retention_days = 30;
  bool read_only = false;
  int busy_timeout_ms = 5000;
};

// Reads options from a JSON object; fields not given keep their defaults. Throws
// StorageError naming the key for an unknown key, a wrong type or an out-of-range value.
StorageOptions storage_options_from_json(const nlohmann::json& doc);

}  // namespace gbdcs::storage
