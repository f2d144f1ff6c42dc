// Schema migrations, versioned in code. Each is a numbered SQL step applied in one
// transaction together with its row in schema_migrations, so a crash leaves either the
// whole step or none of it.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "sqlite_connection.hpp"

namespace gbdcs::storage::detail {

struct Migration {
  int version;
  std::string_view name;
  std::string_view sql;
};

std::span<const Migration> migrations();
int latest_schema_version();

// The highest applied version; 0 for a new (or not-yet-GBDCS) database.
int applied_schema_version(Connection& db);

// Brings the database at `path` to latest_schema_version(). Throws StorageError when the
// database is newer than this code, belongs to something else, or (read_only) needs migrating.
int migrate(Connection& db, const std::string& path, std::int64_t now_ms, bool read_only);

}  // namespace gbdcs::storage::detail
