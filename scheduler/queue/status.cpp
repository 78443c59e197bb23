// Status: counts per sweep, kind and state in one read snapshot, running jobs, the ETA.
#include <algorithm>
#include <map>

#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

using db::Database;
using db::Statement;
using db::Transaction;
using nlohmann::json;
namespace fs = std::filesystem;

Status status(Database& db, std::size_t max_running) {
  Status s;
  const double now = clock_s(db);
  // A read transaction gives one consistent snapshot (WAL: does not block writers).
  Transaction tx(db, Transaction::Mode::deferred);
  std::map<std::pair<std::string, std::string>, std::int64_t> remaining;  // per (sweep, kind), each job once
  {
    // Jobs counted under the sweep that created them (covering index jobs_sweep_state), plus the
    // few memberships of jobs shared with another sweep.
    Statement own(db, "SELECT sweep_id, kind, state, count(*) FROM jobs GROUP BY sweep_id, kind, state");
    Statement shared(db,
                     "SELECT sj.sweep_id, j.kind, j.state, count(*) FROM sweep_jobs sj JOIN jobs j ON "
                     "j.job_id=sj.job_id WHERE sj.shared=1 GROUP BY sj.sweep_id, j.kind, j.state");
    std::map<std::pair<std::string, std::string>, StateCounts> m;
    std::vector<std::pair<std::string, std::string>> order;
    for (Statement* q : {&own, &shared}) {
      Statement& st = *q;
      while (st.step()) {
        const auto key = std::make_pair(st.get_text(0), st.get_text(1));
        if (!m.count(key)) {
          order.push_back(key);
          m[key].sweep = key.first;
          m[key].kind = key.second;
        }
        auto& c = m[key];
        const JobState state = parse_state(st.get_text(2));
        const std::int64_t n = st.get_int(3);
        switch (state) {
          case JobState::waiting:
            c.waiting += n;
            break;
          case JobState::queued:
            c.queued += n;
            break;
          case JobState::running:
            c.running += n;
            break;
          case JobState::failed:
            c.failed += n;
            break;
          case JobState::done:
            c.done += n;
            break;
          case JobState::dead:
            c.dead += n;
            break;
        }
        const bool left = state == JobState::waiting || state == JobState::queued || state == JobState::failed;
        if (q == &own && left) remaining[key] += n;
      }
    }
    std::sort(order.begin(), order.end());
    for (const auto& k : order) s.per_sweep.push_back(m[k]);
  }
  {
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
      if (s.running.size() < max_running || r.stale) s.running.push_back(std::move(r));
    }
  }
  {
    // Remaining work per kind (the table), and the ETA from the median runtime of finished
    // attempts of the same sweep and kind: one sweep's 1 g drops say little about another's
    // low-gravity ones. A sweep with none finished yet of that kind takes the kind's median.
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
      if (k.finished > 0) {
        med.reset();
        med.bind(1, name).bind(2, k.finished / 2);
        if (med.step()) k.median_s = med.get_double(0);
      }
      s.runtimes.push_back(k);
    }
    Statement cnt_sk(db,
                     "SELECT count(*) FROM attempts a JOIN jobs j ON j.job_id=a.job_id WHERE j.sweep_id=? AND "
                     "a.kind=? AND a.outcome='done'");
    Statement med_sk(db,
                     "SELECT a.runtime_s FROM attempts a JOIN jobs j ON j.job_id=a.job_id WHERE j.sweep_id=? AND "
                     "a.kind=? AND a.outcome='done' ORDER BY a.runtime_s LIMIT 1 OFFSET ?");
    // The sweep of each running job, and for a sweep with nothing of a kind finished yet, the
    // runtime its running jobs of that kind project (elapsed / progress, once past 5 %).
    std::map<std::string, std::string> sweep_of_running;
    {
      Statement sweep_of(db, "SELECT sweep_id FROM jobs WHERE job_id=?");
      for (const auto& r : s.running) {
        sweep_of.reset();
        sweep_of.bind(1, r.job_id);
        if (sweep_of.step()) sweep_of_running[r.job_id] = sweep_of.get_text(0);
      }
    }
    auto projected = [&](const std::string& sweep, const std::string& kind, double& out) {
      std::vector<double> p;
      for (const auto& r : s.running)
        if (!r.stale && r.kind == kind && sweep_of_running[r.job_id] == sweep && r.progress > 0.05 && r.started_at > 0)
          p.push_back((now - r.started_at) / r.progress);
      if (p.empty()) return false;
      std::sort(p.begin(), p.end());
      out = p[p.size() / 2];
      return true;
    };
    // The median runtime for a job of this sweep and kind; false when nothing is known of the kind.
    auto median_for = [&](const std::string& sweep, const std::string& kind, double& out) {
      cnt_sk.reset();
      cnt_sk.bind(1, sweep).bind(2, kind);
      cnt_sk.step();
      if (const std::int64_t n = cnt_sk.get_int(0); n > 0) {
        med_sk.reset();
        med_sk.bind(1, sweep).bind(2, kind).bind(3, n / 2);
        if (med_sk.step()) {
          out = med_sk.get_double(0);
          return true;
        }
      }
      if (projected(sweep, kind, out)) return true;
      const auto& k = kinds[kind];
      out = k.median_s;
      return k.finished > 0;
    };
    double total = 0;
    bool known = true;
    for (const auto& [key, n] : remaining) {
      double m = 0;
      if (n > 0 && median_for(key.first, key.second, m))
        total += static_cast<double>(n) * m;
      else if (n > 0)
        known = false;
    }
    for (const auto& r : s.running) {
      if (r.stale) continue;
      double m = 0;
      if (median_for(sweep_of_running[r.job_id], r.kind, m))
        total += std::max(0.0, m * (1 - r.progress));
      else
        known = false;
    }
    if (known) s.eta_s = total / static_cast<double>(std::max<std::int64_t>(1, s.active_workers));
  }
  {
    Statement st(db, "SELECT count(*) FROM jobs WHERE state='dead' AND blocked_by IS NOT NULL");
    st.step();
    s.blocked = st.get_int(0);
  }
  {
    Statement st(db,
                 "SELECT coalesce(sum(releases), 0), coalesce(sum(CASE WHEN releases>0 AND state!='done' THEN 1 "
                 "ELSE 0 END), 0), coalesce(sum(CASE WHEN state='dead' AND last_error LIKE 'released % times%without "
                 "finishing%' THEN 1 ELSE 0 END), 0) FROM jobs");
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
                 "SELECT job_id, error FROM attempts WHERE kind='drop' AND error LIKE 'bed checksum mismatch%' "
                 "GROUP BY job_id, error ORDER BY max(ended_at) DESC LIMIT 20");
    while (st.step()) s.beds_rebuilt.emplace_back(st.get_text(0), st.get_text(1));
  }
  return s;
}

}  // namespace gravsweep::queue
