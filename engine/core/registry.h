// The one way a name is looked up: a table of rows, each with a `name` (contact laws, rolling
// models, integrators, job kinds, model terms). A table is a std::vector (or a std::deque) of
// rows built in one place; find_row returns the row of a name, or throws a ConfigError that says
// what was asked for and lists the valid names:
//   unknown contact law 'hertzz'; valid contact laws: hertz, hooke
// Adding a physics term or a kind is one row in its table (see the table's header).
#pragma once
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/error.h"

namespace gravsweep {

/// The names of a table's rows, in table order.
template <class Rows>
std::vector<std::string> row_name_list(const Rows& rows) {
  std::vector<std::string> out;
  for (const auto& row : rows) out.emplace_back(row.name);
  return out;
}

/// The names of a table's rows, in table order, joined by ", ".
template <class Rows>
std::string row_names(const Rows& rows) {
  return fmt::format("{}", fmt::join(row_name_list(rows), ", "));
}

/// The row named `name`, or nullptr.
template <class Rows>
const auto* find_row_or_null(const Rows& rows, std::string_view name) {
  for (const auto& row : rows)
    if (std::string_view(row.name) == name) return &row;
  return static_cast<decltype(&*std::begin(rows))>(nullptr);
}

/// The error of a name no row has: "unknown <what> '<name>'; valid <what>s: <names><also>".
template <class Rows>
ConfigError unknown_name(const Rows& rows, std::string_view name, std::string_view what, std::string_view also = {}) {
  return ConfigError(fmt::format("unknown {} '{}'; valid {}s: {}{}", what, name, what, row_names(rows), also));
}

/// The row named `name`; throws unknown_name(rows, name, what, also) when there is none.
template <class Rows>
const auto& find_row(const Rows& rows, std::string_view name, std::string_view what, std::string_view also = {}) {
  if (const auto* row = find_row_or_null(rows, name)) return *row;
  throw unknown_name(rows, name, what, also);
}

}  // namespace gravsweep
