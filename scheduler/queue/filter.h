// The results table of a campaign database, queried: `gravsweep results`, its `--where` filters
// (grammar: db/where.h) checked against the table's real columns, their values bound as
// parameters, so nothing the user types is ever pasted into SQL.
#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "db/database.h"
#include "db/where.h"

namespace gravsweep::queue {

struct ResultsQuery {
  std::vector<std::string> where;    ///< --where expressions (ANDed)
  std::vector<std::string> columns;  ///< empty: all
  std::string sweep;                 ///< empty: all sweeps
  std::string order_by;              ///< empty: insertion order
  long limit = -1;
  long offset = 0;          ///< rows skipped first (a page of a long table)
  bool descending = false;  ///< order_by from the largest value down
};

struct ResultsTable {
  std::vector<std::string> columns;
  std::vector<std::vector<nlohmann::json>> rows;
};

/// Runs the query on the results table; bad columns/expressions throw std::invalid_argument. Typed
/// the same on both backends: a numeric column (numeric_result_columns) compares with numbers only
/// (anything else throws, naming the column and the value), a text column with the value's text as
/// typed, and `~` looks for the typed text in the column's text form.
ResultsTable query_results(db::Database& db, const ResultsQuery& q);

/// The number of rows `q` selects, limit and offset aside (the pages of a long table); the same
/// checks and errors as query_results.
std::int64_t count_results(db::Database& db, const ResultsQuery& q);

}  // namespace gravsweep::queue
