#include "scheduler/queue/filter.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <set>

#include "scheduler/queue/dialect.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

namespace {

std::string quote_ident(const std::string& n) { return "\"" + n + "\""; }

/// The FROM and WHERE of a query on the results table, its values to bind, and the check of a
/// column name against the table's columns.
struct Selection {
  std::vector<std::string> all;
  std::string from_where;
  std::vector<json> binds;

  void check(const std::string& col, const std::string& where) const {
    if (std::find(all.begin(), all.end(), col) != all.end()) return;
    std::string list;
    for (const auto& a : all) list += (list.empty() ? "" : ", ") + a;
    throw std::invalid_argument(fmt::format("{}: found column '{}', expected one of: {}", where, col, list));
  }
};

Selection select_rows(db::Database& db, const ResultsQuery& q) {
  Selection s;
  s.all = result_columns(db);
  const std::set<std::string> numeric = numeric_result_columns(db);
  std::vector<std::string> clauses;
  if (!q.sweep.empty()) {
    clauses.push_back("sweep = ?");
    s.binds.push_back(q.sweep);
  }
  for (const auto& w : q.where) {
    for (const auto& c : db::parse_where(w)) {
      s.check(c.column, fmt::format("--where '{}'", w));
      if (c.op == "~") {
        clauses.push_back(dialect_of(db).contains(quote_ident(c.column)));
        s.binds.push_back(c.text);
      } else if (numeric.count(c.column)) {
        db::require_number(c, w);
        clauses.push_back(fmt::format("{} {} ?", quote_ident(c.column), c.op));  // op from a fixed list
        s.binds.push_back(c.value);
      } else {
        clauses.push_back(fmt::format("{} {} ?", quote_ident(c.column), c.op));
        s.binds.push_back(c.text);  // a text column compares with the text as typed
      }
    }
  }
  s.from_where = " FROM results";
  for (std::size_t i = 0; i < clauses.size(); ++i) s.from_where += (i ? " AND " : " WHERE ") + clauses[i];
  return s;
}

void bind_all(db::Statement& st, const std::vector<json>& binds) {
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
}

}  // namespace

ResultsTable query_results(db::Database& db, const ResultsQuery& q) {
  const Selection sel = select_rows(db, q);
  ResultsTable t;
  t.columns = q.columns.empty() ? sel.all : q.columns;
  for (const auto& c : t.columns) sel.check(c, "--columns");
  std::string sql = "SELECT ";
  for (std::size_t i = 0; i < t.columns.size(); ++i) sql += (i ? ", " : "") + quote_ident(t.columns[i]);
  sql += sel.from_where;
  if (!q.order_by.empty()) {
    sel.check(q.order_by, "--sort");
    // Then by insertion: equal values keep one order from page to page.
    sql += fmt::format(" ORDER BY {}{}, {}", quote_ident(q.order_by), q.descending ? " DESC" : "",
                       dialect_of(db).insertion_order());
  } else {
    sql += std::string(" ORDER BY sweep, ") + dialect_of(db).insertion_order();
  }
  // Integers, not user text. SQLite takes an OFFSET only after a LIMIT, PostgreSQL no negative
  // LIMIT: no limit with an offset is the largest one.
  if (q.limit >= 0 || q.offset > 0)
    sql += " LIMIT " + std::to_string(q.limit >= 0 ? q.limit : std::numeric_limits<std::int64_t>::max());
  if (q.offset > 0) sql += " OFFSET " + std::to_string(q.offset);
  db::Statement st(db, sql);
  bind_all(st, sel.binds);
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

std::int64_t count_results(db::Database& db, const ResultsQuery& q) {
  const Selection sel = select_rows(db, q);
  db::Statement st(db, "SELECT count(*)" + sel.from_where);
  bind_all(st, sel.binds);
  st.step();
  return st.get_int(0);
}

}  // namespace gravsweep::queue
