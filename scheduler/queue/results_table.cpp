// The results table's columns: the fixed ones (one table, which the schema, the row and the
// readers all take them from), one per swept parameter and one per output a job kind declares,
// both added at submit, units in the names; and the column lists the readers show.
#include <fmt/format.h>

#include <algorithm>
#include <set>

#include "scheduler/queue/dialect.h"
#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

namespace detail {

const std::vector<FixedResultColumn>& fixed_result_columns() {
  // name, type, constraint, what it holds, its value in a finished job's row.
  static const std::vector<FixedResultColumn> columns = {
      {"job_id", "TEXT", "PRIMARY KEY REFERENCES jobs(job_id)", "the finished job",
       [](const FinishedJob& f) { return json(f.claim.job_id); }},
      {"sweep", "TEXT", "NOT NULL", "the sweep that created the job (jobs.sweep_id)",
       [](const FinishedJob& f) { return json(f.claim.sweep_id); }},
      {"kind", "TEXT", "NOT NULL", "its job kind", [](const FinishedJob& f) { return json(kind_name(f.claim.kind)); }},
      {"bed_job_id", "TEXT", "", "the job it waited for (a drop's bed); NULL: none",
       [](const FinishedJob& f) { return f.bed_job_id.empty() ? json(nullptr) : json(f.bed_job_id); }},
      {"attempt", "INTEGER", "NOT NULL", "the attempt that finished it (1: the first)",
       [](const FinishedJob& f) { return json(f.claim.attempt); }},
      {"trace_path", "TEXT", "", "its output, relative to the files root",
       [](const FinishedJob& f) { return json(f.done.output_rel); }},
      {"trace_sha256", "TEXT", "", "the output's SHA-256", [](const FinishedJob& f) { return json(f.done.sha256); }},
      {"trace_bytes", "INTEGER", "", "the output's size in bytes",
       [](const FinishedJob& f) { return json(f.done.bytes); }},
      {"runtime_s", "REAL", "", "from its claim to its completion, on the campaign's clock",
       [](const FinishedJob& f) { return json(f.now_s - f.claim.claimed_at); }},
      {"finished_at", "REAL", "", "its completion, seconds since the Unix epoch",
       [](const FinishedJob& f) { return json(f.now_s); }},
      {"code_version", "TEXT", "", "the build of the worker that ran it",
       [](const FinishedJob& f) { return json(f.code_version); }},
  };
  return columns;
}

std::string results_table_sql(const Dialect& d) {
  std::string cols;
  for (const auto& c : fixed_result_columns())
    cols += fmt::format("{}  {} {}{}{}", cols.empty() ? "" : ",\n", c.name, d.column_type(c.type),
                        *c.constraint ? " " : "", c.constraint);
  return fmt::format("CREATE TABLE IF NOT EXISTS results(\n{}\n) {};", cols, d.schema_types().strict);
}

std::string sql_type_of(const json& v) {
  if (v.is_boolean() || v.is_number_integer() || v.is_number_unsigned()) return "INTEGER";
  if (v.is_number()) return "REAL";
  if (v.is_string()) return "TEXT";
  return "ANY";
}

std::map<std::string, ResultColumn> result_extra_columns(Database& db) {
  std::map<std::string, ResultColumn> out;
  Statement st(db, "SELECT name, role, sql_type FROM results_columns");
  while (st.step()) out[st.get_text(0)] = {st.get_text(1), st.get_text(2)};
  return out;
}

namespace {

/// Makes the INTEGER column `name` REAL, keeping its values (SQLite rebuilds the STRICT table).
void make_real(Database& db, const std::string& name, ResultColumn& col) {
  dialect_of(db).widen_to_real(db, "results", name);
  Statement st(db, "UPDATE results_columns SET sql_type='REAL' WHERE name=?");
  st.bind(1, name);
  st.run();
  col.type = "REAL";
}

bool is_fixed_column(const std::string& name) {
  const auto& fixed = fixed_result_columns();
  return std::any_of(fixed.begin(), fixed.end(), [&](const FixedResultColumn& c) { return name == c.name; });
}

/// The campaign has a column for output `o` that holds its values: present, and not INTEGER for a
/// REAL output (an older build typed a metric column by its first value, which may have been 3).
bool has_column_for(const OutputField& o, const std::map<std::string, ResultColumn>& cols) {
  const auto it = cols.find(output_column(o.key, cols));
  return it != cols.end() && !(o.type == "REAL" && it->second.type == "INTEGER");
}

}  // namespace

void widen_result_column(Database& db, const std::string& name, ResultColumn& col, const json& v) {
  if (col.type == "INTEGER" && v.is_number_float()) make_real(db, name, col);
}

void add_result_column(Database& db, const std::string& name, const std::string& role, const std::string& type) {
  const Dialect& d = dialect_of(db);
  db.exec(d.add_column_sql("results", "\"" + name + "\"", d.column_type(type)));
  Statement st(db,
               "INSERT INTO results_columns(name, role, sql_type, position) "
               "VALUES(?, ?, ?, (SELECT coalesce(max(position), 0) + 1 FROM results_columns)) "
               "ON CONFLICT(name) DO NOTHING");  // another worker added it first (PostgreSQL)
  st.bind(1, name).bind(2, role).bind(3, type);
  st.run();
}

std::string output_column(const std::string& key, const std::map<std::string, ResultColumn>& cols) {
  const auto it = cols.find(key);
  if (is_fixed_column(key) || (it != cols.end() && it->second.role == "param")) return "metric_" + key;
  return key;
}

void declare_output_columns(Database& db, JobKind kind) {
  const JobKindInfo& info = kind_info(kind);
  if (!info.results_row) return;
  auto cols = result_extra_columns(db);
  // Added in the order of their keys: where the metric columns stood before outputs were declared
  // (a runner's JSON object iterates in key order), so that a new campaign's results table and
  // CSV have the columns of an older one, in its order.
  std::vector<const OutputField*> fields;
  for (const auto& o : info.outputs) fields.push_back(&o);
  std::sort(fields.begin(), fields.end(), [](const OutputField* a, const OutputField* b) { return a->key < b->key; });
  for (const OutputField* o : fields) {
    if (has_column_for(*o, cols)) continue;
    const std::string name = output_column(o->key, cols);
    if (const auto it = cols.find(name); it != cols.end()) {
      make_real(db, name, it->second);
    } else {
      add_result_column(db, name, "metric", o->type);
      cols[name] = {"metric", o->type};
    }
  }
}

void declare_output_columns_of_jobs(Database& db) {
  const auto cols = result_extra_columns(db);
  for (JobKind k : registered_kinds()) {
    const JobKindInfo& info = kind_info(k);
    const bool lacks = std::any_of(info.outputs.begin(), info.outputs.end(),
                                   [&](const OutputField& o) { return !has_column_for(o, cols); });
    if (!info.results_row || !lacks) continue;
    bool has_jobs = false;
    {  // finished before the columns change (SQLite drops no table under an open statement)
      Statement st(db, "SELECT 1 FROM jobs WHERE kind=? LIMIT 1");
      st.bind(1, info.name);
      has_jobs = st.step();
    }
    if (has_jobs) declare_output_columns(db, k);
  }
}

}  // namespace detail

