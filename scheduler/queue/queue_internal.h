// What the queue's source files share (not part of the queue's interface): the names they use, the
// statements that more than one verb runs inside its own transaction, and the results table's
// columns.
#pragma once
#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "scheduler/queue/dialect.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::queue {
// The names every source file of the queue uses.
using db::Database;
using db::Statement;
using db::Transaction;
using nlohmann::json;
namespace fs = std::filesystem;
}  // namespace gravsweep::queue

namespace gravsweep::queue::detail {

/// Marks the waiting dependents of a dead job dead too, recursively, each with `blocked_by` naming
/// the dead dependency (they can never run). Inside the caller's transaction.
void cascade_dead(db::Database& db, const std::string& job_id, double now);

/// Closes the attempts of up to `limit` expired leases (outcome `lost`) and requeues their jobs, or
/// marks them dead when the budget is spent. Inside the caller's transaction.
void reap_expired(db::Database& db, double now, Reclaimed& out, int limit);

// ---- the results table (results_table.cpp: its columns; results_row.cpp: a row) ---------------
/// What a finished job's results row is made from.
struct FinishedJob {
  const Claim& claim;
  const Completion& done;
  double now_s;                     ///< the completion's time on the campaign's clock
  const std::string& code_version;  ///< of the attempt's worker
  const std::string& bed_job_id;    ///< the job it depended on (a drop's bed); empty: none
};

/// One fixed column of the results table: what creates the table, what inserts a row and what
/// readers list all come from this table (fixed_result_columns).
struct FixedResultColumn {
  const char* name;
  const char* type;        ///< REAL, INTEGER or TEXT (Dialect::column_type gives the backend's word)
  const char* constraint;  ///< after the type in CREATE TABLE ("" when none)
  const char* doc;         ///< what it holds
  nlohmann::json (*value)(const FinishedJob&);  ///< its value in a finished job's row (null: NULL)
};
/// The fixed columns, in the table's order.
const std::vector<FixedResultColumn>& fixed_result_columns();
/// CREATE TABLE IF NOT EXISTS results(...) with the fixed columns, in the backend's words.
std::string results_table_sql(const Dialect& d);

/// SQL type of a swept parameter's column for a value: INTEGER, REAL, TEXT or ANY.
std::string sql_type_of(const nlohmann::json& v);
/// An extra column of results: "param" or "metric", and its queue type (INTEGER, REAL, TEXT, ANY).
struct ResultColumn {
  std::string role, type;
};
/// Existing extra columns of results by name.
std::map<std::string, ResultColumn> result_extra_columns(db::Database& db);
/// Adds a results column (inside the caller's transaction).
void add_result_column(db::Database& db, const std::string& name, const std::string& role, const std::string& type);
/// Makes an INTEGER results column REAL, keeping its values, when `v` is a non-integer number (an
/// axis extended by 2.5 after 1, 2). Inside the caller's transaction.
void widen_result_column(db::Database& db, const std::string& name, ResultColumn& col, const nlohmann::json& v);

/// The results column of a kind's output `key`: the key, or metric_<key> when the key is a fixed
/// column's name or a swept parameter's column (the parameter keeps the name). One rule for the
/// column made at submit and the value bound at completion.
std::string output_column(const std::string& key, const std::map<std::string, ResultColumn>& cols);
/// Adds the columns `kind` declares (JobKindInfo::outputs) that the campaign lacks, and makes REAL
/// a column an older build made INTEGER from a first whole value. Inside the caller's transaction
/// (submit's, or the write-mode open of a campaign an older build submitted to).
void declare_output_columns(db::Database& db, JobKind kind);
/// declare_output_columns for every registered kind that has jobs in the campaign and lacks a
/// column (jobs an older build submitted, before outputs were declared). Inside the caller's
/// transaction.
void declare_output_columns_of_jobs(db::Database& db);

/// Inserts the results row of a finished job whose kind has results rows: the fixed columns, its
/// swept parameters and its metrics in their declared columns. Runs no DDL. Throws OutputError
/// (check_outputs) for an undeclared metric, std::runtime_error naming the column when a declared
/// one is missing (a job an older build submitted after the campaign was opened); the caller's
/// transaction then rolls back. Inside the caller's transaction.
void insert_results_row(db::Database& db, const Claim& c, const Completion& done, double now,
                        const std::string& code_version);

}  // namespace gravsweep::queue::detail
