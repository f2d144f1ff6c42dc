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

// Creates the folders above `path`; throws the matching StorageError when it cannot.
void create_parent_directories(const std::string& path);

}  // namespace gbdcs::storage::detail
