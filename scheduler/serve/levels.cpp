#include "scheduler/serve/levels.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <tuple>

#include "scheduler/queue/queue.h"

namespace gravsweep::serve {

namespace {

using nlohmann::json;

constexpr std::array<const char*, 6> kStates = {"waiting", "queued", "running", "failed", "done", "dead"};

/// The gravity of a job from its parameters, or from its scenario when no sweep varies it; empty
/// for a job without one.
std::string level_of(db::Database& db, std::int64_t seq, const std::string& params) {
  const auto gravity_in = [](const std::string& text) -> std::string {
    const json j = json::parse(text, nullptr, false);
    if (!j.is_object()) return {};
    const auto g = j.find("gravity_m_s2");
    return g != j.end() && g->is_number() ? fmt::format("{:.6g}", g->get<double>()) : std::string();
  };
  std::string g = gravity_in(params);
  if (!g.empty()) return g;
  db::Statement st(db, "SELECT scenario_json FROM jobs WHERE seq=?");
  st.bind(1, seq);
  return st.step() ? gravity_in(st.get_text(0)) : std::string();
}

struct Tally {
  std::array<std::int64_t, kStates.size()> n{};
  std::int64_t recent = 0;  ///< finished within the window
  double first_start = 0;   ///< the earliest start among its jobs (0: none started)
};

}  // namespace

Reply LevelCounts::reply(db::Database& db) {
  const std::lock_guard<std::mutex> lock(m_);
  const auto now = std::chrono::steady_clock::now();
  if (!fresh_ || now - at_ > std::chrono::seconds(1)) {
    reply_ = compute(db);
    at_ = now;
    fresh_ = reply_.status == 200;
  }
  return reply_;
}

void LevelCounts::read_new_jobs(db::Database& db) {
  db::Statement st(db, "SELECT seq, sweep_id, kind, params_json FROM jobs WHERE seq > ? ORDER BY seq");
  st.bind(1, last_seq_);
  std::vector<std::tuple<std::int64_t, std::string, std::string, std::string>> rows;
  while (st.step()) rows.emplace_back(st.get_int(0), st.get_text(1), st.get_text(2), st.get_text(3));
  for (const auto& [seq, sweep, kind, params] : rows) {
    const std::string key = sweep + '\x1f' + kind + '\x1f' + level_of(db, seq, params);
    const auto [it, added] = group_.try_emplace(key, groups_.size());
    if (added) groups_.push_back(key);
    of_[seq] = it->second;
    last_seq_ = std::max(last_seq_, seq);
  }
}

Reply LevelCounts::compute(db::Database& db) {
  const db::Transaction snapshot(db, db::Transaction::Mode::deferred);
  read_new_jobs(db);
  const double now = queue::clock_s(db);
  std::vector<Tally> tally(groups_.size());
  db::Statement st(db, "SELECT seq, state, coalesce(finished_at, 0), coalesce(started_at, 0) FROM jobs");
  while (st.step()) {
    const auto g = of_.find(st.get_int(0));
    if (g == of_.end()) continue;  // committed after the new jobs were read: counted next time
    Tally& t = tally[g->second];
    const std::string state = st.get_text(1);
    const auto s = std::find(kStates.begin(), kStates.end(), state);
    if (s != kStates.end()) ++t.n[static_cast<std::size_t>(s - kStates.begin())];
    const double finished = st.get_double(2), started = st.get_double(3);
    if (state == "done" && finished > now - kLevelRateWindowS) ++t.recent;
    if (started > 0 && (t.first_start == 0 || started < t.first_start)) t.first_start = started;
  }
  // Sweeps and kinds in name order, the levels from the strongest gravity down.
  std::vector<std::size_t> order(groups_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto parts = [this](std::size_t i) {
    const std::string& k = groups_[i];
    const auto a = k.find('\x1f'), b = k.find('\x1f', a + 1);
    const std::string level = k.substr(b + 1);
    return std::make_tuple(k.substr(0, a), k.substr(a + 1, b - a - 1), level.empty() ? -1.0 : -std::stod(level), level);
  };
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return parts(x) < parts(y); });
  json levels = json::array();
  for (const std::size_t i : order) {
    const auto [sweep, kind, neg_g, level] = parts(i);
    const Tally& t = tally[i];
    json row = {{"sweep", sweep}, {"kind", kind}, {"gravity_m_s2", level.empty() ? json(nullptr) : json(-neg_g)}};
    std::int64_t total = 0;
    for (std::size_t s = 0; s < kStates.size(); ++s) {
      row[kStates[s]] = t.n[s];
      total += t.n[s];
    }
    const std::int64_t left = t.n[0] + t.n[1] + t.n[2] + t.n[3];
    // The rate over the window, or over the time since the level's first start when shorter.
    const double window = t.first_start > 0 ? std::clamp(now - t.first_start, 1.0, kLevelRateWindowS) : 0;
    const double per_s = window > 0 ? static_cast<double>(t.recent) / window : 0;
    row["total"] = total;
    row["done_recently"] = t.recent;
    row["jobs_per_min"] = 60 * per_s;
    row["eta_s"] = left == 0 ? json(0) : per_s > 0 ? json(static_cast<double>(left) / per_s) : json(nullptr);
    levels.push_back(std::move(row));
  }
  Reply r;
  r.body = json({{"now", now}, {"window_s", kLevelRateWindowS}, {"levels", std::move(levels)}})
               .dump(-1, ' ', false, json::error_handler_t::replace);
  return r;
}

}  // namespace gravsweep::serve
