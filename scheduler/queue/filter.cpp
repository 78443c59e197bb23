#include "scheduler/queue/filter.h"

#include <fmt/format.h>

#include <algorithm>

#include "scheduler/queue/dialect.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::queue {

using nlohmann::json;

namespace {

std::string quote_ident(const std::string& n) { return "\"" + n + "\""; }

}  // namespace

ResultsTable query_results(db::Database& db, const ResultsQuery& q) {
  const std::vector<std::string> all = result_columns(db);
  const std::set<std::string> numeric = numeric_result_columns(db);
  auto check = [&](const std::string& col, const std::string& where) {
    if (std::find(all.begin(), all.end(), col) == all.end()) {
      std::string list;
      for (const auto& a : all) list += (list.empty() ? "" : ", ") + a;
      throw std::invalid_argument(fmt::format("{}: found column '{}', expected one of: {}", where, col, list));
    }
  };
  ResultsTable t;
  t.columns = q.columns.empty() ? all : q.columns;
  for (const auto& c : t.columns) check(c, "--columns");
  std::string sql = "SELECT ";
  for (std::size_t i = 0; i < t.columns.size(); ++i) sql += (i ? ", " : "") + quote_ident(t.columns[i]);
  sql += " FROM results";
  std::vector<json> binds;
  std::vector<std::string> clauses;
  if (!q.sweep.empty()) {
    clauses.push_back("sweep = ?");
    binds.push_back(q.sweep);
  }
  for (const auto& w : q.where) {
    for (const auto& c : db::parse_where(w)) {
      check(c.column, fmt::format("--where '{}'", w));
      if (c.op == "~") {
        clauses.push_back(dialect_of(db).contains(quote_ident(c.column)));
        binds.push_back(c.text);
      } else if (numeric.count(c.column)) {
        db::require_number(c, w);
        clauses.push_back(fmt::format("{} {} ?", quote_ident(c.column), c.op));  // op from a fixed list
        binds.push_back(c.value);
      } else {
        clauses.push_back(fmt::format("{} {} ?", quote_ident(c.column), c.op));
        binds.push_back(c.text);  // a text column compares with the text as typed
      }
    }
  }
  for (std::size_t i = 0; i < clauses.size(); ++i) sql += (i ? " AND " : " WHERE ") + clauses[i];
  if (!q.order_by.empty()) {
    check(q.order_by, "--sort");
    sql += " ORDER BY " + quote_ident(q.order_by);
  } else {
    sql += std::string(" ORDER BY sweep, ") + dialect_of(db).insertion_order();
  }
  if (q.limit >= 0) sql += " LIMIT " + std::to_string(q.limit);  // an integer, not user text
  db::Statement st(db, sql);
  for (std::size_t i = 0; i < binds.size(); ++i) {
    const json& v = binds[i];
    const int idx = static_cast<int>(i + 1);
    if (v.is_boolean())
      st.bind(idx, static_cast<std::int64_t>(v.get<bool>()));
    else if (v.is_number_integer())
      st.bind(idx, v.get<std::int64_t>());
    else if (v.is_number())
      st.bind(idx, v.get<double>());
    else
      st.bind(idx, v.get<std::string>());
  }
  while (st.step()) {
    std::vector<json> row;
    for (int c = 0; c < st.columns(); ++c) {
      switch (st.column_type(c)) {
        case db::ColumnType::null:
          row.emplace_back(nullptr);
          break;
        case db::ColumnType::integer:
          row.emplace_back(st.get_int(c));
          break;
        case db::ColumnType::real:
          row.emplace_back(st.get_double(c));
          break;
        default:
          row.emplace_back(st.get_text(c));
      }
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

}  // namespace gravsweep::queue
