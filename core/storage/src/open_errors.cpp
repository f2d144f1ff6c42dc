#include "open_errors.hpp"

#include <sqlite3.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace gbdcs::storage::detail {

StorageError not_a_database_error(const std::string& path, const std::string& cause) {
  return StorageError(path + " is not a valid GBDCS database (" + cause +
                      "): move it aside or restore a backup; a new one is created at that path "
                      "on next start");
}

StorageError cannot_write_error(const std::string& path, const std::string& cause) {
  return StorageError("cannot write database " + path + " (" + cause +
                      "): check the permissions or choose another path with --db");
}

StorageError open_error(const std::string& path, const SqliteError& e) {
  const std::string cause = e.what();
  const int os_errno = e.system_errno();
  switch (e.code()) {
    case SQLITE_NOTADB:
    case SQLITE_CORRUPT:
      return not_a_database_error(path, cause);
    case SQLITE_READONLY:
    case SQLITE_PERM:
    case SQLITE_AUTH:
      return cannot_write_error(path, cause);
    case SQLITE_FULL:
      return StorageError("cannot write database " + path + " (" + cause +
                          "): free disk space or choose another path with --db");
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      return StorageError("database " + path + " is locked by another process (" + cause +
                          "): stop the other gbdcs using it or choose another path with --db");
    default:
      break;
  }
  if (os_errno == EACCES || os_errno == EPERM || os_errno == EROFS) {
    return cannot_write_error(path, cause);
  }
  // SQLite retries a refused create as a read-only open, so the errno it keeps is often that
  // retry's ENOENT; ask the file system what the real obstacle was.
  if (e.code() == SQLITE_CANTOPEN && !std::filesystem::is_directory(path)) {
    std::filesystem::path parent = std::filesystem::path(path).parent_path();
    if (parent.empty()) parent = ".";
    const bool exists = std::filesystem::exists(path);
    if ((exists && ::access(path.c_str(), W_OK) != 0) ||
        (!exists && ::access(parent.c_str(), W_OK) != 0)) {
      return cannot_write_error(path, cause + ", " + std::strerror(errno));
    }
  }
  return StorageError("cannot open database " + path + " (" + cause +
                      "): check that the path names a file (not a folder) in a folder you can "
                      "write, or choose another path with --db");
}

void create_parent_directories(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (parent.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(parent, ec);
  if (!ec) return;
  const std::string cause = "cannot create folder " + parent.string() + ": " + ec.message();
  if (ec == std::errc::permission_denied || ec == std::errc::read_only_file_system ||
      ec == std::errc::operation_not_permitted) {
    throw cannot_write_error(path, cause);
  }
  throw StorageError("cannot open database " + path + " (" + cause +
                     "): check the path or choose another path with --db");
}

}  // namespace gbdcs::storage::detail
