// `gravsweep measurements import DIR --db FILE`: reads a measurement campaign (trials.csv and
// traces, docs/formats/measurements.md), processes every trace as Sunday et al. 2021 Sect. 2.3
// and stores trials, processed samples and metrics in SQLite.
#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "results/measurements/campaign.h"
#include "results/io/table.h"
#include "scheduler/cli/campaign_input.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/format_option.h"
#include "scheduler/cli/verbs.h"
#include "db/database.h"

namespace gravsweep::cli {

namespace {

struct ImportOptions {
  std::string dir;
  std::string db = "campaign.db";
  std::string format = "table";
  std::vector<std::string> where;
  double cutoff_hz = 500.0;
  std::string files;  ///< files root of a postgresql:// input
  bool keep_going = false;
  results::ProcessingChoice processing;
};

/// `measurements import`: read, check, store, print the table of metrics.
void run_import(const ImportOptions& o) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(o.db) && fs::equivalent(o.db, o.dir, ec))
    throw UsageError(fmt::format("--db '{}': the campaign read; another file expected", o.db));
  auto in = load_campaign_input(o.dir, o.where, o.cutoff_hz, o.files, o.processing);
  describe_input(o.dir, in);
  const results::Campaign& c = in.campaign;
  std::size_t bad = 0;
  for (const auto& is : c.issues) bad += is.kind == results::ImportIssue::Kind::bad_input;
  if (bad > 0 && !o.keep_going)
    throw UsageError(
        fmt::format("{}: {} trial{} with bad input (listed above); nothing written to {} "
                    "(--keep-going stores the others)",
                    o.dir, bad, bad == 1 ? "" : "s", o.db));
  if (c.trials.empty()) throw UsageError(fmt::format("{}: no usable trials; nothing written to {}", o.dir, o.db));
  int stored = 0;
  {
    db::Database db(o.db);
    stored = results::store_campaign(db, c);
  }
  // A clipped accelerometer's apeak is a lower bound: its column holds the clip level.
  results::Table t({"trial_id", "source", "gravity_m_s2", "vc_m_s", "apeak_m_s2", "zstop_mm", "tstop_ms", "bias_m_s2",
                    "rebound", "clipped_at_m_s2"});
  for (const auto& tr : c.trials) {
    const auto& m = tr.processed.metrics;
    const bool clipped = tr.info.clipped_at_m_s2 > 0;
    t.add({tr.info.trial_id, results::to_string(tr.info.source), results::num(tr.info.gravity_m_s2),
           results::num(m.vc_m_s), results::num(m.apeak_m_s2), results::num(1e3 * m.zstop_m),
           results::num(1e3 * m.tstop_s), results::num(tr.processed.bias_m_s2, 3), m.rebound ? "yes" : "no",
           clipped ? results::num(tr.info.clipped_at_m_s2) : ""});
  }
  t.print(o.format);
  std::fprintf(stderr, "%d trials stored in %s (read from %s: %s), %zu not usable\n", stored, o.db.c_str(),
               o.dir.c_str(), in.kind.c_str(), c.issues.size());
  for (const auto& tr : c.trials)
    if (const std::string clip = results::clip_summary(tr); !clip.empty())
      std::fprintf(stderr, "warning: trial %s: %s\n", tr.info.trial_id.c_str(), clip.c_str());
  if (!c.issues.empty()) throw ExitWith{kExitIncomplete};  // finished, but some trials failed
}