namespace {

bool fits_type(const std::string& type, const json& v) {
  if (v.is_null()) return true;
  if (type == "REAL") return v.is_number();
  if (type == "INTEGER") return v.is_number_integer() || v.is_boolean();
  return v.is_string();
}

}  // namespace

void check_outputs(JobKind kind, const RunOutput& out) {
  const JobKindInfo& info = kind_info(kind);
  if (!out.values.is_null() && !out.values.is_object())
    throw OutputError(fmt::format("job kind '{}': its runner's values are {}, expected an object of its outputs",
                                  info.name, out.values.type_name()));
  std::set<std::string> reported;
  out.each_output([&](const std::string& key, const json& v) {
    const auto o = std::find_if(info.outputs.begin(), info.outputs.end(),
                                [&key = key](const OutputField& f) { return f.key == key; });
    if (o == info.outputs.end()) {
      std::string declared;
      for (const auto& f : info.outputs) declared += (declared.empty() ? "" : ", ") + f.key;
      throw OutputError(fmt::format(
          "job kind '{}': its runner reported the metric '{}', which the kind does not declare (its outputs: {}); "
          "declare it in the kind's registration (JobKindInfo::outputs), which gives it a results column at submit",
          info.name, key, declared.empty() ? "none" : declared));
    }
    if (!reported.insert(key).second)
      throw OutputError(fmt::format("job kind '{}': its runner reported the metric '{}' twice", info.name, key));
    if (!fits_type(o->type, v))
      throw OutputError(
          fmt::format("job kind '{}': its runner reported the metric '{}' as {} ({}), expected {} or null", info.name,
                      key, v.type_name(), v.dump(),
                      o->type == "REAL"      ? "a number"
                      : o->type == "INTEGER" ? "an integer or a flag"
                                             : "a string"));
  });
}

std::vector<std::string> result_columns(Database& db) {
  std::vector<std::string> cols;
  for (const auto& c : detail::fixed_result_columns()) cols.emplace_back(c.name);
  Statement st(db, "SELECT name FROM results_columns ORDER BY role DESC, position");  // params, then metrics
  while (st.step()) cols.push_back(st.get_text(0));
  return cols;
}

std::set<std::string> numeric_result_columns(Database& db) {
  std::set<std::string> out;
  for (const auto& c : detail::fixed_result_columns())
    if (std::string(c.type) != "TEXT") out.insert(c.name);
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
