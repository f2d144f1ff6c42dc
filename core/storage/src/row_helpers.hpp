// Helpers shared by the StorageManager sources: time and enum columns, and the locked read.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/storage/records.hpp"
#include "gbdcs/storage/storage_options.hpp"
#include "sqlite_connection.hpp"

namespace gbdcs::storage::detail {

inline std::int64_t to_ms(contracts::UtcTime t) {
  return t.time_since_epoch().count();
}
inline contracts::UtcTime from_ms(std::int64_t ms) {
  return contracts::UtcTime{std::chrono::milliseconds{ms}};
}
inline std::optional<contracts::UtcTime> from_ms(const std::optional<std::int64_t>& ms) {
  if (!ms) return std::nullopt;
  return from_ms(*ms);
}

// An enum column holding a name this build does not know means the file was edited by hand
// or written by a newer gbdcs; say so rather than guess a value.
template <class E>
E decode_enum(std::optional<E> (*parse)(std::string_view), const std::string& text,
              std::string_view table, std::string_view column) {
  if (auto value = parse(text)) return *value;
  throw StorageError("column " + std::string(table) + "." + std::string(column) + " holds '" +
                     text +
                     "', which this gbdcs does not know (written by hand or by a newer "
                     "gbdcs)");
}

// Runs a read under the connection mutex; any failure becomes a StorageError naming what was
// read and the database path.
template <class F>
auto locked_read(std::mutex& mutex, const std::string& path, std::string_view what, F&& read)
    -> decltype(read()) {
  try {
    std::lock_guard lock(mutex);
    return read();
  } catch (const StorageError&) {
    throw;
  } catch (const std::exception& e) {
    throw StorageError("cannot read " + std::string(what) + " from " + path + ": " + e.what());
  }
}

// A users row selected as `id, username, password_hash, theme, created_at_ms`.

inline UserRecord user_from_row(Query& q) {
  UserRecord u;
  u.id = q->int64(0);
  u.username = q->text(1);
  u.password_hash = q->text(2);
  u.theme = q->text(3);
  u.created_at = from_ms(q->int64(4));
  return u;
}

}  // namespace gbdcs::storage::detail
