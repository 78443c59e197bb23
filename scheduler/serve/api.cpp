#include "scheduler/serve/api.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cctype>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "results/io/table.h"
#include "results/io/trace_file.h"
#include "results/processing/metric_fields.h"
#include "scheduler/queue/filter.h"

namespace gravsweep::serve {

namespace {

using nlohmann::json;

/// A request the API refuses: its HTTP status and why.
struct ApiError : std::runtime_error {
  int status;
  ApiError(int s, const std::string& what) : std::runtime_error(what), status(s) {}
};

Reply json_reply(const json& j) {
  Reply r;
  // Replace: a stored text that is not UTF-8 (an error message cut mid-character) must not fail
  // the whole reply.
  r.body = j.dump(-1, ' ', false, json::error_handler_t::replace);
  return r;
}

const std::string* param(const Params& p, const std::string& name) {
  const auto it = p.find(name);
  return it == p.end() ? nullptr : &it->second;
}

/// An integer parameter in [lo, hi]; `fallback` when absent or empty.
std::int64_t int_param(const Params& p, const std::string& name, std::int64_t fallback, std::int64_t lo,
                       std::int64_t hi) {
  const std::string* v = param(p, name);
  if (!v || v->empty()) return fallback;
  std::size_t used = 0;
  long long n = 0;
  try {
    n = std::stoll(*v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != v->size() || n < lo || n > hi)
    throw ApiError(400, fmt::format("{}={}: expected a whole number from {} to {}", name, *v, lo, hi));
  return n;
}

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  std::size_t from = 0;
  while (from <= s.size()) {
    const std::size_t to = std::min(s.find(',', from), s.size());
    if (to > from) out.push_back(s.substr(from, to - from));
    from = to + 1;
  }
  return out;
}

/// The query of /api/results from its parameters (the checks of the grammar come later, in
/// query_results: std::invalid_argument).
queue::ResultsQuery results_query(db::Database& db, const Params& p, bool csv) {
  queue::ResultsQuery q;
  for (auto [it, end] = p.equal_range("where"); it != end; ++it)
    if (!it->second.empty()) q.where.push_back(it->second);
  if (const std::string* s = param(p, "sweep")) q.sweep = *s;
  if (const std::string* s = param(p, "sort"); s && !s->empty()) {
    q.descending = (*s)[0] == '-';
    q.order_by = q.descending ? s->substr(1) : *s;
  }
  // No columns named: as `results`, a table shows the job, the parameters and the paper's metrics,
  // a CSV export every column (empty: all).
  const std::string* cols = param(p, "columns");
  if (cols && *cols != "all" && !cols->empty())
    q.columns = split_commas(*cols);
  else if ((!cols || cols->empty()) && !csv)
    q.columns = queue::summary_result_columns(db, results::headline_metric_keys());
  q.offset = int_param(p, "offset", 0, 0, std::numeric_limits<std::int64_t>::max() / 2);
  q.limit = csv ? int_param(p, "limit", kMaxCsvRows, 0, kMaxCsvRows)
                : int_param(p, "limit", kDefaultPageRows, 0, kMaxPageRows);
  return q;
}

json numeric_columns_json(db::Database& db) {
  const auto numeric = queue::numeric_result_columns(db);
  json a = json::array();
  for (const auto& c : queue::result_columns(db))
    if (numeric.count(c)) a.push_back(c);
  return a;
}

Reply results_unchecked(db::Database& db, const Params& p) {
  const std::string* format = param(p, "format");
  const bool csv = format && *format == "csv";
  if (format && !csv && *format != "json") throw ApiError(400, fmt::format("format={}: expected json or csv", *format));
  const queue::ResultsQuery q = results_query(db, p, csv);
  db::Transaction tx(db, db::Transaction::Mode::deferred);  // the rows and their count of one snapshot
  queue::ResultsTable t;
  std::int64_t total = 0;
  try {
    t = queue::query_results(db, q);
    total = queue::count_results(db, q);
  } catch (const std::invalid_argument& e) {
    throw ApiError(400, e.what());
  }
  if (csv) {
    results::Table table(t.columns);
    for (auto& row : t.rows) table.add_values(std::move(row));
    Reply r;
    r.content_type = "text/csv; charset=utf-8";
    r.body = table.csv();
    r.download_name = "results.csv";
    return r;
  }
  json rows = json::array();
  for (auto& row : t.rows) rows.push_back(std::move(row));
  return json_reply({{"columns", t.columns},
                     {"rows", std::move(rows)},
                     {"total", total},
                     {"offset", q.offset},
                     {"limit", q.limit},
                     {"all_columns", queue::result_columns(db)},
                     {"numeric_columns", numeric_columns_json(db)}});
}

/// Every `stride`-th sample of `v`, the last one kept.
json thinned(const std::vector<double>& v, std::size_t stride) {
  json a = json::array();
  for (std::size_t i = 0; i < v.size(); i += stride) a.push_back(std::isfinite(v[i]) ? json(v[i]) : json(nullptr));
  if (!v.empty() && (v.size() - 1) % stride != 0) a.push_back(std::isfinite(v.back()) ? json(v.back()) : json(nullptr));
  return a;
}

json trace_json(const std::filesystem::path& file, std::int64_t points) {
  results::TraceData d;
  {
    const std::lock_guard<std::mutex> lock(hdf5_mutex());
    d = results::read_trace(file);
  }
  const std::size_t n = d.size();
  const auto stride = std::max<std::size_t>(1, (n + static_cast<std::size_t>(points) - 1) / points);
  return {{"samples", n},
          {"stride", stride},
          {"gravity_m_s2", d.info.gravity_m_s2},
          {"projectile_diameter_m", d.info.projectile_diameter_m},
          {"stopped", d.stopped},
          {"t_s", thinned(d.raw.t_s, stride)},
          {"accel_up_m_s2", thinned(d.raw.accel_up_m_s2, stride)},
          {"depth_m", thinned(d.raw.depth_m, stride)},
          {"velocity_down_m_s", thinned(d.raw.velocity_down_m_s, stride)}};
}

Reply drop_unchecked(db::Database& db, const queue::CampaignPaths* paths, const std::string& id, const Params& p) {
  if (!is_job_id(id)) throw ApiError(404, fmt::format("'{}' is not a job id (hexadecimal digits)", id));
  const std::int64_t points = int_param(p, "points", kDefaultTracePoints, 2, kMaxTracePoints);
  queue::ResultsQuery q;
  q.where = {"job_id='" + id + "'"};  // quoted: an id of digits alone is still text
  q.limit = 1;
  const queue::ResultsTable t = queue::query_results(db, q);
  if (t.rows.empty()) throw ApiError(404, fmt::format("job {} has no results row (unknown, or not finished)", id));
  json row = json::object();
  for (std::size_t c = 0; c < t.columns.size(); ++c) row[t.columns[c]] = t.rows[0][c];
  json out = {{"job_id", id}, {"row", row}, {"trace", nullptr}};
  const json& kind = row["kind"];
  const json& rel = row["trace_path"];
  if (kind != "drop" || !rel.is_string()) {
    out["trace_error"] = fmt::format("a {} job has no trace", kind.is_string() ? kind.get<std::string>() : "?");
    return json_reply(out);
  }
  if (!paths) {
    out["trace_error"] = "the campaign's files root is unknown: serve it with --files";
    return json_reply(out);
  }
  const std::filesystem::path file = paths->abs(rel.get<std::string>());
  try {
    out["trace"] = trace_json(file, points);
  } catch (const std::exception& e) {  // moved, deleted, unreadable: the row still answers
    out["trace_error"] = fmt::format("cannot read the trace '{}': {}", file.string(), e.what());
  }
  return json_reply(out);
}

/// Runs `f`, turning a refusal into its reply.
template <class F>
Reply guarded(F&& f) {
  try {
    return f();
  } catch (const ApiError& e) {
    return error_reply(e.status, e.what());
  }
}

}  // namespace

bool is_job_id(const std::string& id) {
  return !id.empty() && id.size() <= 64 &&
         std::all_of(id.begin(), id.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); });
}

