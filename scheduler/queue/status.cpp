// Status: counts per sweep, kind and state in one read snapshot, running jobs, the ETA.
#include <algorithm>
#include <map>

#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

namespace {

using SweepKind = std::pair<std::string, std::string>;
/// Jobs left to run (waiting, queued, failed) per (sweep, kind), each job under the sweep that
/// created it only.
using Remaining = std::map<SweepKind, std::int64_t>;

std::int64_t& count_of(StateCounts& c, JobState state) {
  switch (state) {
    case JobState::waiting:
      return c.waiting;
    case JobState::queued:
      return c.queued;
    case JobState::running:
      return c.running;
    case JobState::failed:
      return c.failed;
    case JobState::done:
      return c.done;
    case JobState::dead:
      break;
  }
  return c.dead;
}

/// s.per_sweep: jobs counted under the sweep that created them (covering index jobs_sweep_state),
/// plus the few memberships of jobs shared with another sweep; returns the remaining work.
Remaining count_states(Database& db, Status& s) {
  Remaining remaining;
  Statement own(db, "SELECT sweep_id, kind, state, count(*) FROM jobs GROUP BY sweep_id, kind, state");
  Statement shared(db,
                   "SELECT sj.sweep_id, j.kind, j.state, count(*) FROM sweep_jobs sj JOIN jobs j ON "
                   "j.job_id=sj.job_id WHERE sj.shared=1 GROUP BY sj.sweep_id, j.kind, j.state");
  std::map<SweepKind, StateCounts> m;  // ordered by sweep, then kind
  for (Statement* q : {&own, &shared}) {
    while (q->step()) {
      const SweepKind key{q->get_text(0), q->get_text(1)};
      StateCounts& c = m[key];
      c.sweep = key.first;
      c.kind = key.second;
      const JobState state = parse_state(q->get_text(2));
      const std::int64_t n = q->get_int(3);
      count_of(c, state) += n;
      const bool left = state == JobState::waiting || state == JobState::queued || state == JobState::failed;
      if (q == &own && left) remaining[key] += n;
    }
  }
  for (auto& [key, c] : m) s.per_sweep.push_back(std::move(c));
  return remaining;
}

/// Counts `r` under its lease owner in `workers` (a few entries: one a worker process).
void note_worker(std::vector<WorkerSeen>& workers, const RunningJob& r) {
  auto w = std::find_if(workers.begin(), workers.end(), [&](const WorkerSeen& x) { return x.owner == r.owner; });
  if (w == workers.end()) w = workers.insert(workers.end(), WorkerSeen{r.owner, 0, 0, true});
  ++w->jobs;
  w->last_heartbeat_at = std::max(w->last_heartbeat_at, r.heartbeat_at);
  w->stale = w->stale && r.stale;
}

/// s.running (at most max_running live ones, every stale one), active workers, stale leases.
void read_running(Database& db, Status& s, double now, std::size_t max_running) {
  Statement st(db,
               "SELECT job_id, kind, coalesce(lease_owner,''), coalesce(phase,''), coalesce(detail,''), "
               "coalesce(progress,0), coalesce(started_at,0), coalesce(heartbeat_at,0), coalesce(lease_expires,0), "
               "attempts FROM jobs WHERE state='running' ORDER BY started_at");
  while (st.step()) {
    RunningJob r{st.get_text(0),
                 st.get_text(1),
                 st.get_text(2),
                 st.get_text(3),
                 st.get_text(4),
                 st.get_double(5),
                 st.get_double(6),
                 st.get_double(7),
                 st.get_double(8),
                 static_cast<int>(st.get_int(9)),
                 false};
    r.stale = r.lease_expires < now;
    if (r.stale)
      ++s.stale_leases;
    else
      ++s.active_workers;
    note_worker(s.workers, r);
    if (s.running.size() < max_running || r.stale) s.running.push_back(std::move(r));
  }
}

/// Median runtime of the attempts that finished, per kind, with the work left of each kind (the
/// runtimes table).
std::map<std::string, KindRuntime> kind_runtimes(Database& db, const Status& s, const Remaining& remaining) {
  std::map<std::string, KindRuntime> kinds;
  for (const auto& [key, n] : remaining) {
    kinds[key.second].kind = key.second;
    kinds[key.second].remaining += n;
  }
  for (const auto& r : s.running) kinds[r.kind].kind = r.kind;
  Statement cnt(db, "SELECT count(*) FROM attempts WHERE kind=? AND outcome='done'");
  Statement med(db,
                "SELECT runtime_s FROM attempts WHERE kind=? AND outcome='done' ORDER BY runtime_s LIMIT 1 OFFSET ?");
  for (auto& [name, k] : kinds) {
    cnt.reset();
    cnt.bind(1, name);
    cnt.step();
    k.finished = cnt.get_int(0);
    if (k.finished == 0) continue;
    med.reset();
    med.bind(1, name).bind(2, k.finished / 2);
    if (med.step()) k.median_s = med.get_double(0);
  }
  return kinds;
}

/// The runtime to expect of a job of one sweep and kind: the median of the attempts of the same
/// sweep and kind that finished (one sweep's 1 g drops say little about another's low-gravity
/// ones); with none, what its running jobs project (elapsed / progress, once past 5 %); with
/// neither, the kind's median over every sweep.
class RuntimeEstimate {
 public:
  RuntimeEstimate(Database& db, const Status& s, const std::map<std::string, KindRuntime>& kinds, double now)
      : s_(s),
        kinds_(kinds),
        now_(now),
        cnt_(db,
             "SELECT count(*) FROM attempts a JOIN jobs j ON j.job_id=a.job_id WHERE j.sweep_id=? AND a.kind=? AND "
             "a.outcome='done'"),
        med_(db,
             "SELECT a.runtime_s FROM attempts a JOIN jobs j ON j.job_id=a.job_id WHERE j.sweep_id=? AND a.kind=? "
             "AND a.outcome='done' ORDER BY a.runtime_s LIMIT 1 OFFSET ?") {
    Statement sweep_of(db, "SELECT sweep_id FROM jobs WHERE job_id=?");
    for (const auto& r : s.running) {
      sweep_of.reset();
      sweep_of.bind(1, r.job_id);
      if (sweep_of.step()) sweep_of_running_[r.job_id] = sweep_of.get_text(0);
    }
  }

