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
#include "scheduler/pipeline/scenario_defaults.h"
#include "scheduler/pipeline/scenario_spec.h"
#include "scheduler/queue/campaign.h"
#include "db/where.h"
#include "scheduler/queue/queue.h"
#include "scheduler/sweep/impact_kinds.h"
#include "scheduler/sweep/spec.h"
#include "scheduler/sweep/sweep_kind.h"

namespace gravsweep::cli {

namespace {

struct SubmitOptions {
  std::vector<std::string> specs;
  std::string db = "campaign.db";
  std::string files;
  std::vector<std::string> where;  ///< keep only the points whose swept values match (ANDed)
  bool dry_run = false;
};

/// The jobs other planned jobs wait for (an impact sweep's beds): shared by points, not points.
std::set<std::string> shared_jobs(const std::vector<queue::PlannedJob>& jobs) {
  std::set<std::string> ids;
  for (const auto& j : jobs) ids.insert(j.deps.begin(), j.deps.end());
  return ids;
}

/// `--where` on the swept parameters: the points' jobs (drops, noop jobs) that fail a condition are
/// not submitted, nor any shared job (a bed) that no kept job needs. Returns how many points were
/// left out.
std::size_t keep_matching(const std::string& path, std::vector<queue::PlannedJob>& jobs,
                          const std::vector<std::string>& where) {
  if (where.empty()) return 0;
  const std::set<std::string> shared = shared_jobs(jobs);
  std::vector<queue::PlannedJob> kept;
  std::set<std::string> shared_needed;
  std::size_t left_out = 0;
  try {
    for (const auto& w : where) db::parse_where(w);
    for (auto& j : jobs) {
      if (shared.count(j.job_id)) continue;
      if (!db::row_matches(j.params, where)) {
        ++left_out;
        continue;
      }
      shared_needed.insert(j.deps.begin(), j.deps.end());
      kept.push_back(std::move(j));
    }
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("{}: {} (the sweep's axis columns)", path, e.what()));
  }
  std::vector<queue::PlannedJob> out;
  for (auto& j : jobs)  // shared jobs first, in their planned order, as expand() gives them
    if (shared.count(j.job_id) && shared_needed.count(j.job_id)) out.push_back(std::move(j));
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
  auto jobs = sweep::expand(spec, [&](std::size_t done, std::size_t total) {
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

/// Says how many of the sweep's jobs run differently under the current defaults version than a
/// submit before versions existed would have run them (their stored point names its version only
/// then: pipeline/scenario_defaults.h), and how to keep the old defaults and ids.
void note_versioned_defaults(const Planned& p) {
  const std::set<std::string> shared = shared_jobs(p.jobs);
  const auto n = std::count_if(p.jobs.begin(), p.jobs.end(), [&](const queue::PlannedJob& j) {
    return !shared.count(j.job_id) && j.scenario_json.find("\"defaults_version\"") != std::string::npos;
  });
  if (n == 0) return;
  fmt::print(
      "sweep {}: {} job{} take the adaptive step of defaults version {} (0.001-0.1 m/s2 without /time_step; "
      "docs/queue.md, \"Defaults versions\"), so their ids differ from a submit of this spec by a build before it; "
      "\"defaults_version\": 1 in the base keeps the fixed step and those ids\n",
      p.spec.name, n, n == 1 ? "" : "s", pipeline::kCurrentDefaultsVersion);
}

/// "2 bed, 12 drop" (or "12 noop"): the planned jobs by kind, in planned order, as `submit` prints them.
std::string jobs_by_kind(const Planned& p) {
  std::vector<std::pair<queue::JobKind, std::size_t>> counts;
  for (const auto& j : p.jobs) {
    auto it = std::find_if(counts.begin(), counts.end(), [&](const auto& c) { return c.first == j.kind; });
    if (it == counts.end()) it = counts.insert(counts.end(), {j.kind, 0});
    ++it->second;
  }
  std::string out;
  for (const auto& [kind, n] : counts)
    out += fmt::format("{}{} {}", out.empty() ? "" : ", ", n, queue::kind_name(kind));
  return out.empty() ? "no jobs" : out;
}

/// The dry run's memory line: the largest estimate (pipeline::job_memory_bytes) of the sweep's bed
/// and drop jobs against what `work --max-memory` allows by default.
void print_memory(const Planned& p) {
  double most = 0, grains = 0;
  for (const auto& j : p.jobs) {
    if (j.kind != sweep::bed_kind()) continue;  // a drop loads its bed: the same bound
    const pipeline::Scenario s =
        pipeline::scenario_of(pipeline::StoredScenario::parse(nlohmann::json::parse(j.scenario_json)).validated);
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
      note_versioned_defaults(p);
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
    const auto r = queue::submit(db, p.spec, p.jobs);
    fmt::print("sweep {} ({}): {} jobs planned ({}): {} new, {} already present\n", r.sweep,
               r.sweep_new ? "new sweep" : "existing sweep", r.planned, jobs_by_kind(p), r.added, r.present);
  }
}

}  // namespace

/// The registered job kinds, one line each ("job" of a sweep spec: what it plans).
std::string kinds_help() {
  std::string out = "Job kinds (a spec's \"job\"):\n";
  for (const sweep::SweepKind* k : sweep::sweep_kinds()) out += fmt::format("  {:<8} {}\n", k->name, k->summary);
  return out;
}

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
      "half this machine's memory or 30 minutes is refused (exit 2) with both estimates: split it.\n"
      "A new scenario takes the current defaults version (docs/queue.md, \"Defaults versions\").\n\n" +
          kinds_help() +
          "\nExamples:\n"
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
