// /api/collapse: the drops in Froude scaling (docs/serve.md). The results rows carry the impact
// speed and the metrics but not the projectile's diameter unless a sweep varies it; the drop's
// scenario (jobs.scenario_json, resolved with its defaults when submitted) always has it, and its
// gravity. A job's scenario never changes, so each is parsed once and kept.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "scheduler/queue/filter.h"
#include "scheduler/serve/api.h"

namespace gravsweep::serve {

namespace {

using nlohmann::json;

struct DropScale {
  double g = std::numeric_limits<double>::quiet_NaN();
  double d = std::numeric_limits<double>::quiet_NaN();
};

/// Gravity and projectile diameter per drop job, read from its scenario once.
class ScaleCache {
 public:
  /// The scales of `ids` (those already known from memory, the others from the jobs table).
  std::vector<DropScale> get(db::Database& db, const std::vector<std::string>& ids) {
    std::vector<std::string> missing;
    {
      const std::lock_guard<std::mutex> lock(m_);
      for (const auto& id : ids)
        if (!known_.count(id)) missing.push_back(id);
    }
    constexpr std::size_t kBatch = 200;
    for (std::size_t from = 0; from < missing.size(); from += kBatch) {
      const std::size_t n = std::min(kBatch, missing.size() - from);
      std::string sql = "SELECT job_id, scenario_json FROM jobs WHERE job_id IN (";
      for (std::size_t i = 0; i < n; ++i) sql += i ? ",?" : "?";
      db::Statement st(db, sql + ")");
      for (std::size_t i = 0; i < n; ++i) st.bind(static_cast<int>(i + 1), missing[from + i]);
      std::unordered_map<std::string, DropScale> read;
      while (st.step()) read[st.get_text(0)] = scale_of(st.get_text(1));
      const std::lock_guard<std::mutex> lock(m_);
      known_.insert(read.begin(), read.end());
    }
    std::vector<DropScale> out;
    out.reserve(ids.size());
    const std::lock_guard<std::mutex> lock(m_);
    for (const auto& id : ids) {
      const auto it = known_.find(id);
      out.push_back(it == known_.end() ? DropScale{} : it->second);
    }
    return out;
  }

 private:
  static DropScale scale_of(const std::string& scenario) {
    DropScale s;
    const json j = json::parse(scenario, nullptr, false);
    if (j.is_discarded()) return s;
    if (const auto g = j.find("gravity_m_s2"); g != j.end() && g->is_number()) s.g = g->get<double>();
    if (const auto p = j.find("projectile"); p != j.end() && p->is_object())
      if (const auto d = p->find("diameter_m"); d != p->end() && d->is_number()) s.d = d->get<double>();
    return s;
  }

  std::mutex m_;
  std::unordered_map<std::string, DropScale> known_;
};

ScaleCache& scale_cache() {
  static ScaleCache c;
  return c;
}

json finite(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

double number(const json& v) { return v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN(); }

}  // namespace

Reply collapse_reply(db::Database& db, const Params& params) {
  queue::ResultsQuery q;
  for (auto [it, end] = params.equal_range("where"); it != end; ++it)
    if (!it->second.empty()) q.where.push_back(it->second);
  q.where.push_back("kind=drop");
  const std::vector<std::string> metrics = {"vc_m_s", "zstop_m", "tstop_s", "apeak_m_s2"};
  const std::vector<std::string> have = queue::result_columns(db);
  const std::set<std::string> present(have.begin(), have.end());
  q.columns = {"job_id"};
  for (const auto& m : metrics)
    if (present.count(m)) q.columns.push_back(m);
  q.limit = kMaxPageRows;
  const std::vector<std::string> columns = {"job_id", "gravity_m_s2", "projectile_diameter_m", "vc_m_s",
                                            "froude", "zstop_over_d", "tstop_sqrt_g_over_d",   "apeak_over_g"};
  json rows = json::array();
  std::int64_t total = 0;
  if (present.count("kind")) {
    db::Transaction tx(db, db::Transaction::Mode::deferred);  // the rows and their count of one snapshot
    queue::ResultsTable t;
    try {
      t = queue::query_results(db, q);
      total = queue::count_results(db, q);
    } catch (const std::invalid_argument& e) {
      return error_reply(400, e.what());
    }
    std::vector<std::string> ids;
    for (const auto& r : t.rows) ids.push_back(r[0].get<std::string>());
    const std::vector<DropScale> scales = scale_cache().get(db, ids);
    for (std::size_t i = 0; i < t.rows.size(); ++i) {
      double m[4];
      for (std::size_t k = 0; k < metrics.size(); ++k) {
        const auto c = std::find(t.columns.begin(), t.columns.end(), metrics[k]);
        m[k] = c == t.columns.end() ? std::nan("") : number(t.rows[i][static_cast<std::size_t>(c - t.columns.begin())]);
      }
      const double g = scales[i].g, d = scales[i].d;
      rows.push_back({ids[i], finite(g), finite(d), finite(m[0]), finite(m[0] / std::sqrt(g * d)), finite(m[1] / d),
                      finite(m[2] * std::sqrt(g / d)), finite(m[3] / g)});
    }
  }
  Reply r;
  r.body = json({{"columns", columns}, {"rows", std::move(rows)}, {"total", total}, {"limit", q.limit}})
               .dump(-1, ' ', false, json::error_handler_t::replace);
  return r;
}

}  // namespace gravsweep::serve