  /// The sweep of a running job ("" when it is gone).
  [[nodiscard]] std::string sweep_of(const std::string& job_id) const {
    const auto it = sweep_of_running_.find(job_id);
    return it == sweep_of_running_.end() ? std::string() : it->second;
  }

  /// false when nothing is known of the kind.
  bool runtime_s(const std::string& sweep, const std::string& kind, double& out) {
    cnt_.reset();
    cnt_.bind(1, sweep).bind(2, kind);
    cnt_.step();
    if (const std::int64_t n = cnt_.get_int(0); n > 0) {
      med_.reset();
      med_.bind(1, sweep).bind(2, kind).bind(3, n / 2);
      if (med_.step()) {
        out = med_.get_double(0);
        return true;
      }
    }
    if (projected(sweep, kind, out)) return true;
    const auto k = kinds_.find(kind);
    if (k == kinds_.end()) return false;
    out = k->second.median_s;
    return k->second.finished > 0;
  }

 private:
  const Status& s_;
  const std::map<std::string, KindRuntime>& kinds_;
  double now_;
  Statement cnt_, med_;
  std::map<std::string, std::string> sweep_of_running_;

  bool projected(const std::string& sweep, const std::string& kind, double& out) const {
    std::vector<double> p;
    for (const auto& r : s_.running)
      if (!r.stale && r.kind == kind && sweep_of(r.job_id) == sweep && r.progress > 0.05 && r.started_at > 0)
        p.push_back((now_ - r.started_at) / r.progress);
    if (p.empty()) return false;
    std::sort(p.begin(), p.end());
    out = p[p.size() / 2];
    return true;
  }
};

/// Seconds until the work left is done by the active workers; < 0 when some kind has no runtime
/// to go by.
double eta_s(RuntimeEstimate& est, const Status& s, const Remaining& remaining) {
  double total_s = 0;
  for (const auto& [key, n] : remaining) {
    double m = 0;
    if (n == 0) continue;
    if (!est.runtime_s(key.first, key.second, m)) return -1;
    total_s += static_cast<double>(n) * m;
  }
  for (const auto& r : s.running) {
    double m = 0;
    if (r.stale) continue;
    if (!est.runtime_s(est.sweep_of(r.job_id), r.kind, m)) return -1;
    total_s += std::max(0.0, m * (1 - r.progress));
  }
  return total_s / static_cast<double>(std::max<std::int64_t>(1, s.active_workers));
}

/// Blocked and released counts, the latest dead jobs' errors, beds rebuilt after a mismatch.
void read_troubles(Database& db, Status& s) {
  {
    Statement st(db, "SELECT count(*) FROM jobs WHERE state='dead' AND blocked_by IS NOT NULL");
    st.step();
    s.blocked = st.get_int(0);
  }
  {
    Statement st(
        db,
        "SELECT coalesce(sum(releases), 0), coalesce(sum(CASE WHEN releases>0 AND state!='done' THEN 1 "
        "ELSE 0 END), 0), coalesce(sum(CASE WHEN state='dead' AND blocked_by IS NULL AND (SELECT a.outcome FROM "
        "attempts a WHERE "
        "a.job_id=jobs.job_id ORDER BY a.attempt_id DESC LIMIT 1)='released' THEN 1 ELSE 0 END), 0) "
        "FROM jobs");  // stopped by releases: dead of its own (not blocked), its last attempt released
    st.step();
    s.released_attempts = st.get_int(0);
    s.released_jobs = st.get_int(1);
    s.stopped_by_releases = st.get_int(2);
  }
  {
    Statement st(db,
                 "SELECT job_id, coalesce(last_error,'') FROM jobs WHERE state='dead' AND "
                 "blocked_by IS NULL ORDER BY finished_at DESC LIMIT 5");
    while (st.step()) s.recent_errors.emplace_back(st.get_text(0), st.get_text(1));
  }
  {
    Statement st(db,
                 "SELECT job_id, error FROM attempts WHERE outcome='failed' AND error LIKE '% checksum mismatch: %' "
                 "GROUP BY job_id, error ORDER BY max(ended_at) DESC LIMIT 20");
    while (st.step()) s.dependency_mismatches.emplace_back(st.get_text(0), st.get_text(1));
  }
}

}  // namespace

