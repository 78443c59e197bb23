// The end of an attempt: complete (fenced, with the results row), fail (backoff or dead), a bed
// checksum mismatch (the bed is rebuilt), release (interrupted; the attempt is not counted).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "scheduler/queue/exit_codes.h"
#include "scheduler/queue/queue_internal.h"
#include "scheduler/queue/canonical.h"

namespace gravsweep::queue {

namespace {

/// Closes the attempt row of an attempt that did not complete: its outcome ('failed', 'dead',
/// 'released'), end time, runtime, exit code and error.
void end_attempt(Database& db, const Claim& c, const std::string& outcome, double now, int exit_code,
                 const std::string& error) {
  Statement st(db,
               "UPDATE attempts SET outcome=?1, ended_at=?2, runtime_s=?2-started_at, exit_code=?3, error=?4 "
               "WHERE attempt_id=?5");
  st.bind(1, outcome).bind(2, now).bind(3, exit_code).bind(4, error).bind(5, c.attempt_row);
  st.run();
}

/// Steps `st`, a fenced UPDATE of the claimed job's row (WHERE job_id, lease_token and
/// state='running') ending in RETURNING state: the job's new state, or "" when the lease was lost
/// (another worker holds the job now; nothing changed).
std::string returned_state(Statement& st) {
  if (!st.step()) return "";
  std::string state = st.get_text(0);
  st.run();
  return state;
}

/// The end of fail and release once the attempt row is closed: a job that is now dead takes its
/// waiting dependents with it (they can never run); then commits. Returns `state`.
std::string commit_new_state(Database& db, Transaction& tx, const Claim& c, const std::string& state, double now) {
  if (state == "dead") detail::cascade_dead(db, c.job_id, now);
  tx.commit();
  return state;
}

/// Takes the claimed job off its lease without counting the attempt (dependency_mismatch,
/// give_back): `set_state` is the job's new state (and what goes with it), the lease, phase,
/// detail and progress are cleared and last_error is `error`. Then closes the attempt row as
/// `outcome` with `error` and kExitFailure. False when the lease was lost (another worker holds
/// the job now; nothing changed). Inside the caller's transaction.
bool take_back(Database& db, const Claim& c, std::string_view set_state, const std::string& outcome,
               const std::string& error, double now) {
  {
    Statement st(db, fmt::format("UPDATE jobs SET {}, attempts=CASE WHEN attempts>0 THEN attempts-1 ELSE 0 END, "
                                 "last_error=?1, lease_owner=NULL, lease_expires=NULL, progress=NULL, phase=NULL, "
                                 "detail=NULL WHERE job_id=?2 AND lease_token=?3 AND state='running'",
                                 set_state));
    st.bind(1, error).bind(2, c.job_id).bind(3, c.token);
    st.run();
    if (db.changes() != 1) return false;
  }
  end_attempt(db, c, outcome, now, kExitFailure, error);
  return true;
}

}  // namespace

bool complete(Database& db, const Claim& c, const Completion& done) {
  const double now = clock_s(db);
  Transaction tx(db);
  {
    Statement st(db,
                 "UPDATE jobs SET state='done', output_path=?1, output_sha256=?2, output_bytes=?3, finished_at=?4, "
                 "progress=1, phase='done', detail=NULL, lease_owner=NULL, lease_expires=NULL, last_error=NULL "
                 "WHERE job_id=?5 AND lease_token=?6 AND state='running'");
    st.bind(1, done.output_rel)
        .bind(2, done.sha256)
        .bind(3, done.bytes)
        .bind(4, now)
        .bind(5, c.job_id)
        .bind(6, c.token);
    st.run();
    if (db.changes() != 1) return false;  // fenced out: another worker holds the job now
  }
  std::string code_version;
  {
    Statement st(db,
                 "UPDATE attempts SET outcome='done', ended_at=?1, runtime_s=?1-started_at, exit_code=0, "
                 "report_json=?2, output_path=?3 WHERE attempt_id=?4 RETURNING code_version");
    st.bind(1, now).bind(2, queue::canonical_json(done.report.is_null() ? json::object() : done.report));
    st.bind(3, done.output_rel).bind(4, c.attempt_row);
    if (st.step()) code_version = st.get_text(0);
    st.run();
  }
  {  // release dependents
    Statement st(db,
                 "UPDATE jobs SET deps_pending=deps_pending-1, state=CASE WHEN deps_pending<=1 AND state='waiting' "
                 "THEN 'queued' ELSE state END WHERE job_id IN (SELECT job_id FROM job_deps WHERE dep_id=?) "
                 "AND deps_pending>0");
    st.bind(1, c.job_id);
    st.run();
  }
  if (kind_info(c.kind).results_row) detail::insert_results_row(db, c, done, now, code_version);
  tx.commit();
  return true;
}

std::string fail(Database& db, const Claim& c, const std::string& error, int exit_code, bool permanent,
                 double backoff_base_s, double backoff_cap_s) {
  const double now = clock_s(db);
  thread_local std::mt19937_64 rng(std::random_device{}());
  const double delay = std::min(backoff_cap_s, backoff_base_s * std::pow(2.0, std::max(0, c.attempt - 1)));
  const double jitter = std::uniform_real_distribution<double>(0, 0.25 * delay)(rng);
  Transaction tx(db);
  std::string state;
  {
    Statement st(db,
                 "UPDATE jobs SET state=CASE WHEN ?1 <> 0 OR attempts>=max_attempts THEN 'dead' ELSE 'failed' END, "
                 "not_before=?2, last_error=?3, lease_owner=NULL, lease_expires=NULL, phase=NULL, detail=NULL, "
                 "finished_at=?4 WHERE job_id=?5 AND lease_token=?6 AND state='running' RETURNING state");
    st.bind(1, permanent ? 1 : 0).bind(2, now + delay + jitter).bind(3, error).bind(4, now).bind(5, c.job_id);
    st.bind(6, c.token);
    state = returned_state(st);
  }
  if (state.empty()) return "";
  end_attempt(db, c, state, now, exit_code, error);
  return commit_new_state(db, tx, c, state, now);
}

bool dependency_mismatch(Database& db, const Claim& c, const std::string& reason) {
  const double now = clock_s(db);
  Transaction tx(db);
  // The job waits for its dependency to be made again.
  if (!take_back(db, c, "state='waiting', deps_pending=1", "failed", reason, now)) return false;
  {  // the dependency is made again once, by whichever dependent noticed first
    Statement st(db,
                 "UPDATE jobs SET state='queued', output_path=NULL, output_sha256=NULL, output_bytes=NULL, "
                 "finished_at=NULL, last_error=?1, not_before=0, max_attempts=CASE WHEN max_attempts>attempts THEN "
                 "max_attempts ELSE attempts+1 END "
                 "WHERE job_id=?2 AND state='done' AND output_sha256=?3");
    st.bind(1, reason).bind(2, c.dep_job_id).bind(3, c.dep_sha256);
    st.run();
  }
  {  // its other dependents that have not started wait for the new output
    Statement st(db,
                 "UPDATE jobs SET state='waiting', deps_pending=deps_pending+1 WHERE state IN ('queued','failed') "
                 "AND job_id IN (SELECT job_id FROM job_deps WHERE dep_id=?)");
    st.bind(1, c.dep_job_id);
    st.run();
  }
  tx.commit();
  return true;
}

std::string release(Database& db, const Claim& c, const std::string& why, int max_releases, bool saved_progress) {
  const double now = clock_s(db);
  const std::string stopped = fmt::format(
      "released {} times in a row without finishing or saving progress (every attempt interrupted before its "
      "first checkpoint: a Slurm time limit or a scancel shorter than the job or its checkpoint interval?); "
      "stopped so that it does not loop; `gravsweep resume --dead` runs it again",
      max_releases);
  Transaction tx(db);
  std::string state;
  {
    // The attempt is not counted against the retry budget; the release is (jobs.releases), and
    // against max_releases when it saved no progress (jobs.stalled_releases, reset by one that did).
    Statement st(db,
                 "UPDATE jobs SET releases=releases+1, "
                 "stalled_releases=CASE WHEN ?6=1 THEN 0 ELSE stalled_releases+1 END, "
                 "state=CASE WHEN ?6=0 AND stalled_releases+1>=?1 THEN 'dead' ELSE 'queued' END, "
                 "last_error=CASE WHEN ?6=0 AND stalled_releases+1>=?1 THEN ?2 ELSE last_error END, "
                 "finished_at=CASE WHEN ?6=0 AND stalled_releases+1>=?1 THEN ?3 ELSE finished_at END, "
                 "attempts=CASE WHEN attempts>0 THEN attempts-1 ELSE 0 END, lease_owner=NULL, lease_expires=NULL, "
                 "progress=NULL, phase=NULL, detail=NULL WHERE job_id=?4 AND lease_token=?5 AND state='running' "
                 "RETURNING state");
    st.bind(1, max_releases).bind(2, stopped).bind(3, now).bind(4, c.job_id).bind(5, c.token);
    st.bind(6, saved_progress ? 1 : 0);
    state = returned_state(st);
  }
  if (state.empty()) return "";
  end_attempt(db, c, "released", now, kExitInterrupted, why);
  return commit_new_state(db, tx, c, state, now);
}

bool give_back(Database& db, const Claim& c, const std::string& why) {
  const double now = clock_s(db);
  Transaction tx(db);
  if (!take_back(db, c, "state='queued'", "released", why, now)) return false;
  tx.commit();
  return true;
}

}  // namespace gravsweep::queue
