// `--where` filters of `gravsweep results`: parsed into (column, operator, value) conditions; the
// column is checked against the table's real columns and the value is bound as a parameter, so
// nothing the user types is ever pasted into SQL.
//
// Grammar:  condition (("and" | "&&" | ",") condition)*
//           condition := column op value
//           op        := < | <= | > | >= | = | == | != | <> | ~ (substring match on text)
//           value     := number | 'text' | "text" | true | false | bare-word
#pragma once
#include <nlohmann/json.hpp>

#include <stdexcept>
#include <string>
#include <vector>

#include "db/database.h"

namespace gravsweep::queue {

struct Condition {
  std::string column, op;
  nlohmann::json value;  ///< a finite number, a boolean, or text
  std::string text;      ///< the value as typed (without quotes): what `~` looks for, and text columns compare to
};

/// Throws std::invalid_argument naming the position and what was expected (also for nan and inf:
/// no value compares with them the same way on both backends).
std::vector<Condition> parse_where(const std::string& expr);

/// The in-memory twin of query_results, for rows that are not in a database (the trials of a lab
/// campaign, the planned jobs of `submit --where`): true when `row` ({column: value}) satisfies
/// every condition of every expression. Numbers (and booleans) compare as numbers, everything else
/// as text; `~` is a substring match. A column the row lacks, or a value that is not a number
/// compared (< <= > >= = !=) with a column holding a number, throws std::invalid_argument naming
/// the expression, the column and the value.
bool row_matches(const nlohmann::json& row, const std::vector<std::string>& where);

struct ResultsQuery {
  std::vector<std::string> where;    ///< --where expressions (ANDed)
  std::vector<std::string> columns;  ///< empty: all
  std::string sweep;                 ///< empty: all sweeps
  std::string order_by;              ///< empty: insertion order
  long limit = -1;
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

}  // namespace gravsweep::queue
