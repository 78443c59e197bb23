// Sweep expansion into the queue: idempotent inserts, dependencies and sweep memberships, and the
// results columns of the sweep's parameters and of its job kinds' outputs.
#include <set>

#include "scheduler/queue/queue_internal.h"
#include "scheduler/queue/canonical.h"

namespace gravsweep::queue {

namespace {

/// The sweep's row (its spec as submitted last; `submits` counts the submissions).
void upsert_sweep(Database& db, const SweepRecord& spec, double now) {
  Statement st(db,
               "INSERT INTO sweeps(sweep_id, job_kind, spec_json, spec_sha256, submitted_at, updated_at) "
               "VALUES(?1, ?2, ?3, ?4, ?5, ?5) ON CONFLICT(sweep_id) DO UPDATE SET spec_json=excluded.spec_json, "
               "spec_sha256=excluded.spec_sha256, updated_at=excluded.updated_at, submits=sweeps.submits+1");
  st.bind(1, spec.name).bind(2, spec.job_kind).bind(3, spec.spec_json).bind(4, queue::sha256_hex(spec.spec_json));
  st.bind(5, now);
  st.run();
}

/// One results column per swept parameter, of a type that fits every value of the axis: 1, 1.5
/// (canonical 1 is an integer) needs REAL, and so does 2.5 added to an axis that had 1, 2.
void add_param_columns(Database& db, const SweepRecord& spec) {
  auto cols = detail::result_extra_columns(db);
  for (const auto& [name, values] : spec.columns) {
    if (!cols.count(name)) {
      detail::add_result_column(db, name, "param", detail::sql_type_of(values.front()));
      cols[name] = {"param", detail::sql_type_of(values.front())};
    }
    for (const auto& v : values) detail::widen_result_column(db, name, cols[name], v);
  }
}

/// The results columns of the outputs the planned jobs' kinds declare, after the parameters' (an
/// output named as a parameter is metric_<name>): a campaign's results table is known before
/// any of its jobs finishes, and a completion adds no column.
void add_output_columns(Database& db, const std::vector<PlannedJob>& jobs) {
  std::set<JobKind> kinds;
  for (const auto& j : jobs) kinds.insert(j.kind);
  for (JobKind k : kinds) detail::declare_output_columns(db, k);
}

/// Each planned job inserted unless present, with its dependencies and its membership of the sweep.
void insert_jobs(Database& db, const SweepRecord& spec, const std::vector<PlannedJob>& jobs, double now,
                 SubmitReport& rep) {
  Statement ins(db,
                "INSERT INTO jobs(job_id, kind, sweep_id, state, priority, deps_pending, max_attempts, params_json, "
                "scenario_json, created_at) VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10) "
                "ON CONFLICT(job_id) DO NOTHING");
  Statement dep(db, "INSERT INTO job_deps(job_id, dep_id) VALUES(?, ?) ON CONFLICT DO NOTHING");
  Statement pending(
      db,
      "UPDATE jobs SET deps_pending=(SELECT count(*) FROM job_deps d JOIN jobs j ON j.job_id=d.dep_id "
      "WHERE d.job_id=?1 AND j.state!='done'), state=CASE WHEN (SELECT count(*) FROM job_deps d JOIN "
      "jobs j ON j.job_id=d.dep_id WHERE d.job_id=?1 AND j.state='dead') > 0 THEN 'dead' WHEN "
      "(SELECT count(*) FROM job_deps d JOIN jobs j ON j.job_id=d.dep_id WHERE d.job_id=?1 AND "
      "j.state!='done') > 0 THEN 'waiting' ELSE 'queued' END, blocked_by=(SELECT d.dep_id FROM job_deps d JOIN "
      "jobs j ON j.job_id=d.dep_id WHERE d.job_id=?1 AND j.state='dead' ORDER BY d.dep_id LIMIT 1) "
      "WHERE job_id=?1");
  Statement member(db,
                   "INSERT INTO sweep_jobs(sweep_id, job_id, shared) VALUES(?1, ?2, (SELECT CASE WHEN sweep_id <> ?1 "
                   "THEN 1 ELSE 0 END FROM jobs "
                   "WHERE job_id=?2)) ON CONFLICT DO NOTHING");
  for (const auto& j : jobs) {
    ins.reset();
    ins.bind(1, j.job_id).bind(2, kind_name(j.kind)).bind(3, spec.name);
    ins.bind(4, state_name(j.deps.empty() ? JobState::queued : JobState::waiting));
    ins.bind(5, j.priority).bind(6, static_cast<std::int64_t>(j.deps.size())).bind(7, spec.max_attempts);
    ins.bind(8, queue::canonical_json(j.params)).bind(9, j.scenario_json).bind(10, now);
    ins.run();
    const bool added = db.changes() == 1;
    if (added) {
      ++rep.added;
      ++rep.added_by_kind[j.kind];
      if (!j.deps.empty()) {
        for (const auto& d : j.deps) {
          dep.reset();
          dep.bind(1, j.job_id).bind(2, d);
          dep.run();
        }
        pending.reset();
        pending.bind(1, j.job_id);
        pending.run();
      }
    } else {
      ++rep.present;
    }
    member.reset();
    member.bind(1, spec.name).bind(2, j.job_id);
    member.run();
  }
}

}  // namespace

SubmitReport submit(Database& db, const SweepRecord& spec, const std::vector<PlannedJob>& jobs) {
  SubmitReport rep;
  rep.sweep = spec.name;
  rep.planned = jobs.size();
  const double now = clock_s(db);
  Transaction tx(db);
  {
    Statement exists(db, "SELECT 1 FROM sweeps WHERE sweep_id=?");
    exists.bind(1, spec.name);
    rep.sweep_new = !exists.step();
  }
  upsert_sweep(db, spec, now);
  add_param_columns(db, spec);
  add_output_columns(db, jobs);
  insert_jobs(db, spec, jobs, now, rep);
  tx.commit();
  return rep;
}

}  // namespace gravsweep::queue
