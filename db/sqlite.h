// RAII access to SQLite: Database (one connection, WAL, busy timeout), Statement (prepared,
// bound by index or :name), Transaction (BEGIN IMMEDIATE by default; rolled back in the
// destructor unless committed). Errors are DbError with the SQL and SQLite's message.
// One connection per process (or thread); never carried across fork().
#pragma once
#include <sqlite3.h>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace gravsweep::db {

class DbError : public std::runtime_error {
 public:
  DbError(const std::string& what, int code) : std::runtime_error(what), code_(code) {}
  [[nodiscard]] int code() const { return code_; }
  [[nodiscard]] bool busy() const { return code_ == SQLITE_BUSY || code_ == SQLITE_LOCKED; }

 private:
  int code_;
};

class Database {
 public:
  /// Opens (creating if needed) the file; sets WAL, synchronous=NORMAL, foreign keys and a busy
  /// timeout. ":memory:" works for tests.
  explicit Database(const std::string& path, int busy_timeout_ms = 30000, bool read_only = false);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;
  Database(Database&& o) noexcept : db_(o.db_), path_(std::move(o.path_)) { o.db_ = nullptr; }

  /// Runs one or more statements without results.
  void exec(std::string_view sql);
  [[nodiscard]] sqlite3* handle() const { return db_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::int64_t last_insert_rowid() const;
  [[nodiscard]] int changes() const;

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
};

class Statement {
 public:
  Statement(Database& db, std::string_view sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  // Binding (1-based index, or ":name").
  Statement& bind(int idx, std::int64_t v);
  Statement& bind(int idx, int v) { return bind(idx, static_cast<std::int64_t>(v)); }
  Statement& bind(int idx, double v);
  Statement& bind(int idx, std::string_view v);
  Statement& bind(int idx, const char* v) { return bind(idx, std::string_view(v)); }
  Statement& bind(int idx, const std::string& v) { return bind(idx, std::string_view(v)); }
  Statement& bind_null(int idx);
  template <class T>
  Statement& bind(const char* name, const T& v) { return bind(index_of(name), v); }
  int index_of(const char* name) const;

  /// Advances to the next row; false when done. Throws DbError on failure.
  bool step();
  /// Runs to completion (for statements without result rows).
  void run();
  void reset();

  // Columns of the current row (0-based).
  [[nodiscard]] int columns() const;
  [[nodiscard]] std::string column_name(int i) const;
  [[nodiscard]] bool is_null(int i) const;
  [[nodiscard]] std::int64_t get_int(int i) const;
  [[nodiscard]] double get_double(int i) const;
  [[nodiscard]] std::string get_text(int i) const;
  [[nodiscard]] int column_type(int i) const;  ///< SQLITE_INTEGER, SQLITE_FLOAT, SQLITE_TEXT, ...

 private:
  Database& db_;
  sqlite3_stmt* stmt_ = nullptr;
  std::string sql_;
  void check(int rc, const char* what) const;
};

class Transaction {
 public:
  enum class Mode { deferred, immediate, exclusive };
  explicit Transaction(Database& db, Mode mode = Mode::immediate);
  ~Transaction();  ///< rolls back unless committed; never throws
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  Database& db_;
  bool done_ = false;
};

}  // namespace gravsweep::db
