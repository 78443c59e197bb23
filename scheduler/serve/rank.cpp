#include "scheduler/serve/rank.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <utility>
#include <vector>

#include "results/model/discover.h"
#include "results/model/model_spec.h"
#include "scheduler/pipeline/drop_campaign.h"
#include "scheduler/queue/campaign.h"

namespace gravsweep::serve {

namespace {

using nlohmann::json;

/// Traces read under one hold of the HDF5 lock: a drop's trace asked for meanwhile waits for a
/// few reads at most, not for the whole campaign.
constexpr std::size_t kTracesPerLock = 4;

CampaignState campaign_state(db::Database& db) {
  db::Statement st(db, "SELECT count(*), coalesce(max(finished_at), 0) FROM jobs WHERE kind='drop' AND state='done'");
  CampaignState s;
  if (st.step()) {
    s.drops = st.get_int(0);
    s.last_finished_at = st.get_double(1);
  }
  return s;
}

json state_json(const CampaignState& s) { return {{"drops", s.drops}, {"last_finished_at", s.last_finished_at}}; }

double finite_or_zero(double v) { return std::isfinite(v) ? v : 0.0; }

/// The ranked terms as `model rank --format json` lists them: each round of the named terms, then
/// the held-out test of the generated family when it ran.
json ranking_json(const results::Discovery& d) {
  json rows = json::array();
  const auto add = [&rows](const std::string& round, std::size_t rank, const results::Candidate& c) {
    rows.push_back({round, rank, c.term, finite_or_zero(100 * c.mean_rel_improvement), c.trials_better, c.trials,
                    finite_or_zero(c.p_value), c.significant});
  };
  for (std::size_t r = 0; r < d.rounds.size(); ++r)
    for (std::size_t i = 0; i < d.rounds[r].size(); ++i) add(std::to_string(r + 1), i + 1, d.rounds[r][i]);
  if (d.generated_searched) add("generated", 1, d.generated_test);
  return {{"columns",
           {"round", "rank", "term", "mean_rel_improvement_pct", "trials_better", "trials", "p_signed_rank",
            "significant"}},
          {"rows", std::move(rows)}};
}

}  // namespace

RankWatch::RankWatch(std::string db, std::string files, std::optional<queue::CampaignPaths> paths, double interval_s)
    : db_(std::move(db)), files_(std::move(files)), paths_(std::move(paths)), interval_s_(interval_s) {
  answer_ = {{"state", "computing"}, {"min_drops", kRankMinDrops}, {"for", nullptr}};
  thread_ = std::thread([this] { run(); });
}

RankWatch::~RankWatch() {
  {
    const std::lock_guard<std::mutex> lock(m_);
    stopping_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

Reply RankWatch::reply() const {
  Reply r;
  const std::lock_guard<std::mutex> lock(m_);
  r.body = answer_.dump(-1, ' ', false, json::error_handler_t::replace);
  return r;
}

bool RankWatch::wait(double seconds) {
  std::unique_lock<std::mutex> lock(m_);
  cv_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return stopping_; });
  return !stopping_;
}

void RankWatch::publish(json j) {
  const std::lock_guard<std::mutex> lock(m_);
  answer_ = std::move(j);
}

bool RankWatch::stopping() const {
  const std::lock_guard<std::mutex> lock(m_);
  return stopping_;
}

void RankWatch::run() {
  std::optional<CampaignState> done;  // the state of the answer published last
  do {
    try {
      db::Database db = queue::open_campaign(db_, queue::OpenMode::read, files_);
      while (true) {
        if (!done || !(campaign_state(db) == *done)) done = compute(db);
        if (!wait(interval_s_)) return;
      }
    } catch (const std::exception& e) {  // the database went away: say so, look again later
      publish({{"state", "error"},
               {"min_drops", kRankMinDrops},
               {"for", nullptr},
               {"error", fmt::format("the campaign database did not answer: {}", e.what())}});
      done.reset();
    }
  } while (wait(interval_s_));
}

std::optional<CampaignState> RankWatch::compute(db::Database& db) {
  pipeline::DropRefs drops;
  CampaignState state;
  {
    const db::Transaction snapshot(db, db::Transaction::Mode::deferred);  // the state and its drops
    state = campaign_state(db);
    if (paths_) drops = pipeline::finished_drops(db, *paths_, {});
  }
  json j = {{"min_drops", kRankMinDrops}, {"for", state_json(state)}};
  if (state.drops < kRankMinDrops) {
    j["state"] = "not enough drops";
    j["message"] = fmt::format("{} finished drop{}: `model rank` needs at least {}", state.drops,
                               state.drops == 1 ? "" : "s", kRankMinDrops);
    publish(std::move(j));
    return state;
  }
  if (!paths_) {
    j["state"] = "error";
    j["error"] = "the campaign's files root (its traces) is unknown: serve it with --files";
    publish(std::move(j));
    return state;
  }
  {
    const std::lock_guard<std::mutex> lock(m_);
    answer_["state"] = "computing";  // the previous verdict stays shown meanwhile
    answer_["computing_for"] = state_json(state);
  }
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const std::optional<results::Campaign> c = load(drops.refs);
    if (!c) return std::nullopt;  // stopping
    j["trials"] = c->trials.size();
    j["left_out"] = c->issues.size();
    json reasons = json::array();
    for (std::size_t i = 0; i < std::min<std::size_t>(3, c->issues.size()); ++i)
      reasons.push_back(c->issues[i].message);
    j["left_out_reasons"] = std::move(reasons);
    if (c->trials.size() < static_cast<std::size_t>(kRankMinDrops)) {
      j["state"] = "not enough drops";
      j["message"] = fmt::format("{} usable drops of {} finished: `model rank` needs at least {}", c->trials.size(),
                                 state.drops, kRankMinDrops);
      publish(std::move(j));
      return state;
    }
    const results::Discovery d = results::discover(*c, results::parse_model("base"));
    j["state"] = "ready";
    j["baseline"] = d.baseline;
    j["verdict"] = d.verdict;
    j["model"] = d.named_model;
    j["ranking"] = ranking_json(d);
    j["computed_at"] = queue::clock_s(db);
    j["compute_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  } catch (const db::DbError&) {
    throw;
  } catch (const std::exception& e) {  // a campaign the model cannot rank (one gravity level, ...)
    j["state"] = "error";
    j["error"] = e.what();
  }
  publish(std::move(j));
  return state;
}

std::optional<results::Campaign> RankWatch::load(const std::vector<results::DemTraceRef>& refs) const {
  results::Campaign c;
  c.directory = db_;
  for (std::size_t from = 0; from < refs.size(); from += kTracesPerLock) {
    if (stopping()) return std::nullopt;
    const std::vector<results::DemTraceRef> part(
        refs.begin() + static_cast<std::ptrdiff_t>(from),
        refs.begin() + static_cast<std::ptrdiff_t>(std::min(refs.size(), from + kTracesPerLock)));
    results::Campaign some;
    {
      const std::lock_guard<std::mutex> lock(hdf5_mutex());
      some = results::load_dem_campaign(db_, part);
    }
    for (auto& t : some.trials) c.trials.push_back(std::move(t));
    for (auto& i : some.issues) c.issues.push_back(std::move(i));
  }
  return c;
}

}  // namespace gravsweep::serve
