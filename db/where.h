// The `--where` filter grammar, shared by everything that selects rows: the results table of a
// campaign database (scheduler/queue/filter.h binds the values as SQL parameters, so nothing the
// user types is pasted into SQL), the planned jobs of `submit --where`, and the trials of a lab
// campaign or an imported file (results/measurements/campaign_input.h, matched in memory).
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

namespace gravsweep::db {

struct Condition {
  std::string column, op;  ///< op is one of < <= > >= = != ~ (== and <> are read as = and !=)
  nlohmann::json value;    ///< a finite number, a boolean, or text
  std::string text;        ///< the value as typed (without quotes): what `~` looks for, and text columns compare to
};

/// Throws std::invalid_argument naming the position and what was expected (also for nan and inf:
/// no value compares with them the same way on both backends).
std::vector<Condition> parse_where(const std::string& expr);

/// Throws std::invalid_argument unless `c` compares a number or a boolean (or is a `~` match):
/// what a column holding numbers accepts. `where` is the expression, for the message.
void require_number(const Condition& c, const std::string& where);

/// Rows that are not in a database (the trials of a lab campaign, the planned jobs of
/// `submit --where`): true when `row` ({column: value}) satisfies every condition of every
/// expression, as the results table's query would. Numbers (and booleans) compare as numbers,
/// everything else as text; `~` is a substring match. A column the row lacks, or a value that is
/// not a number compared (< <= > >= = !=) with a column holding a number, throws
/// std::invalid_argument naming the expression, the column and the value.
bool row_matches(const nlohmann::json& row, const std::vector<std::string>& where);

}  // namespace gravsweep::db