Status status(Database& db, std::size_t max_running) {
  Status s;
  const double now = clock_s(db);
  // A read transaction gives one consistent snapshot (WAL: does not block writers).
  Transaction tx(db, Transaction::Mode::deferred);
  const Remaining remaining = count_states(db, s);
  read_running(db, s, now, max_running);
  const auto kinds = kind_runtimes(db, s, remaining);
  for (const auto& [name, k] : kinds) s.runtimes.push_back(k);
  RuntimeEstimate est(db, s, kinds, now);
  s.eta_s = eta_s(est, s, remaining);
  read_troubles(db, s);
  return s;
}

namespace {

nlohmann::json running_json(const RunningJob& r) {
  return {{"job_id", r.job_id},
          {"kind", r.kind},
          {"attempt", r.attempt},
          {"worker", r.owner},
          {"phase", r.phase},
          {"progress", r.progress},
          {"detail", r.detail},
          {"started_at", r.started_at},
          {"heartbeat_at", r.heartbeat_at},
          {"lease_expires", r.lease_expires},
          {"stale", r.stale}};
}

}  // namespace

nlohmann::json status_json(const Status& s) {
  json j;
  j["sweeps"] = json::array();
  for (const auto& c : s.per_sweep)
    j["sweeps"].push_back({{"sweep", c.sweep},
                           {"kind", c.kind},
                           {"waiting", c.waiting},
                           {"queued", c.queued},
                           {"running", c.running},
                           {"failed", c.failed},
                           {"done", c.done},
                           {"dead", c.dead}});
  j["running"] = json::array();
  for (const auto& r : s.running) j["running"].push_back(running_json(r));
  j["workers"] = json::array();
  for (const auto& w : s.workers)
    j["workers"].push_back(
        {{"worker", w.owner}, {"jobs", w.jobs}, {"last_heartbeat_at", w.last_heartbeat_at}, {"stale", w.stale}});
  j["stale_leases"] = s.stale_leases;
  j["released_attempts"] = s.released_attempts;
  j["released_jobs"] = s.released_jobs;
  j["stopped_by_releases"] = s.stopped_by_releases;
  j["active_workers"] = s.active_workers;
  j["eta_s"] = s.eta_s >= 0 ? json(s.eta_s) : json(nullptr);
  j["runtimes"] = json::array();
  for (const auto& r : s.runtimes)
    j["runtimes"].push_back(
        {{"kind", r.kind}, {"finished", r.finished}, {"median_runtime_s", r.median_s}, {"remaining", r.remaining}});
  j["dead_recent"] = json::array();
  for (const auto& [id, err] : s.recent_errors) j["dead_recent"].push_back({{"job_id", id}, {"error", err}});
  j["bed_checksum_mismatches"] = json::array();
  for (const auto& [id, err] : s.dependency_mismatches)
    j["bed_checksum_mismatches"].push_back({{"drop_job_id", id}, {"error", err}});
  return j;
}