std::mutex& hdf5_mutex() {
  static std::mutex m;
  return m;
}

Reply error_reply(int status, const std::string& what) {
  Reply r = json_reply({{"error", what}});
  r.status = status;
  return r;
}

Reply status_reply(db::Database& db, const std::string& campaign) {
  const auto t0 = std::chrono::steady_clock::now();
  const queue::Status s = queue::status(db, 50);
  json j = queue::status_json(s);
  j["campaign"] = campaign;
  j["now"] = queue::clock_s(db);
  j["query_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return json_reply(j);
}

Reply results_reply(db::Database& db, const Params& params) {
  return guarded([&] { return results_unchecked(db, params); });
}

Reply failed_reply(db::Database& db, const Params& params) {
  return guarded([&] {
    const auto offset = int_param(params, "offset", 0, 0, std::numeric_limits<std::int64_t>::max() / 2);
    const auto limit = int_param(params, "limit", kDefaultPageRows, 0, kMaxPageRows);
    const queue::TroubledPage page = queue::troubled_jobs(db, offset, limit);
    json jobs = json::array();
    for (const auto& j : page.jobs)
      jobs.push_back({{"job_id", j.job_id},
                      {"sweep", j.sweep},
                      {"kind", j.kind},
                      {"state", j.state},
                      {"attempts", j.attempts},
                      {"max_attempts", j.max_attempts},
                      {"finished_at", j.finished_at > 0 ? json(j.finished_at) : json(nullptr)},
                      {"blocked_by", j.blocked_by.empty() ? json(nullptr) : json(j.blocked_by)},
                      {"error", j.error}});
    return json_reply({{"total", page.total}, {"offset", offset}, {"limit", limit}, {"jobs", std::move(jobs)}});
  });
}

Reply attempts_reply(db::Database& db, const std::string& job_id) {
  return guarded([&] {
    if (!is_job_id(job_id)) throw ApiError(404, fmt::format("'{}' is not a job id (hexadecimal digits)", job_id));
    json attempts = json::array();
    for (const auto& a : queue::job_attempts(db, job_id, kMaxAttempts)) {
      const auto when = [](double t) { return t > 0 ? json(t) : json(nullptr); };
      attempts.push_back({{"attempt", a.attempt},
                          {"outcome", a.outcome},
                          {"worker", a.worker},
                          {"host", a.host},
                          {"threads", a.threads},
                          {"code_version", a.code_version},
                          {"started_at", when(a.started_at)},
                          {"ended_at", when(a.ended_at)},
                          {"runtime_s", when(a.runtime_s)},
                          {"error", a.error}});
    }
    if (attempts.empty())
      throw ApiError(404, fmt::format("job {} has no attempts (unknown, or never claimed)", job_id));
    return json_reply({{"job_id", job_id}, {"attempts", std::move(attempts)}});
  });
}

Reply drop_reply(db::Database& db, const queue::CampaignPaths* paths, const std::string& job_id, const Params& params) {
  return guarded([&] { return drop_unchecked(db, paths, job_id, params); });
}

}  // namespace gravsweep::serve
