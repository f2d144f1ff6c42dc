// Turns what went wrong while opening a database into a StorageError that names the path,
// the cause and the fix: the message an operator sees when `gbdcs serve` will not start.
#pragma once

#include <string>
#include <system_error>

#include "gbdcs/storage/storage_options.hpp"
#include "sqlite_connection.hpp"

namespace gbdcs::storage::detail {

StorageError not_a_database_error(const std::string& path, const std::string& cause);
StorageError cannot_write_error(const std::string& path, const std::string& cause);
StorageError open_error(const std::string& path, const SqliteError& e);

// For a write that failed while running: whether it ran out of space, and the fix to tell
// the operator (empty when there is nothing specific to do).
struct WriteFailureKind {
  bool disk_full = false;
  std::string suggestion;
};
WriteFailureKind classify_write_failure(const std::string& path, const SqliteError& e);

// Creates the folders above `path`; throws the matching StorageError when it cannot.
void create_parent_directories(const std::string& path);

}  // namespace gbdcs::storage::detail