TroubledPage troubled_jobs(Database& db, std::int64_t offset, std::int64_t limit) {
  TroubledPage page;
  Transaction tx(db, Transaction::Mode::deferred);  // the count and the page of one snapshot
  {
    Statement st(db, "SELECT count(*) FROM jobs WHERE state IN ('failed','dead')");  // index jobs_claim
    st.step();
    page.total = st.get_int(0);
  }
  Statement st(db,
               "SELECT job_id, sweep_id, kind, state, coalesce(last_error,''), coalesce(blocked_by,''), attempts, "
               "max_attempts, coalesce(finished_at,0) FROM jobs WHERE state IN ('failed','dead') "
               "ORDER BY coalesce(finished_at,0) DESC, seq DESC LIMIT ? OFFSET ?");
  st.bind(1, std::max<std::int64_t>(0, limit)).bind(2, std::max<std::int64_t>(0, offset));
  while (st.step())
    page.jobs.push_back({st.get_text(0), st.get_text(1), st.get_text(2), st.get_text(3), st.get_text(4), st.get_text(5),
                         static_cast<int>(st.get_int(6)), static_cast<int>(st.get_int(7)), st.get_double(8)});
  return page;
}

std::vector<AttemptRecord> job_attempts(Database& db, const std::string& job_id, std::int64_t limit) {
  Statement st(db,
               "SELECT attempt, worker, host, code_version, outcome, coalesce(error,''), threads, started_at, "
               "coalesce(ended_at,0), coalesce(runtime_s,0) FROM attempts WHERE job_id=? "
               "ORDER BY attempt_id DESC LIMIT ?");  // index attempts_job
  st.bind(1, job_id).bind(2, std::max<std::int64_t>(0, limit));
  std::vector<AttemptRecord> out;
  while (st.step())
    out.push_back({static_cast<int>(st.get_int(0)), st.get_text(1), st.get_text(2), st.get_text(3), st.get_text(4),
                   st.get_text(5), static_cast<int>(st.get_int(6)), st.get_double(7), st.get_double(8),
                   st.get_double(9)});
  return out;
}

std::string done_output_path(Database& db, const std::string& job_id) {
  Statement st(db,
               "SELECT output_path FROM attempts WHERE job_id=? AND outcome='done' AND output_path IS NOT NULL "
               "ORDER BY attempt DESC LIMIT 1");
  st.bind(1, job_id);
  return st.step() ? st.get_text(0) : std::string();
}

}  // namespace gravsweep::queue
