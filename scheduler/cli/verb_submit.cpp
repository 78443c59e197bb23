// `gravsweep submit`: expands sweep specs into content-addressed jobs in a campaign database.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/progress.h"
#include "scheduler/cli/campaign_options.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/pipeline/impact_runners.h"
#include "scheduler/pipeline/scenario_spec.h"
#include "scheduler/queue/campaign.h"
#include "db/where.h"
#include "scheduler/queue/queue.h"
#include "scheduler/sweep/impact_kinds.h"
#include "scheduler/sweep/spec.h"

namespace gravsweep::cli {

namespace {

struct SubmitOptions {
  std::vector<std::string> specs;
  std::string db = "campaign.db";
  std::string files;
  std::vector<std::string> where;  ///< keep only the points whose swept values match (ANDed)
  bool dry_run = false;
};

/// `--where` on the swept parameters: drops (or noop jobs) that fail a condition are not
/// submitted, nor any bed that no kept drop needs. Returns how many points were left out.
std::size_t keep_matching(const std::string& path, std::vector<queue::PlannedJob>& jobs,
                          const std::vector<std::string>& where) {
  if (where.empty()) return 0;
  std::vector<queue::PlannedJob> kept;
  std::set<std::string> beds_needed;
  std::size_t left_out = 0;
  try {
    for (const auto& w : where) db::parse_where(w);
    for (auto& j : jobs) {
      if (j.kind == sweep::bed_kind()) continue;
      if (!db::row_matches(j.params, where)) {
        ++left_out;
        continue;
      }
      beds_needed.insert(j.deps.begin(), j.deps.end());
      kept.push_back(std::move(j));
    }
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("{}: {} (the sweep's axis columns)", path, e.what()));
  }
  std::vector<queue::PlannedJob> out;
  for (auto& j : jobs)  // beds first, in their planned order, as expand() gives them
    if (j.kind == sweep::bed_kind() && beds_needed.count(j.job_id)) out.push_back(std::move(j));
  for (auto& j : kept) out.push_back(std::move(j));
  jobs = std::move(out);
  return left_out;
}

/// Expands and validates a sweep; a large one shows its progress with an ETA on stderr.
std::vector<queue::PlannedJob> expand_with_progress(const sweep::SweepSpec& spec) {
  constexpr std::size_t kProgressFromPoints = 20000;
  ProgressBar bar(spec.points() >= kProgressFromPoints);
  if (spec.points() >= kProgressFromPoints) {
    const sweep::ExpansionCost c = sweep::expansion_cost(spec);
    std::fprintf(stderr, "sweep %s: expanding and validating %zu points (about %.2g GB and %s estimated)\n",
                 spec.name.c_str(), spec.points(), c.memory_bytes / 1e9, format_duration(c.seconds).c_str());
  }
  auto jobs = sweep::expand(spec, pipeline::impact_point_check(), [&](std::size_t done, std::size_t total) {
    bar.update("expand", static_cast<double>(done) / static_cast<double>(total),
               fmt::format("{} of {} points validated", done, total));
  });
  bar.finish();
  return jobs;
}

/// A sweep spec and the jobs it plans.
struct Planned {
  sweep::SweepSpec spec;
  std::vector<queue::PlannedJob> jobs;
};

/// "B bed, N drop" (or noop): the planned jobs by kind, as `submit` prints them.
std::string jobs_by_kind(const Planned& p) {
  const auto beds = static_cast<std::size_t>(
      std::count_if(p.jobs.begin(), p.jobs.end(), [](const auto& j) { return j.kind == sweep::bed_kind(); }));
  return fmt::format("{} bed, {} {}", beds, p.jobs.size() - beds, p.spec.job_kind == "noop" ? "noop" : "drop");
}

/// The dry run's memory line: the largest estimate (pipeline::job_memory_bytes) of the sweep's bed
/// and drop jobs against what `work --max-memory` allows by default.
void print_memory(const Planned& p) {
  double most = 0, grains = 0;
  for (const auto& j : p.jobs) {
    if (j.kind != sweep::bed_kind()) continue;  // a drop loads its bed: the same bound
    const auto s = nlohmann::json::parse(j.scenario_json);
    if (pipeline::job_memory_bytes(s) > most)
      most = pipeline::job_memory_bytes(s), grains = pipeline::bed_grain_bound(s);
  }
  if (most <= 0) return;
  fmt::print(
      "  memory per bed or drop job: up to {:.3g} MB (up to {:.3g} grains at {:g} bytes each); this machine "
      "has {:.3g} MB\n",
      most / 1048576.0, grains, pipeline::kBytesPerGrain, sweep::machine_memory_bytes() / 1048576.0);
}

void run_submit(const SubmitOptions& o) {
  // Validate and expand every spec before the database is even opened: a bad spec writes nothing.
  std::vector<Planned> planned;
  for (const auto& path : o.specs) {
    try {
      Planned p{sweep::load_spec(path), {}};
      p.jobs = expand_with_progress(p.spec);
      if (const std::size_t n = keep_matching(path, p.jobs, o.where))
        fmt::print("sweep {}: --where leaves out {} of {} points\n", p.spec.name, n, p.spec.points());
      planned.push_back(std::move(p));
    } catch (const sweep::SpecError& e) {
      throw UsageError(e.what());
    }
  }
  if (o.dry_run) {
    for (const auto& p : planned) {
      fmt::print("sweep {}: {} points -> {} jobs ({}) [dry run: nothing written]\n", p.spec.name, p.spec.points(),
                 p.jobs.size(), jobs_by_kind(p));
      print_memory(p);
    }
    return;
  }
  db::Database db = queue::open_campaign(o.db, queue::OpenMode::create, o.files);
  queue::bind_files_root(db, queue::CampaignPaths(o.db, o.files));  // the marker naming this campaign
  for (const auto& p : planned) {
    const auto r = queue::submit(db, sweep::record(p.spec), p.jobs);
    fmt::print("sweep {} ({}): {} jobs planned ({}): {} new, {} already present\n", r.sweep,
               r.sweep_new ? "new sweep" : "existing sweep", r.planned, jobs_by_kind(p), r.added, r.present);
  }
}

}  // namespace

