// RAII database access with two backends behind one front: an SQLite file (WAL, busy timeout,
// foreign keys) or a PostgreSQL server (libpq, a `postgresql://user@host:port/dbname` URL).
// Database (one connection), Statement (bound by index `?N`, `?` or `:name` in SQLite's syntax on
// both backends), Transaction (rolled back in the destructor unless committed). Errors are DbError
// with the SQL and the backend's message. One connection per process (or thread); never carried
// across fork(). SQL that differs between the backends lives with its user, one place per
// backend (the job queue: scheduler/queue/dialect.h).
#pragma once
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

namespace gravsweep::db {

enum class Backend { sqlite, postgres };

class DbError : public std::runtime_error {
 public:
  enum class Kind {
    other,
    busy,             ///< locked or a serialisation conflict: retry the transaction
    not_a_database,   ///< the file is not SQLite (or is corrupt)
    connection_lost,  ///< the server closed the connection or cannot be reached (a restart, an outage)
  };
  explicit DbError(const std::string& what, Kind kind = Kind::other) : std::runtime_error(what), kind_(kind) {}
  [[nodiscard]] Kind kind() const { return kind_; }
  [[nodiscard]] bool busy() const { return kind_ == Kind::busy; }
  [[nodiscard]] bool not_a_database() const { return kind_ == Kind::not_a_database; }
  [[nodiscard]] bool connection_lost() const { return kind_ == Kind::connection_lost; }

 private:
  Kind kind_;
};

/// The type of a value in a result row (per value, as SQLite reports it).
enum class ColumnType { null, integer, real, text, blob };

enum class TxMode { deferred, immediate, exclusive };

/// True when `location` names a PostgreSQL server (`postgresql://...` or `postgres://...`).
bool is_postgres_url(std::string_view location);

namespace detail {
/// One prepared statement of a backend (db/sqlite.cpp, db/postgres.cpp).
class Cursor {
 public:
  virtual ~Cursor() = default;
  virtual void bind_int(int idx, std::int64_t v) = 0;
  virtual void bind_double(int idx, double v) = 0;
  virtual void bind_text(int idx, std::string_view v) = 0;
  virtual void bind_null(int idx) = 0;
  [[nodiscard]] virtual int index_of(const char* name) const = 0;
  virtual bool step() = 0;
  virtual void reset() = 0;
  [[nodiscard]] virtual int columns() const = 0;
  [[nodiscard]] virtual std::string column_name(int i) const = 0;
  [[nodiscard]] virtual ColumnType column_type(int i) const = 0;
  [[nodiscard]] virtual std::int64_t get_int(int i) const = 0;
  [[nodiscard]] virtual double get_double(int i) const = 0;
  [[nodiscard]] virtual std::string get_text(int i) const = 0;
};
/// One connection of a backend.
class Connection {
 public:
  virtual ~Connection() = default;
  [[nodiscard]] virtual Backend backend() const = 0;
  virtual void exec(std::string_view sql) = 0;
  virtual std::unique_ptr<Cursor> prepare(std::string_view sql) = 0;
  [[nodiscard]] virtual int changes() const = 0;
  virtual void begin(TxMode mode) = 0;
  virtual void rollback() noexcept = 0;
};
}  // namespace detail

class Database {
 public:
  /// Opens a campaign store. A PostgreSQL URL connects to the server (read_only: every
  /// transaction read-only; the busy timeout becomes the lock timeout); anything else is an SQLite
  /// file, opened (created if needed) with WAL, synchronous=NORMAL, foreign keys and a busy
  /// timeout. ":memory:" works for tests.
  explicit Database(const std::string& location, int busy_timeout_ms = 30000, bool read_only = false);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;
  Database(Database&& o) noexcept;
  Database& operator=(Database&& o) noexcept;  ///< (a worker's reconnection replaces its connection)

  /// Runs one or more statements without results.
  void exec(std::string_view sql);
  [[nodiscard]] Backend backend() const { return conn_->backend(); }
  /// The location as given (file path or URL), for messages.
  [[nodiscard]] const std::string& path() const { return path_; }
  /// Rows changed by the last INSERT, UPDATE or DELETE.
  [[nodiscard]] int changes() const { return conn_->changes(); }
  [[nodiscard]] detail::Connection& connection() { return *conn_; }

 private:
  std::unique_ptr<detail::Connection> conn_;
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
  Statement& bind(const char* name, const T& v) {
    return bind(index_of(name), v);
  }
  [[nodiscard]] int index_of(const char* name) const;

  /// Advances to the next row; false when done. Throws DbError on failure.
  bool step();
  /// Runs to completion (for statements without result rows).
  void run();
  /// Ready to run again; bindings are cleared.
  void reset();

  // Columns of the current row (0-based).
  [[nodiscard]] int columns() const;
  [[nodiscard]] std::string column_name(int i) const;
  [[nodiscard]] bool is_null(int i) const { return column_type(i) == ColumnType::null; }
  [[nodiscard]] std::int64_t get_int(int i) const;
  [[nodiscard]] double get_double(int i) const;
  [[nodiscard]] std::string get_text(int i) const;
  [[nodiscard]] ColumnType column_type(int i) const;

 private:
  std::unique_ptr<detail::Cursor> cur_;
};

/// True when the database has a table of this name (in the current schema on PostgreSQL).
bool has_table(Database& db, std::string_view name);

class Transaction {
 public:
  using Mode = TxMode;
  /// SQLite: BEGIN IMMEDIATE (deferred: BEGIN, a read snapshot in WAL). PostgreSQL: BEGIN (read
  /// committed; row locks do the serialising), deferred: a repeatable-read snapshot.
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
