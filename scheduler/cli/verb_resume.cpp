// `gravsweep resume`: requeue expired leases and failed jobs; remove orphaned files.
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <string>

#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/campaign_options.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::cli {

namespace {

struct ResumeCliOptions {
  std::string db = "campaign.db";
  std::string files;
  bool dead = false;
  int extra_attempts = 1;
  bool keep_orphans = false;
  bool dry_run = false;
};

void run_resume(const ResumeCliOptions& o) {
  db::Database db = queue::open_campaign(o.db, queue::OpenMode::write, o.files);
  queue::ResumeOptions r;
  r.retry_dead = o.dead;
  r.extra_attempts = o.extra_attempts;
  r.remove_orphans = !o.keep_orphans;
  r.dry_run = o.dry_run;
  const queue::CampaignPaths paths(o.db, o.files);
  queue::bind_files_root(db, paths, /*write=*/!o.dry_run);  // before anything in it moves
  const auto rep = queue::resume(db, paths, r);
  fmt::print("expired leases: {} requeued{}, {} dead (retry budget spent)\n", rep.expired_requeued,
             o.dry_run ? " (dry run)" : "", rep.expired_dead);
  fmt::print("failed jobs requeued without waiting for their backoff: {}\n", rep.failed_requeued);
  if (o.dead) fmt::print("dead jobs given {} more attempt(s): {}\n", o.extra_attempts, rep.dead_requeued);
  if (!o.keep_orphans) {
    if (!o.dry_run) fmt::print("quarantined files removed: {}\n", rep.purged);
    fmt::print("orphaned files {}: {}\n", o.dry_run ? "found" : "moved to quarantine", rep.orphans.size());
    for (const auto& f : rep.orphans) fmt::print("  {}\n", f);
    for (const auto& f : rep.restored) fmt::print("  {} put back: the database refers to it again\n", f);
  }
  if (o.dry_run) fmt::print("(dry run: nothing changed)\n");
}

}  // namespace

void setup_resume(CLI::App& app) {
  auto opt = std::make_shared<ResumeCliOptions>();
  auto* sub = app.add_subcommand(
      "resume",
      "Repair a campaign after crashes: requeue jobs whose lease expired (their worker died; jobs\n"
      "whose retry budget is spent go dead), requeue failed jobs at once instead of after their\n"
      "backoff, and move files no job refers to (outputs of killed attempts) to <db stem>.files/\n"
      "quarantine/; the next resume deletes what an earlier one quarantined. Only files unknown to\n"
      "the database (one consistent snapshot) and older than it by 5 s move. Safe while workers run:\n"
      "done outputs, live leases and their files are left alone. Refuses (exit 2) a database that is\n"
      "not a campaign, whose files folder misses most of its outputs (a renamed copy without its\n"
      "folder), or whose files folder is another campaign's (its gravsweep-campaign.json names\n"
      "another) or, unmarked, holds files the campaign did not write. Then run `gravsweep work` again.\n\n"
      "Examples:\n"
      "  gravsweep resume --db campaign.db\n"
      "  gravsweep resume --db campaign.db --dead --extra-attempts 2   # also retry dead jobs\n"
      "  gravsweep resume --db campaign.db --dry-run");
  add_campaign_options(sub, opt->db, &opt->files);
  sub->add_flag("--dead", opt->dead, "also requeue dead jobs (and the drops waiting on a dead bed)");
  sub->add_option("--extra-attempts", opt->extra_attempts, "attempts added to a dead job's budget")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  sub->add_flag("--keep-orphans", opt->keep_orphans,
                "do not look for orphaned files (nor check that most done outputs are there; the folder's marker "
                "is still checked)");
  sub->add_flag("--dry-run", opt->dry_run, "report only");
  sub->callback([opt]() { run_resume(*opt); });
}

}  // namespace gravsweep::cli
