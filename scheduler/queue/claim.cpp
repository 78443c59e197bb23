// Claims with lease reaping, heartbeats, and the worker's identity.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>

#include "scheduler/queue/dialect.h"
#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

namespace detail {

void cascade_dead(Database& db, const std::string& job_id, double now) {
  std::vector<std::string> stack{job_id};
  Statement st(db,
               "UPDATE jobs SET state='dead', last_error=?1, finished_at=?2, blocked_by=?3 WHERE state='waiting' "
               "AND job_id IN (SELECT job_id FROM job_deps WHERE dep_id=?3) RETURNING job_id");
  while (!stack.empty()) {
    const std::string id = stack.back();
    stack.pop_back();
    st.reset();
    st.bind(1, fmt::format("dependency {} is dead", id)).bind(2, now).bind(3, id);
    while (st.step()) stack.push_back(st.get_text(0));
  }
}

/// Closes the attempts of expired leases and requeues their jobs (or marks them dead when the
/// budget is spent). Inside the caller's transaction. Each job is fenced by the lease token it had
/// when it was picked (and locked on PostgreSQL), so a lease another worker renewed or reaped in
/// the meantime is left alone.
void reap_expired(Database& db, double now, Reclaimed& out, int limit) {
  struct Expired {
    std::string job_id, owner;
    int attempts, max_attempts;
    double heartbeat_at;
    std::int64_t token;
  };
  std::vector<Expired> found;
  {
    Statement st(db, std::string("SELECT job_id, coalesce(lease_owner, ''), attempts, max_attempts, "
                                 "coalesce(heartbeat_at, 0), lease_token FROM jobs WHERE state='running' AND "
                                 "lease_expires < ? ORDER BY lease_expires LIMIT ?") +
                         dialect_of(db).lock_picked_rows());
    st.bind(1, now).bind(2, limit);
    while (st.step())
      found.push_back({st.get_text(0), st.get_text(1), static_cast<int>(st.get_int(2)), static_cast<int>(st.get_int(3)),
                       st.get_double(4), st.get_int(5)});
  }
  if (found.empty()) return;
  Statement requeue(db,
                    "UPDATE jobs SET state=?1, last_error=?2, lease_owner=NULL, lease_expires=NULL, phase=NULL, "
                    "detail=NULL, progress=NULL, finished_at=CASE WHEN ?1='dead' THEN ?3 ELSE NULL END "
                    "WHERE job_id=?4 AND state='running' AND lease_token=?5");
  Statement close(db,
                  "UPDATE attempts SET outcome='lost', ended_at=?1, runtime_s=?1-started_at, error=?2 "
                  "WHERE job_id=?3 AND lease_token=?4 AND outcome='running' RETURNING coalesce(output_path, ''), "
                  "attempt");
  for (const auto& e : found) {
    const std::string why = fmt::format("lease expired: no heartbeat from {} for {:.1f} s (worker killed or stalled)",
                                        e.owner, now - e.heartbeat_at);
    const bool dead = e.attempts >= e.max_attempts;
    requeue.reset();
    requeue.bind(1, dead ? "dead" : "queued").bind(2, why).bind(3, now).bind(4, e.job_id).bind(5, e.token);
    requeue.run();
    if (db.changes() != 1) continue;  // renewed or reaped by someone else meanwhile
    close.reset();
    close.bind(1, now).bind(2, why).bind(3, e.job_id).bind(4, e.token);
    while (close.step()) {
      if (!close.get_text(0).empty()) out.output_rels.push_back(close.get_text(0));
      out.job_prefixes.push_back(fmt::format("{}.a{}", e.job_id, close.get_int(1)));
    }
    ++out.lost;
    if (dead) {
      ++out.dead;
      cascade_dead(db, e.job_id, now);
    }
  }
}

}  // namespace detail

WorkerIdentity make_identity(const std::string& code_version, int threads) {
  WorkerIdentity w;
  char host[256] = {0};
  gethostname(host, sizeof host - 1);
  w.host = host;
  w.pid = static_cast<int>(getpid());
  w.code_version = code_version;
  w.threads = threads;
  w.owner = fmt::format("{}:{}:{:.0f}", w.host, w.pid, now_s() * 1000);
  // A Slurm task says which (`slurm cancel` and `status` show it): array job_task, or the job id.
  const char* array_job = std::getenv("SLURM_ARRAY_JOB_ID");
  const char* array_task = std::getenv("SLURM_ARRAY_TASK_ID");
  const char* job = std::getenv("SLURM_JOB_ID");
  if (array_job && array_task)
    w.owner += fmt::format(":slurm={}_{}", array_job, array_task);
  else if (job)
    w.owner += fmt::format(":slurm={}", job);
  return w;
}

