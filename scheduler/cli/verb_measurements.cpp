// `gravsweep measurements import DIR --db FILE`: reads a measurement campaign (trials.csv and
// traces, shared/formats/measurements.md), processes every trace as Sunday et al. 2021 Sect. 2.3
// and stores trials, processed samples and metrics in SQLite.
#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "results/measurements/campaign.h"
#include "results/report/table.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/db/sqlite.h"

namespace gravsweep::cli {

namespace {

struct ImportOptions {
  std::string dir;
  std::string db = "campaign.db";
  std::string format = "table";
  double cutoff_hz = 500.0;
};

}  // namespace

void setup_measurements(CLI::App& app) {
  auto* sub = app.add_subcommand("measurements", "Laboratory measurement campaigns (import).");
  sub->require_subcommand(1);
  auto o = std::make_shared<ImportOptions>();
  auto* imp = sub->add_subcommand(
      "import",
      "Read DIR/trials.csv and DIR/traces/*.csv, filter each trace (2nd-order Butterworth,\n"
      "500 Hz, zero phase), remove the sensor bias from the free-fall and rest segments,\n"
      "integrate a into v and z from the reported impact speed, find the collision start and\n"
      "end (0.1 g, with the speed below 10 % of vc), and store trials, processed samples and\n"
      "metrics (vc, apeak, zstop, tstop) in the SQLite file (tables trials, trial_samples,\n"
      "trial_metrics). A bad row or trace is reported by file:line:column and does not stop the\n"
      "others (exit code 4 then).\n\n"
      "Example:\n"
      "  gravsweep measurements import ../shared/data/measurements/depth-friction-dev --db lab.db");
  imp->add_option("dir", o->dir, "campaign folder (holds trials.csv and traces/)")->required();
  imp->add_option("--db", o->db, "SQLite file to store into (created if missing)")->capture_default_str();
  imp->add_option("--cutoff", o->cutoff_hz, "low-pass cut-off, Hz")->capture_default_str();
  imp->add_option("--format", o->format, "table, csv or json")->check(CLI::IsMember({"table", "csv", "json"}))->capture_default_str();
  auto runs = std::make_shared<std::vector<std::string>>();
  auto runs_out = std::make_shared<std::string>();
  auto* fr = sub->add_subcommand(
      "from-runs",
      "Make a measurement campaign from DEM runs: finds every trace.h5 written by `gravsweep run`\n"
      "under the given folders and writes OUT/trials.csv pointing at them (gravity, impact speed\n"
      "from the trace, fill height, projectile, sampling rate, code version), so that `measurements\n"
      "import`, `model rank`, `model fit` and `report` treat simulations like laboratory records.\n\n"
      "Example:\n"
      "  gravsweep measurements from-runs runs/ --out runs-campaign && gravsweep model rank runs-campaign");
  fr->add_option("runs", *runs, "run folders (searched recursively) or trace.h5 files")->required();
  fr->add_option("--out", *runs_out, "campaign folder to write")->required();
  fr->callback([runs, runs_out]() {
    std::vector<results::ImportIssue> issues;
    const int n = results::write_campaign_from_runs(*runs, *runs_out, issues);
    for (const auto& is : issues) std::fprintf(stderr, "error: %s\n", is.to_string().c_str());
    fmt::print("{} DEM trials written to {}/trials.csv\n", n, *runs_out);
    if (n == 0) throw UsageError("no readable trace.h5 under the given folders");
    if (!issues.empty()) {
      std::fflush(stdout);
      std::exit(kExitIncomplete);
    }
  });

  imp->callback([o]() {
    results::Campaign c;
    try {
      c = results::load_campaign(o->dir, o->cutoff_hz);
    } catch (const std::runtime_error& e) {
      throw UsageError(e.what());
    }
    int stored = 0;
    {
      db::Database db(o->db);
      stored = results::store_campaign(db, c);
    }
    results::Table t({"trial_id", "gravity_m_s2", "vc_m_s", "apeak_m_s2", "zstop_mm", "tstop_ms",
                      "bias_m_s2", "rebound"});
    for (const auto& tr : c.trials) {
      const auto& m = tr.processed.metrics;
      t.add({tr.info.trial_id, results::num(tr.info.gravity_m_s2), results::num(m.vc_m_s),
             results::num(m.apeak_m_s2), results::num(1e3 * m.zstop_m), results::num(1e3 * m.tstop_s),
             results::num(tr.processed.bias_m_s2, 3), m.rebound ? "yes" : "no"});
    }
    t.print(o->format);
    for (const auto& is : c.issues) std::fprintf(stderr, "error: %s/%s\n", o->dir.c_str(), is.to_string().c_str());
    std::fprintf(stderr, "%d trials stored in %s, %zu rejected\n", stored, o->db.c_str(), c.issues.size());
    if (!c.issues.empty()) {  // finished, but some trials failed: exit code 4
      std::fflush(stdout);
      std::exit(kExitIncomplete);
    }
  });
}

}  // namespace gravsweep::cli
