// Thin RAII over the SQLite C API: a connection, its cached prepared statements and
// transactions. Not thread-safe; StorageManager serialises access with its mutex.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>

struct sqlite3;
struct sqlite3_stmt;

namespace gbdcs::storage::detail {

// A failed SQLite call: the primary result code (SQLITE_*), the OS errno behind it if any,
// and sqlite3_errmsg's text.
class SqliteError : public std::runtime_error {
 public:
  SqliteError(int code, int system_errno, const std::string& message);
  int code() const { return code_; }
  int system_errno() const { return system_errno_; }

 private:
  int code_;
  int system_errno_;
};

class Statement {
 public:
  Statement(sqlite3* db, std::string_view sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  // Parameter indices start at 1, as in SQL's ?1.
  void bind(int index, std::int64_t value);
  void bind(int index, int value) { bind(index, static_cast<std::int64_t>(value)); }
  void bind(int index, bool value) { bind(index, static_cast<std::int64_t>(value ? 1 : 0)); }
  void bind(int index, double value);
  void bind(int index, std::string_view value);
  void bind(int index, const std::optional<std::int64_t>& value);
  void bind(int index, const std::optional<std::string>& value);
  void bind_null(int index);

  bool step();   // true: a row is ready; false: done. Throws SqliteError.
  void reset();  // ready to bind and run again

  // Column indices start at 0.
  bool is_null(int column) const;
  std::int64_t int64(int column) const;
  double real(int column) const;
  std::string text(int column) const;
  std::optional<std::int64_t> optional_int64(int column) const;
  std::optional<std::string> optional_text(int column) const;

 private:
  [[noreturn]] void fail(int code) const;
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

// A cached statement on loan: reset (and its bindings cleared) when the loan ends, so the
// next user starts clean even if this one threw half-way.
class Query {
 public:
  explicit Query(Statement& statement) : statement_(&statement) {}
  ~Query() { statement_->reset(); }
  Query(const Query&) = delete;
  Query& operator=(const Query&) = delete;
  Statement* operator->() { return statement_; }
  Statement& operator*() { return *statement_; }

 private:
  Statement* statement_;
};

class Connection {
 public:
  // Opens (read_only) or opens/creates the file. Throws SqliteError.
  Connection(const std::string& path, bool read_only);
  ~Connection();
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  void exec(std::string_view sql);                  // one or more statements, no results
  Query query(std::string_view sql);                // prepared once, then reused
  std::int64_t scalar_int64(std::string_view sql);  // first column of the first row
  std::string scalar_text(std::string_view sql);
  void set_busy_timeout(int timeout_ms);
  bool is_read_only() const;  // the file was opened without write access
  std::int64_t changes() const;
  std::int64_t last_insert_rowid() const;
  sqlite3* handle() { return db_; }

 private:
  sqlite3* db_ = nullptr;
  std::unordered_map<std::string, std::unique_ptr<Statement>> cache_;
};

// BEGIN IMMEDIATE (take the write lock up front, so a busy database fails here rather than
// half-way); rolls back unless commit() was reached.
class Transaction {
 public:
  explicit Transaction(Connection& db);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  Connection& db_;
  bool open_ = true;
};

}  // namespace gbdcs::storage::detail