std::optional<Claim> claim(Database& db, const WorkerIdentity& who, const CampaignPaths& paths, double lease_s,
                           Reclaimed* reclaimed) {
  const double now = clock_s(db);
  Reclaimed local;
  Transaction tx(db);
  detail::reap_expired(db, now, reclaimed ? *reclaimed : local, 64);
  static constexpr const char* kSet =
      "UPDATE jobs SET state='running', lease_owner=:owner, lease_token=lease_token+1, lease_expires=:now+:lease, "
      "attempts=attempts+1, started_at=:now, heartbeat_at=:now, progress=0, phase='claimed', detail=NULL, "
      "not_before=0 WHERE job_id=(SELECT job_id FROM jobs WHERE ";
  const std::string returning = std::string(" LIMIT 1") + dialect_of(db).lock_picked_rows() +
                                ") RETURNING job_id, kind, sweep_id, scenario_json, params_json, attempts, lease_token";
  const std::string q_queued = std::string(kSet) + "state='queued' ORDER BY priority DESC, seq" + returning;
  const std::string q_failed =
      std::string(kSet) + "state='failed' AND not_before<=:now ORDER BY not_before" + returning;
  std::optional<Claim> c;
  for (const std::string* q : {&q_queued, &q_failed}) {
    Statement st(db, *q);
    st.bind(":owner", who.owner).bind(":now", now).bind(":lease", lease_s);
    if (st.step()) {
      c.emplace();
      c->job_id = st.get_text(0);
      c->kind = parse_kind(st.get_text(1));
      c->sweep_id = st.get_text(2);
      c->scenario = json::parse(st.get_text(3));
      c->params = json::parse(st.get_text(4));
      c->attempt = static_cast<int>(st.get_int(5));
      c->token = st.get_int(6);
      c->claimed_at = now;
      st.run();
      break;
    }
  }
  if (!c) {
    tx.commit();  // keeps the reaped leases
    return std::nullopt;
  }
  {  // one dependency a job: the lowest id when a job had several (today only drops have one, their bed)
    Statement st(db,
                 "SELECT coalesce(j.output_path, ''), j.job_id, coalesce(j.output_sha256, ''), j.kind FROM job_deps d "
                 "JOIN jobs j ON j.job_id=d.dep_id WHERE d.job_id=? AND j.state='done' AND j.output_path IS NOT NULL "
                 "ORDER BY d.dep_id LIMIT 1");
    st.bind(1, c->job_id);
    if (st.step()) {
      c->dep_output_rel = st.get_text(0);
      c->dep_job_id = st.get_text(1);
      c->dep_sha256 = st.get_text(2);
      c->dep_kind = st.get_text(3);
    }
  }
  c->output_rel = paths.output_rel(c->kind, c->job_id, c->attempt);
  {
    Statement st(db,
                 "INSERT INTO attempts(job_id, attempt, lease_token, kind, worker, host, pid, threads, code_version, "
                 "started_at, outcome, output_path) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, 'running', ?) "
                 "RETURNING attempt_id");
    st.bind(1, c->job_id)
        .bind(2, c->attempt)
        .bind(3, c->token)
        .bind(4, kind_name(c->kind))
        .bind(5, who.owner)
        .bind(6, who.host);
    st.bind(7, who.pid).bind(8, who.threads).bind(9, who.code_version).bind(10, now).bind(11, c->output_rel);
    st.step();
    c->attempt_row = st.get_int(0);
    st.run();
  }
  tx.commit();
  return c;
}

bool heartbeat(Database& db, const Claim& c, double lease_s, double fraction, const std::string& phase,
               const std::string& detail) {
  const double now = clock_s(db);
  Statement st(db,
               "UPDATE jobs SET lease_expires=?1+?2, heartbeat_at=?1, progress=?3, phase=?4, detail=?5 "
               "WHERE job_id=?6 AND lease_token=?7 AND state='running'");
  st.bind(1, now).bind(2, lease_s).bind(3, std::clamp(fraction, 0.0, 1.0)).bind(4, phase).bind(5, detail);
  st.bind(6, c.job_id).bind(7, c.token);
  st.run();  // a single statement is its own (immediate-on-write) transaction
  return db.changes() == 1;
}

bool work_remains(Database& db) {
  Statement st(db, "SELECT EXISTS(SELECT 1 FROM jobs WHERE state IN ('queued','waiting','running','failed'))");
  st.step();
  return st.get_int(0) != 0;
}

int threads_for_claim(Database& db, const Claim& c, int threads, int pool_threads) {
  if (!kind_info(c.kind).takes_idle_threads || pool_threads <= threads) return threads;
  Statement st(db, "SELECT EXISTS(SELECT 1 FROM jobs WHERE job_id<>? AND state IN ('queued','running','failed'))");
  st.bind(1, c.job_id);
  st.step();
  return st.get_int(0) != 0 ? threads : pool_threads;
}

}  // namespace gravsweep::queue
