// The results table: fixed columns, one column per swept parameter (added at submit) and one per
// metric (added when first seen), units in the names; and the column lists the readers show.
#include <fmt/format.h>

#include <algorithm>
#include <set>

#include "scheduler/queue/dialect.h"
#include "scheduler/queue/queue_internal.h"
#include "scheduler/queue/canonical.h"

namespace gravsweep::queue {

using db::Database;
using db::Statement;
using nlohmann::json;

namespace {

const std::vector<std::string> kFixedResultColumns = {"job_id",    "sweep",       "kind",         "bed_job_id",
                                                      "attempt",   "trace_path",  "trace_sha256", "trace_bytes",
                                                      "runtime_s", "finished_at", "code_version"};

std::string quote_ident(const std::string& name) { return "\"" + name + "\""; }

}  // namespace

namespace detail {

std::string sql_type_of(const json& v) {
  if (v.is_boolean() || v.is_number_integer() || v.is_number_unsigned()) return "INTEGER";
  if (v.is_number()) return "REAL";
  if (v.is_string()) return "TEXT";
  return "ANY";
}

}  // namespace detail

namespace {

void bind_json_value(Statement& st, int idx, const json& v) {
  if (v.is_null())
    st.bind_null(idx);
  else if (v.is_boolean())
    st.bind(idx, static_cast<std::int64_t>(v.get<bool>() ? 1 : 0));
  else if (v.is_number_integer() || v.is_number_unsigned())
    st.bind(idx, v.get<std::int64_t>());
  else if (v.is_number())
    st.bind(idx, v.get<double>());
  else if (v.is_string())
    st.bind(idx, v.get<std::string>());
  else
    st.bind(idx, queue::canonical_json(v));
}

std::string sanitize_metric(const std::string& key) {
  std::string out;
  for (char c : key) {
    const auto u = static_cast<unsigned char>(c);
    out.push_back(std::isalnum(u) ? static_cast<char>(std::tolower(u)) : '_');
  }
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "m_" + out;
  return out;
}

void flatten(const json& j, const std::string& prefix, std::vector<std::pair<std::string, json>>& out) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it)
      flatten(it.value(), prefix.empty() ? it.key() : prefix + "_" + it.key(), out);
  } else if (j.is_array()) {
    out.emplace_back(prefix, json(queue::canonical_json(j)));
  } else {
    out.emplace_back(prefix, j);
  }
}

}  // namespace

namespace detail {

std::map<std::string, ResultColumn> result_extra_columns(Database& db) {
  std::map<std::string, ResultColumn> out;
  Statement st(db, "SELECT name, role, sql_type FROM results_columns");
  while (st.step()) out[st.get_text(0)] = {st.get_text(1), st.get_text(2)};
  return out;
}

void widen_result_column(Database& db, const std::string& name, ResultColumn& col, const json& v) {
  if (col.type != "INTEGER" || !v.is_number_float()) return;
  dialect_of(db).widen_to_real(db, "results", name);
  Statement st(db, "UPDATE results_columns SET sql_type='REAL' WHERE name=?");
  st.bind(1, name);
  st.run();
  col.type = "REAL";
}

void add_result_column(Database& db, const std::string& name, const std::string& role, const std::string& type) {
  const Dialect& d = dialect_of(db);
  db.exec(d.add_column_sql("results", quote_ident(name), d.column_type(type)));
  Statement st(db,
               "INSERT INTO results_columns(name, role, sql_type, position) "
               "VALUES(?, ?, ?, (SELECT coalesce(max(position), 0) + 1 FROM results_columns)) "
               "ON CONFLICT(name) DO NOTHING");  // another worker added it first (PostgreSQL)
  st.bind(1, name).bind(2, role).bind(3, type);
  st.run();
}

void insert_results_row(Database& db, const Claim& c, const Completion& done, double now,
                        const std::string& code_version) {
  auto cols = result_extra_columns(db);
  std::vector<std::pair<std::string, json>> metrics;
  flatten(done.metrics.is_null() ? json::object() : done.metrics, "", metrics);
  std::vector<std::pair<std::string, json>> values;
  std::set<std::string> used(kFixedResultColumns.begin(), kFixedResultColumns.end());
  for (auto it = c.params.begin(); it != c.params.end(); ++it) {
    const auto col = cols.find(it.key());
    if (col == cols.end() || !used.insert(it.key()).second) continue;
    widen_result_column(db, it.key(), col->second, it.value());
    values.emplace_back(it.key(), it.value());
  }
  for (auto& [key, v] : metrics) {
    std::string name = sanitize_metric(key);
    auto col = cols.find(name);
    if ((col != cols.end() && col->second.role != "metric") ||
        std::find(kFixedResultColumns.begin(), kFixedResultColumns.end(), name) != kFixedResultColumns.end())
      name = "metric_" + name;
    if (!cols.count(name) && v.is_null()) continue;  // the column appears with the first real value
    if (!used.insert(name).second) continue;
    if (!cols.count(name)) {
      add_result_column(db, name, "metric", sql_type_of(v));
      cols[name] = {"metric", sql_type_of(v)};
    }
    widen_result_column(db, name, cols[name], v);
    values.emplace_back(name, v);
  }
  std::string bed_id;
  {
    Statement st(db, "SELECT dep_id FROM job_deps WHERE job_id=?");
    st.bind(1, c.job_id);
    if (st.step()) bed_id = st.get_text(0);
  }
  std::string names =
      "job_id, sweep, kind, bed_job_id, attempt, trace_path, trace_sha256, trace_bytes, runtime_s, "
      "finished_at, code_version";
  std::string marks = "?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?";
  for (const auto& [name, v] : values) {
    names += ", " + quote_ident(name);
    marks += ", ?";
  }
  Statement st(db, fmt::format("INSERT INTO results({}) VALUES({})", names, marks));
  st.bind(1, c.job_id).bind(2, c.sweep_id).bind(3, kind_name(c.kind));
  if (bed_id.empty())
    st.bind_null(4);
  else
    st.bind(4, bed_id);
  st.bind(5, c.attempt).bind(6, done.output_rel).bind(7, done.sha256).bind(8, done.bytes);
  st.bind(9, now - c.claimed_at).bind(10, now).bind(11, code_version);
  int i = 12;
  for (const auto& [name, v] : values) bind_json_value(st, i++, v);
  st.run();
}

}  // namespace detail

std::vector<std::string> result_columns(Database& db) {
  std::vector<std::string> cols = kFixedResultColumns;
  Statement st(db, "SELECT name FROM results_columns ORDER BY role DESC, position");  // params, then metrics
  while (st.step()) cols.push_back(st.get_text(0));
  return cols;
}

std::set<std::string> numeric_result_columns(Database& db) {
  std::set<std::string> out{"attempt", "trace_bytes", "runtime_s", "finished_at"};
  Statement st(db, "SELECT name FROM results_columns WHERE sql_type IN ('INTEGER', 'REAL')");
  while (st.step()) out.insert(st.get_text(0));
  return out;
}

std::vector<std::string> summary_result_columns(Database& db, const std::vector<std::string>& headline_metrics) {
  std::vector<std::string> cols{"job_id"}, metrics;
  Statement st(db, "SELECT name, role FROM results_columns ORDER BY position");
  while (st.step()) {
    if (st.get_text(1) == "param")
      cols.push_back(st.get_text(0));
    else
      metrics.push_back(st.get_text(0));
  }
  for (const auto& m : headline_metrics)
    if (std::find(metrics.begin(), metrics.end(), m) != metrics.end()) cols.push_back(m);
  return cols;
}

}  // namespace gravsweep::queue
