// Resume: expired leases and failed jobs requeued (dead ones on request), files of lost attempts
// removed, orphans to quarantine (campaign.cpp).
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

void remove_lost_files(const CampaignPaths& paths, const Reclaimed& r) {
  std::error_code ec;
  for (const auto& rel : r.output_rels) fs::remove(paths.abs(rel), ec);
  if (r.job_prefixes.empty() || !fs::exists(paths.tmp(), ec)) return;
  for (const auto& e : fs::directory_iterator(paths.tmp(), ec)) {
    const std::string name = e.path().filename().string();
    for (const auto& p : r.job_prefixes) {
      if (name.rfind(p + ".", 0) == 0) {
        fs::remove_all(e.path(), ec);
        break;
      }
    }
  }
}

ResumeReport resume(Database& db, const CampaignPaths& paths, const ResumeOptions& o) {
  ResumeReport rep;
  if (o.remove_orphans) {
    check_files_belong(db, paths);
    check_quarantine_folder(paths);
  }
  const double now = clock_s(db);
  Reclaimed lost;
  {
    Transaction tx(db);
    detail::reap_expired(db, now, lost, 1 << 30);
    rep.expired_requeued = lost.lost - lost.dead;
    rep.expired_dead = lost.dead;
    {
      Statement st(db, "UPDATE jobs SET state='queued', not_before=0 WHERE state='failed'");
      st.run();
      rep.failed_requeued = db.changes();
    }
    if (o.retry_dead) {
      Statement a(
          db,
          "UPDATE jobs SET max_attempts=CASE WHEN max_attempts>attempts+?1 THEN max_attempts ELSE attempts+?1 END, "
          "last_error=NULL, blocked_by=NULL, finished_at=NULL, releases=0, stalled_releases=0, "
          "deps_pending=(SELECT count(*) FROM job_deps d JOIN jobs j2 ON j2.job_id=d.dep_id "
          "WHERE d.job_id=jobs.job_id AND j2.state!='done') WHERE state='dead'");
      a.bind(1, o.extra_attempts);
      a.run();
      Statement b(db,
                  "UPDATE jobs SET state=CASE WHEN deps_pending>0 THEN 'waiting' ELSE 'queued' END WHERE state='dead'");
      b.run();
      rep.dead_requeued = db.changes();
    }
    if (o.dry_run) {
      // Transaction rolls back in its destructor.
    } else {
      tx.commit();
    }
  }
  if (!o.dry_run) remove_lost_files(paths, lost);

  if (o.remove_orphans) {
    auto q = quarantine_orphans(db, paths, o.dry_run);
    rep.orphans = std::move(q.moved);
    rep.restored = std::move(q.restored);
    rep.purged = q.purged;
  }
  return rep;
}

}  // namespace gravsweep::queue