void setup_submit(CLI::App& app) {
  auto opt = std::make_shared<SubmitOptions>();
  auto* sub = app.add_subcommand(
      "submit",
      "Expand sweep specs (schemas/sweep.schema.json) into jobs in a campaign database. A job's id is\n"
      "a hash of its canonical scenario, so submitting the same spec again adds nothing and adding a\n"
      "value to one axis adds only the new jobs (\"n new, m already present\"). Drops that share a bed\n"
      "depend on one bed-preparation job. A malformed spec is refused (exit 2) with the JSON pointer,\n"
      "the value found and the type expected, and nothing is written. A sweep of 20,000 points or more\n"
      "shows its expansion's progress with an ETA on stderr; one whose expansion would need more than\n"
      "half this machine's memory or 30 minutes is refused (exit 2) with both estimates: split it.\n\n"
      "Examples:\n"
      "  gravsweep submit examples/sweep_tiny.json --db campaign.db\n"
      "  gravsweep submit a.json b.json --db campaign.db      # a campaign may hold several sweeps\n"
      "  gravsweep submit spec.json --dry-run                 # validate and count, write nothing\n"
      "  gravsweep submit spec.json --where 'projectile_seed>=2' --db campaign.db\n"
      "                                  # only part of the sweep (its axis columns; beds it needs)");
  sub->add_option("specs", opt->specs, "sweep spec files (JSON)")->required()->check(CLI::ExistingFile);
  add_campaign_options(sub, opt->db, &opt->files, "campaign database (created if missing)");
  sub->add_option("--where", opt->where,
                  "submit only the points whose swept values match, e.g. 'impact_speed_m_s<0.5' (the "
                  "axis column names; same grammar as `results --where`; repeat to AND)");
  sub->add_flag("--dry-run", opt->dry_run, "validate and expand only; write nothing");
  sub->callback([opt]() { run_submit(*opt); });
}

}  // namespace gravsweep::cli
