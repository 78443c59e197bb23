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
  nlohmann::json value;
};

/// Throws std::invalid_argument naming the position and what was expected.
std::vector<Condition> parse_where(const std::string& expr);

/// The in-memory twin of query_results, for rows that are not in a database (the trials of a lab
/// campaign, the planned jobs of `submit --where`): true when `row` ({column: value}) satisfies
/// every condition of every expression. Numbers (and booleans) compare as numbers, everything else
/// as text; `~` is a substring match. A column the row lacks throws std::invalid_argument naming
/// the expression and the columns the row has.
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

/// Runs the query on the results table; bad columns/expressions throw std::invalid_argument.
ResultsTable query_results(db::Database& db, const ResultsQuery& q);

}  // namespace gravsweep::queue
