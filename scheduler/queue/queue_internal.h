// What the queue's source files share (not part of the queue's interface): the statements that
// more than one verb runs inside its own transaction, and the results table's dynamic columns.
#pragma once
#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

#include "scheduler/queue/queue.h"

namespace gravsweep::queue::detail {

/// Marks the waiting dependents of a dead job dead too, recursively, each with `blocked_by` naming
/// the dead dependency (they can never run). Inside the caller's transaction.
void cascade_dead(db::Database& db, const std::string& job_id, double now);

/// Closes the attempts of up to `limit` expired leases (outcome `lost`) and requeues their jobs, or
/// marks them dead when the budget is spent. Inside the caller's transaction.
void reap_expired(db::Database& db, double now, Reclaimed& out, int limit);

// ---- the results table (results_row.cpp) -------------------------------------------------------
/// SQL type of a results column for the first value seen.
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
/// axis extended by 2.5 after 1, 2; a metric first seen as 0). Inside the caller's transaction.
void widen_result_column(db::Database& db, const std::string& name, ResultColumn& col, const nlohmann::json& v);
/// Inserts the results row of a finished drop (or noop) job, adding metric columns as they first
/// appear. Inside the caller's transaction.
void insert_results_row(db::Database& db, const Claim& c, const Completion& done, double now,
                        const std::string& code_version);

}  // namespace gravsweep::queue::detail
