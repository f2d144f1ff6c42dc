#include "open_errors.hpp"

#include <sqlite3.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
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

namespace {

// Whether the files of the database at `path` have no room to grow: the volume has less than
// 1 MiB free, or one of them is within 64 KiB of the process's file-size limit.
bool out_of_space(const std::string& path) {
  std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (folder.empty()) folder = ".";
  struct statvfs fs {};
  if (::statvfs(folder.c_str(), &fs) == 0 &&
      static_cast<unsigned long long>(fs.f_bavail) * fs.f_frsize < (1ULL << 20)) {
    return true;
  }
  rlimit limit{};
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    for (const char* suffix : {"", "-wal", "-journal"}) {
      std::error_code ec;
      const auto size = std::filesystem::file_size(path + suffix, ec);
      if (!ec && size + (64u << 10) > limit.rlim_cur) return true;
    }
  }
  return false;
}

}  // namespace

WriteFailureKind classify_write_failure(const std::string& path, const SqliteError& e) {
  const int os_errno = e.system_errno();
  // SQLite reports ENOSPC as SQLITE_FULL, but a file-size limit's EFBIG (and, on some file
  // systems, a full volume) as a plain I/O error whose errno it does not keep reliably: so an
  // I/O error is also called a full disk when the files visibly have no room to grow.
  if (e.code() == SQLITE_FULL || os_errno == ENOSPC || os_errno == EFBIG || os_errno == EDQUOT ||
      (e.code() == SQLITE_IOERR && out_of_space(path))) {
    return {true, "the disk holding " + path +
                      " is full (or its file-size limit is reached): free disk space there (or "
                      "restart with --db on another volume); flying goes on, but nothing is "
                      "recorded until a write succeeds again"};
  }
  switch (e.code()) {
    case SQLITE_READONLY:
    case SQLITE_PERM:
    case SQLITE_AUTH:
      return {false, "the database " + path +
                         " cannot be written: check its permissions and those of its folder"};
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      return {false, "another process holds a lock on " + path +
                         ": stop the other program using it"};
    case SQLITE_IOERR:
    case SQLITE_CORRUPT:
      return {false, "the disk holding " + path +
                         " reports errors: check the volume (dmesg), then restart gbdcs"};
    default:
      return {};
  }
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