void setup_import(CLI::App* sub) {
  auto o = std::make_shared<ImportOptions>();
  auto* imp = sub->add_subcommand(
      "import",
      "Read a campaign and store it in SQLite (tables trials, trial_samples, trial_metrics): a lab\n"
      "campaign folder (DIR/trials.csv and DIR/traces/*.csv, RFC 4180 CSV, optional UTF-8 BOM), a\n"
      "campaign database from `submit`/`work` (every finished drop job is a trial, read from\n"
      "<campaign>.files/traces/), or an SQLite file of an earlier import. Each trace is filtered\n"
      "(2nd-order Butterworth, 500 Hz or the scenario's cut-off, zero phase); a lab record's sensor\n"
      "bias is removed from its free-fall and rest segments and a is integrated into v and z from\n"
      "the reported impact speed (a DEM trace has no sensor and carries its own v and z); then the\n"
      "collision start and end (0.1 g, with the speed below 10 % of vc) and the metrics (vc, apeak,\n"
      "zstop, tstop). Bad input (a row, a trace, a declared sample rate the timestamps contradict, a\n"
      "gap in a record, a trace_file outside the campaign folder) is listed by file:line:column and\n"
      "nothing is written (exit code 2) unless --keep-going stores the good trials (exit code 4).\n"
      "DEM trials that cannot be measured (no contact, a rebound) are listed with the reason.\n"
      "A saturated accelerometer (a flat top: 3 or more consecutive samples at the record's largest\n"
      "value) is flagged: column clipped_at_m_s2 and a warning; its apeak is a lower bound, left out\n"
      "of apeak fits and errors and its samples out of trace fits; tstop is kept, and zstop while the\n"
      "depth integrated across the clip is off by at most 2 % of it.\n\n"
      "Examples:\n"
      "  gravsweep measurements import ../shared/data/measurements/depth-friction-dev --db lab.db\n"
      "  gravsweep measurements import campaign.db --db trials.db --where 'gravity_m_s2<2'");
  imp->add_option("dir", o->dir,
                  "lab campaign folder (trials.csv and traces/), campaign database from `submit`/`work`, or "
                  "imported SQLite file")
      ->required();
  imp->add_option("--where", o->where, "filter the trials, grammar of `gravsweep results` (e.g. 'gravity_m_s2<1')");
  imp->add_flag("--keep-going", o->keep_going, "store the good trials even when some are bad input (exit code 4)");
  imp->add_option("--db", o->db, "SQLite file to store into (created if missing)")->capture_default_str();
  imp->add_option("--cutoff", o->cutoff_hz,
                  "low-pass cut-off of a trial without filter_cutoff_hz, Hz: the cut-off at the paper's drop (1 g, "
                  "D = 10 cm), scaled by sqrt(g/D) for the trial's own drop under the froude time scale")
      ->capture_default_str();
  add_processing_options(imp, o->processing);
  add_input_files_option(imp, o->files);
  add_format_option(imp, o->format);
  imp->callback([o]() { run_import(*o); });
}

void setup_from_runs(CLI::App* sub) {
  auto runs = std::make_shared<std::vector<std::string>>();
  auto runs_out = std::make_shared<std::string>();
  auto* fr = sub->add_subcommand(
      "from-runs",
      "Make a measurement campaign folder from DEM runs: finds every trace.h5 written by `gravsweep\n"
      "run` and every campaign trace (<campaign>.files/traces/<job>.a<n>.h5) under the given folders,\n"
      "links (or copies) them into OUT/traces/ and writes OUT/trials.csv (gravity, impact speed from\n"
      "the trace, fill height, projectile, sampling rate, the scenario's filter settings, code\n"
      "version), so that `measurements import`, `model rank`, `model fit` and `report` treat\n"
      "simulations like laboratory records. (They also read a campaign database directly.)\n\n"
      "Example:\n"
      "  gravsweep measurements from-runs runs/ --out runs-campaign && gravsweep model rank runs-campaign");
  fr->add_option("runs", *runs, "run folders (searched recursively) or trace.h5 files")->required();
  fr->add_option("--out", *runs_out, "campaign folder to write")->required();
  fr->callback([runs, runs_out]() {
    std::vector<results::ImportIssue> issues;
    const int n = results::write_campaign_from_runs(*runs, *runs_out, issues);
    for (const auto& is : issues) std::fprintf(stderr, "error: %s\n", is.to_string().c_str());
    fmt::print("{} DEM trials written to {}/trials.csv\n", n, *runs_out);
    if (n == 0)
      throw UsageError("no readable trace.h5 (run folders) or <campaign>.files/traces/*.h5 under the given folders");
    if (!issues.empty()) throw ExitWith{kExitIncomplete};
  });
}

}  // namespace

void setup_measurements(CLI::App& app) {
  auto* sub = app.add_subcommand("measurements", "Laboratory measurement campaigns (import).");
  sub->require_subcommand(1);
  setup_import(sub);
  setup_from_runs(sub);
}

}  // namespace gravsweep::cli
