// What differs in the job queue's SQL between the two backends, in one place per backend:
// dialect_sqlite.cpp and dialect_postgres.cpp. Everything else of the queue is one SQL text that
// both run (parameters in SQLite's syntax, translated by db/postgres.cpp).
#pragma once
#include <string>

#include "db/database.h"

namespace gravsweep::queue {

/// The words the queue's one schema (schema.cpp) is written with.
struct SchemaTypes {
  const char* key;                   ///< a generated 64-bit primary key
  const char* integer;               ///< 64-bit integer
  const char* real;                  ///< double precision
  const char* strict;                ///< after a table's columns
  const char* strict_without_rowid;  ///< after a table keyed by its primary key only
};

class Dialect {
 public:
  virtual ~Dialect() = default;
  [[nodiscard]] virtual SchemaTypes schema_types() const = 0;
  /// Appended to the row-picking SELECT of a claim or a lease reap: PostgreSQL locks the rows it
  /// picks and skips those another worker holds (`FOR UPDATE SKIP LOCKED`); SQLite needs nothing,
  /// its BEGIN IMMEDIATE transaction already excludes every other writer.
  [[nodiscard]] virtual const char* lock_picked_rows() const = 0;
  /// Seconds since the Unix epoch on the clock leases are measured on: the server's for
  /// PostgreSQL (workers on many hosts), this host's for SQLite (one host by construction).
  [[nodiscard]] virtual double now_s(db::Database& db) const = 0;
  /// How many of `names` (comma-separated, quoted SQL strings) exist as tables.
  [[nodiscard]] virtual int tables_present(db::Database& db, const std::string& quoted_names) const = 0;
  [[nodiscard]] virtual bool has_column(db::Database& db, const std::string& table,
                                        const std::string& column) const = 0;
  /// The column type for a results column of queue type `type` (INTEGER, REAL, TEXT or ANY).
  [[nodiscard]] virtual std::string column_type(const std::string& type) const = 0;
  /// ALTER TABLE adding `column` (quoted) of `sql_type`; a concurrent add of the same column by
  /// another worker is not an error on PostgreSQL.
  [[nodiscard]] virtual std::string add_column_sql(const std::string& table, const std::string& column,
                                                   const std::string& sql_type) const = 0;

  /// Changes `column` (unquoted) of `table` from INTEGER to REAL, keeping its values.
  virtual void widen_to_real(db::Database& db, const std::string& table, const std::string& column) const = 0;

  /// A condition true when the text form of `quoted_column` contains the bound text (`--where` `~`):
  /// SQLite's instr, PostgreSQL's strpos.
  [[nodiscard]] virtual std::string contains(const std::string& quoted_column) const = 0;
  /// The column that orders results rows as they were written (for listings without --sort).
  [[nodiscard]] virtual const char* insertion_order() const = 0;
  /// After rows were copied in with their keys (campaign copy): generated keys continue after them.
  virtual void after_copy(db::Database& db) const = 0;
};

const Dialect& sqlite_dialect();
const Dialect& postgres_dialect();
/// The dialect of `db`'s backend.
const Dialect& dialect_of(const db::Database& db);

}  // namespace gravsweep::queue
