// `gravsweep run`: one impact end to end (Sunday et al. 2021 Sect. 2.2-2.3): prepare the bed (or
// reuse one), drop the projectile, write bed.h5, trace.h5 and metrics.json, print the metrics.
#include <fmt/format.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "engine/core/error.h"
#include "results/report/figures.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/progress.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/pipeline/impact_job.h"
#include "scheduler/pipeline/scenario_spec.h"
#include "scheduler/queue/stop.h"

namespace gravsweep::cli {

namespace {

/// How the bed's settling ended, against the scenario's criteria (/bed/settle): "settled to the
/// criteria", or what ended it instead (the time cap, or the creep floor of /bed/settle/plateau_window_s)
/// and which criterion it left unmet by how much (the report's speeds are those at the end of the
/// relax; `settled` needs the criteria met in both phases; beds written before settle_end and
/// relax_end were reported were always ended by the criteria or the time cap).
std::string settling_outcome(const results::BedSummary& report, const SettleCriteria& criteria) {
  const double rms = report.rms_speed_m_s, fastest = report.max_speed_m_s;
  const double rms_max = criteria.rms_speed_m_s, fastest_max = criteria.max_speed_m_s;
  if (report.settled)
    return fmt::format("settled to the criteria (rms {:.1e} m/s <= {:g}, fastest {:.1e} m/s <= {:g})", rms, rms_max,
                       fastest, fastest_max);
  auto ended_by = [&](const std::string& end) {
    return end == "plateau" ? fmt::format(
                                  "at the creep floor (the RMS speed fell by less than {:.0f} % in "
                                  "/bed/settle/plateau_window_s = {:g} s)",
                                  100 * (1 - kPlateauNewLow), criteria.plateau_window_s)
                            : std::string("by the time cap /bed/settle/max_time_s");
  };
  std::string unmet;
  auto add = [&](const char* what, double found, double limit) {
    if (found <= limit) return;
    unmet += fmt::format("{}{} {:.1e} m/s above its {:g}", unmet.empty() ? "" : ", ", what, found, limit);
  };
  add("rms", rms, rms_max);
  add("fastest grain", fastest, fastest_max);
  if (unmet.empty())  // the pour's settling ended early; the relax after flattening then met the criteria
    return fmt::format(
        "settling stopped {} before the criteria held; after the relax they hold (rms {:.1e} m/s "
        "<= {:g}, fastest {:.1e} m/s <= {:g})",
        ended_by(report.settle_end), rms, rms_max, fastest, fastest_max);
  const bool pour_ended_otherwise = report.settle_end != "criteria" && report.settle_end != report.relax_end;
  return fmt::format(
      "settling stopped {} ({}){}", ended_by(report.relax_end), unmet,
      pour_ended_otherwise ? "; the pour's settling before flattening ended " + ended_by(report.settle_end) : "");
}

struct RunOptions {
  std::string scenario;
  std::string out;
  std::string bed;
  int threads = 0;
  bool quiet = false;
  double snapshot_interval_s = -1;  ///< < 0: the scenario's, else kRunSnapshotInterval_sqrt_D_g
  bool no_figures = false;
};

/// `run`'s grain snapshots when neither the scenario nor --snapshot-interval sets them: every
/// 0.05 sqrt(D/g) of simulated time (D the projectile diameter; 5 ms at 9.81 m/s2 and 10 cm),
/// about 40 for a drop to rest at any gravity (BENCHMARKS.md: bytes and slowdown). A fixed 5 ms
/// wrote 601 snapshots, 93 MB, for a 3 s drop at 0.001 m/s2.
constexpr double kRunSnapshotInterval_sqrt_D_g = 0.05;

/// The snapshot interval of this run: --snapshot-interval, else the scenario file's own
/// /output/snapshot_interval_s, else kRunSnapshotInterval_sqrt_D_g (campaign drops default to none).
double snapshot_interval(const RunOptions& o, const nlohmann::json& validated) {
  if (o.snapshot_interval_s >= 0) return o.snapshot_interval_s;
  std::ifstream f(o.scenario);
  const auto raw = nlohmann::json::parse(f, nullptr, false);
  const auto ptr = "/output/snapshot_interval_s"_json_pointer;
  if (raw.is_object() && raw.contains(ptr) && raw[ptr].is_number()) return raw[ptr].get<double>();
  const pipeline::Scenario s = pipeline::scenario_of(validated);
  const double D = s.projectile.diameter_m, g = s.gravity_m_s2;
  return kRunSnapshotInterval_sqrt_D_g * std::sqrt(D / g);
}

/// Fig. 2 of the drop next to its trace; a drop the metrics cannot measure gets none (said why).
void draw_run_fig2(const std::filesystem::path& trace, const std::filesystem::path& bed) {
  const auto png = trace.parent_path() / "fig2.png";
  try {
    results::draw_fig2({trace.string(), "", png.string()});
    fmt::print("wrote {} (Fig. 2; `gravsweep plot bed {} --trace {}` draws Fig. 1)\n", png.string(), bed.string(),
               trace.string());
  } catch (const ConfigError& e) {
    fmt::print("no fig2.png: {}\n", e.what());
  }
}

/// Exit code 130 on SIGINT/SIGTERM, after the job stopped cleanly (no partial files).
struct InterruptedExit : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string num(const nlohmann::json& v, double scale, const char* f) {
  return v.is_number() ? fmt::format(fmt::runtime(f), scale * v.get<double>()) : std::string("n/a");
}

void print_metrics(const nlohmann::json& m, const nlohmann::json& bed_report) {
  fmt::print("\n{:<28} {:>14}\n", "metric (Sect. 2.3)", "value");
  fmt::print("{:<28} {:>14}\n", "vc_m_s", num(m["vc_m_s"], 1, "{:.4f}"));
  fmt::print("{:<28} {:>14}\n", "apeak_m_s2", num(m["apeak_m_s2"], 1, "{:.2f}"));
  fmt::print("{:<28} {:>14}\n", "zstop_cm", num(m["zstop_m"], 100, "{:.3f}"));
  fmt::print("{:<28} {:>14}\n", "tstop_ms", num(m["tstop_s"], 1000, "{:.1f}"));
  fmt::print("{:<28} {:>14}\n", "rebound",
             m["rebound"].is_boolean() ? (m["rebound"].get<bool>() ? "yes" : "no") : "n/a");
  fmt::print("{:<28} {:>14}\n", "max_depth_cm", num(m["max_depth_m"], 100, "{:.3f}"));
  fmt::print("{:<28} {:>14}\n", "final_depth_below_surface_cm", num(m["final_depth_below_surface_m"], 100, "{:.3f}"));
  fmt::print("{:<28} {:>14}\n", "duration_to_rest_ms", num(m["duration_to_rest_s"], 1000, "{:.1f}"));
  fmt::print("{:<28} {:>14}\n", "simulated_time_s", num(m["simulated_time_s"], 1, "{:.4f}"));
  fmt::print("{:<28} {:>14}\n", "stopped_at_rest", m.value("stopped", false) ? "yes" : "no (time cap)");
  fmt::print("{:<28} {:>14}\n", "grains", m.value("grains", 0));
  fmt::print("{:<28} {:>14}\n", "threads", m.value("threads", 0));
  if (!bed_report.is_null())
    fmt::print("{:<28} {:>14}\n", "bed_wall_time_s", num(bed_report["wall_time_s"], 1, "{:.1f}"));
  fmt::print("{:<28} {:>14}\n", "drop_wall_time_s", num(m["wall_time_s"], 1, "{:.1f}"));
  if (m.contains("metrics_error"))
    fmt::print("metrics could not be computed: {}\n", m["metrics_error"].get<std::string>());
  else if (!m.value("note", std::string()).empty())
    fmt::print("note: {}\n", m["note"].get<std::string>());
}

void run_impact(const RunOptions& o) {
  nlohmann::json scenario = pipeline::load_scenario(o.scenario);  // refuses bad specs first
  scenario["output"]["snapshot_interval_s"] = snapshot_interval(o, scenario);
  if (!o.bed.empty()) {  // verified before any work: checksum, then the layout (bad -> exit 2)
    std::string unverified;
    (void)pipeline::read_user_bed(o.bed, &unverified);
    if (!unverified.empty()) std::fprintf(stderr, "warning: %s\n", unverified.c_str());
  }
  const std::filesystem::path out(o.out);
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw std::runtime_error(fmt::format("{}: cannot create the output folder: {}", out.string(), ec.message()));

  const queue::ScopedStopSignals stop_signals;  // SIGINT/SIGTERM end the job cleanly (exit 130)

  ProgressBar bar(!o.quiet);
  auto progress = [&](const std::string& phase, double f, const std::string& d) { bar.update(phase, f, d); };
  try {
    std::filesystem::path bed_path;
    nlohmann::json bed_report;
    if (o.bed.empty()) {
      bed_path = out / "bed.h5";
      const auto b = pipeline::run_bed_job(scenario, bed_path, o.threads, progress, &queue::stop_requested());
      bar.finish();
      pipeline::write_bed_checksum(bed_path);
      bed_report = results::to_json(b.report);
      fmt::print(
          "bed: {} grains kept of {} poured, surface at {:.2f} cm, bulk density {:.0f} kg/m3, {}, prepared in {}\n",
          b.report.grains_kept, b.report.grains_placed, 100 * b.report.surface_height_m, b.report.bulk_density_kg_m3,
          settling_outcome(b.report, pipeline::scenario_of(scenario).bed_spec().settle),
          format_duration(b.report.wall_time_s));
    } else {
      bed_path = o.bed;
      fmt::print("bed: reusing {}\n", bed_path.string());
    }
    const auto d =
        pipeline::run_drop_job(scenario, bed_path, out / "trace.h5", o.threads, progress, &queue::stop_requested());
    bar.finish();
    nlohmann::json metrics = d.outputs_json();
    metrics["scenario"] = std::filesystem::absolute(o.scenario).string();
    metrics["bed_file"] = std::filesystem::absolute(bed_path).string();
    metrics["trace_file"] = std::filesystem::absolute(d.trace_path).string();
    if (!bed_report.is_null()) metrics["bed_report"] = bed_report;
    const auto mpath = out / "metrics.json";
    const auto tmp = std::filesystem::path(mpath.string() + ".tmp");
    {
      std::ofstream f(tmp);
      f << metrics.dump(2) << "\n";
      if (!f) throw std::runtime_error(fmt::format("{}: cannot write", tmp.string()));
    }
    std::filesystem::rename(tmp, mpath);
    print_metrics(metrics, bed_report);
    fmt::print("\nwrote {}, {} and {}\n", o.bed.empty() ? bed_path.string() : std::string("(bed reused)"),
               d.trace_path.string(), mpath.string());
    if (d.snapshots > 0)
      fmt::print("wrote {} snapshots ({:.0f} kB of state each) to {}, index {} (ParaView, VisIt)\n", d.snapshots,
                 d.snapshot_bytes / 1e3, d.snapshot_path.string(), d.snapshot_xdmf.string());
    if (!o.no_figures) draw_run_fig2(d.trace_path, bed_path);
  } catch (const pipeline::Interrupted& e) {
    bar.finish();
    throw InterruptedExit(e.what());
  }
}

}  // namespace

void setup_run(CLI::App& app) {
  auto opt = std::make_shared<RunOptions>();
  auto* sub = app.add_subcommand(
      "run",
      "Run one impact as in Sunday et al. 2021 Sect. 2.2-2.3: fill the container, settle the grains,\n"
      "flatten the bed at the fill height, drop the projectile, stop when it rests, and measure\n"
      "vc, apeak, zstop (the maximum depth), tstop (Butterworth 500 Hz; the collision ends at a < 0.1 g,\n"
      "the paper's rule, with the speed below 10 % of vc, our addition: without it a lull between\n"
      "force-chain bursts ends some collisions 5-100 ms early) and the rebound flag (back up by more\n"
      "than 10 % of zstop). The stop criterion scales with gravity (schemas: /stop), and the bed must\n"
      "be at rest relative to the impact (/at_rest).\n"
      "Writes DIR/bed.h5 (the prepared bed, reusable) with its checksum DIR/bed.h5.sha256,\n"
      "DIR/trace.h5 (the projectile at 10 kHz), DIR/metrics.json, DIR/fig2.png (Sunday et al.\n"
      "Fig. 2, as `gravsweep plot trace`), grain snapshots DIR/snapshots.h5 with DIR/snapshots.xdmf (open it in "
      "ParaView: grains and\n"
      "projectile as point sets, every 0.05 sqrt(D/g): 5 ms at 9.81 m/s2 for the 10 cm projectile, unless\n"
      "the scenario or --snapshot-interval says otherwise), and prints the metrics. The spec is checked against\n"
      "schemas/scenario.schema.json before any work; errors name the JSON pointer of the field.\n\n"
      "Examples:\n"
      "  gravsweep run examples/impact_1g.json --out runs/1g\n"
      "  gravsweep run runs/1g_mur0.json --out runs/1g_mur0 --bed runs/1g/bed.h5   # reuse a bed:\n"
      "      only fields outside the bed (speed, offsets, dt of the drop, ...) may differ, and the\n"
      "      drop's /materials when /bed/materials names the bed's (a stiffer spring on the same bed)\n"
      "--bed checks the bed against BED.sha256 first and refuses (exit 2) a bed that changed or is\n"
      "not a readable bed file; a bed without BED.sha256 (older runs) is used with a warning.\n\n"
      "gravsweep's OpenMP threads spin briefly, then sleep, at each barrier (OMP_WAIT_POLICY=passive,\n"
      "GOMP_SPINCOUNT=500, unless you set OMP_WAIT_POLICY): with unbounded spinning an oversubscribed\n"
      "2-core machine ran the paper's bed ~50x slower; the short spin saves 10 % on a quiet machine.");
  sub->add_option("scenario", opt->scenario, "scenario spec (JSON, see schemas/scenario.schema.json)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--out", opt->out, "output folder (created if missing)")->required();
  sub->add_option(
      "--bed", opt->bed,
      "reuse this prepared bed (bed.h5 of an earlier run, verified against bed.h5.sha256) instead of preparing one");
  sub->add_option("--threads", opt->threads, "OpenMP threads (0: the scenario's, else all cores)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_flag("--quiet", opt->quiet, "no progress bar");
  sub->add_option("--snapshot-interval", opt->snapshot_interval_s,
                  fmt::format("grain snapshots every S s of simulated time into DIR/snapshots.h5 + .xdmf; 0: none "
                              "(default: the scenario's /output/snapshot_interval_s, else {} sqrt(D/g))",
                              kRunSnapshotInterval_sqrt_D_g))
      ->check(CLI::NonNegativeNumber);
  sub->add_flag("--no-figures", opt->no_figures, "do not draw DIR/fig2.png");
  sub->callback([opt]() {
    try {
      run_impact(*opt);
    } catch (const InterruptedExit& e) {
      std::fprintf(stderr, "interrupted: %s (no partial files left)\n", e.what());
      throw ExitWith{kExitInterrupted};
    }
  });
}

}  // namespace gravsweep::cli
