// `gravsweep bench`: engine speed on the paper's bed (Sunday et al. 2021 Sect. 3.4).
#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "engine/neighbor/verlet_list.h"
#include "engine/scenario/bed.h"
#include "engine/scenario/paper_params.h"
#include "engine/scenario/tile.h"
#include "scheduler/pipeline/impact_job.h"
#include "scheduler/cli/bench_checkpoint.h"
#include "scheduler/cli/bench_host.h"
#include "scheduler/cli/progress.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

struct BenchOptions {
  int steps = 2000;
  double dt_s = 1e-6;
  std::vector<int> threads{1, 2};
  double settle_dt_s = 5e-6;
  double settle_cap_s = 0.3;
  double fill_height_m = 0.10;
  bool scaling = false;
  std::vector<double> scaling_grains{64000, 512000};  ///< target sizes of the tiled beds
  double tile_relax_s = 0.01;                         ///< relaxation of a tiled bed before timing
  double diameter_m = 0.315;
  std::string bed_file;
  std::string checkpoint_dir;                             ///< --checkpoint-dir: measure a drop checkpoint there
  std::size_t checkpoint_samples = 10000;                 ///< trace samples in it (1 s at the paper's 10 kHz)
  std::uint32_t pair_filter_min_pairs = kFilterMinPairs;  ///< SystemConfig::pair_filter_min_pairs
  std::vector<std::uint32_t> pair_work{kRowWork, kTouchingWork, kWallWork};  ///< SystemConfig::pair_work
};

struct BenchRow {
  std::string bed;
  std::size_t grains;
  int threads;
  double ns_per_particle_step;
  double contacts_per_particle;
  double bytes_per_particle;
  double neighbour_builds;
  double force_region_share;          ///< of the timed wall time, in the force region (pairs, walls, sums, end of step)
  double wait_share;                  ///< of the force region's thread-time, waiting at its barriers (RegionTiming)
  double pair_barrier_share;          ///< of it, after the pair and wall loops waiting for a ready block
  std::vector<double> pair_loops_us;  ///< per thread, microseconds of pair and wall loops a step
};

/// Microseconds a step each thread spent in the pair and wall loops.
std::vector<double> per_thread_us(const RegionTiming& t, int steps) {
  std::vector<double> us;
  for (int k = 0; k < std::min(t.threads, RegionTiming::kTimedThreads); ++k)
    us.push_back(1e6 * t.pair_loops_s[static_cast<std::size_t>(k)] / steps);
  return us;
}

/// Times `steps` steps of a copy of the bed with `threads` threads.
BenchRow time_bed(const System& bed, const std::string& label, const BenchOptions& o, int threads) {
  SystemConfig cfg = bed.config();
  cfg.dt_s = o.dt_s;
  cfg.threads = threads;
  cfg.pair_filter_min_pairs = o.pair_filter_min_pairs;
  cfg.pair_work = PairWork{o.pair_work[0], o.pair_work[1], o.pair_work[2]};
  System sys(cfg);
  sys.particles = bed.particles;
  sys.walls = bed.walls;
  sys.initialize();
  sys.advance(50);  // warm-up: caches, first neighbour list
  const long long builds0 = sys.neighbor_list().builds();
  double contacts = 0;
  RegionTiming timing;
  sys.set_region_timing(&timing);
  const auto t0 = std::chrono::steady_clock::now();
  for (int s = 0; s < o.steps; ++s) {
    sys.step();
    contacts += static_cast<double>(2 * sys.stats().contacts + sys.stats().wall_contacts);
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  sys.set_region_timing(nullptr);
  const double n = static_cast<double>(sys.particles.size());
  if (!o.checkpoint_dir.empty() && threads == o.threads.front())
    print_checkpoint_cost(sys, o.checkpoint_dir, o.checkpoint_samples);
  return BenchRow{label,
                  sys.particles.size(),
                  threads,
                  1e9 * secs / (n * o.steps),
                  contacts / (o.steps * n),  // each pair counts for both grains, a wall contact for one
                  sys.bytes_per_particle(),
                  static_cast<double>(sys.neighbor_list().builds() - builds0),
                  timing.wall_s / secs,
                  timing.wait_share(),
                  timing.wall_s > 0 ? timing.pair_barrier_wait_s / (timing.threads * timing.wall_s) : 0,
                  per_thread_us(timing, o.steps)};
}

std::unique_ptr<System> make_bed(double container_diameter_m, const BenchOptions& o, ProgressBar& bar,
                                 std::string& note) {
  SystemConfig cfg = chrono_table1_config();
  cfg.dt_s = o.settle_dt_s;
  auto sys = std::make_unique<System>(cfg);
  BedSpec spec;
  spec.container.diameter_m = container_diameter_m;
  spec.fill_height_m = o.fill_height_m;
  spec.settle.max_time_s = o.settle_cap_s;
  spec.relax_time_s = 0.05;
  const auto t0 = std::chrono::steady_clock::now();
  const BedReport rep =
      prepare_bed(*sys, spec, [&](BedPhase ph, double f, const std::string& d) { bar.update(to_string(ph), f, d); });
  bar.finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  note = fmt::format(
      "{} grains, bulk density {:.0f} kg/m3, surface {:.2f} cm, {} (rms {:.1e} m/s), "
      "prepared in {} wall",
      rep.grains_kept, rep.bulk_density_kg_m3, 100 * rep.surface_height_m,
      rep.settled ? "settled to the paper's criteria" : "settling capped", rep.rms_speed_m_s, format_duration(wall));
  return sys;
}

/// A bed written by `gravsweep run` (bed.h5, verified as `run --bed` does), in a system with
/// Table 1's Chrono set.
std::unique_ptr<System> load_bed_file(const std::string& path) {
  auto sys = std::make_unique<System>(chrono_table1_config());
  std::string unverified;
  pipeline::load_user_bed(*sys, path, &unverified);
  if (!unverified.empty()) std::fprintf(stderr, "warning: %s\n", unverified.c_str());
  return sys;
}

/// The base bed tiled to about `target` grains (square patches of the inscribed square), relaxed
/// for o.tile_relax_s so the seams between copies close, with a label naming the layout.
std::unique_ptr<System> make_tiled_bed(const System& base, double target, const BenchOptions& o, ProgressBar& bar,
                                       std::string& label) {
  double radius = 0;
  for (const auto& w : base.walls)
    if (w.kind == WallKind::cylinder) radius = w.radius_m;
  TileSpec ts;
  ts.patch_side_m = radius > 0 ? std::sqrt(2.0) * radius : 0.22;
  const double per_tile = static_cast<double>(grains_in_patch(base, ts.patch_side_m));
  const int tiles = std::max(1, static_cast<int>(std::lround(target / std::max(per_tile, 1.0))));
  ts.nx = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(tiles))));
  ts.ny = std::max(1, static_cast<int>(std::lround(static_cast<double>(tiles) / ts.nx)));
  SystemConfig cfg = base.config();
  cfg.dt_s = o.settle_dt_s;
  auto sys = std::make_unique<System>(cfg);
  tile_bed(base, ts, *sys);
  label = fmt::format("tiled {}x{}", ts.nx, ts.ny);
  const long long steps = std::max<long long>(1, std::llround(o.tile_relax_s / o.settle_dt_s));
  const long long chunk = std::max<long long>(1, steps / 50);
  for (long long k = 0; k < steps; k += chunk) {
    sys->advance(std::min(chunk, steps - k));
    bar.update("relax", static_cast<double>(k + chunk) / static_cast<double>(steps),
               fmt::format("{} grains, {:.1f} x {:.1f} m", sys->particles.size(), ts.nx * ts.patch_side_m,
                           ts.ny * ts.patch_side_m));
  }
  bar.finish();
  return sys;
}

void run_bench(const BenchOptions& o) {
  const HostReport host = measure_host(o.threads);  // before the beds: the timed runs follow it
  ProgressBar bar;
  std::vector<BenchRow> rows;
  std::unique_ptr<System> base;
  std::string base_label;
  if (!o.bed_file.empty()) {
    base = load_bed_file(o.bed_file);
    base_label = "file";
    fmt::print("bed {}: {} grains loaded\n", o.bed_file, base->particles.size());
  } else {
    std::string note;
    base_label = fmt::format("{:.1f} cm", 100 * o.diameter_m);
    base = make_bed(o.diameter_m, o, bar, note);
    fmt::print("bed {}: {}\n", base_label, note);
  }
  for (int t : o.threads) rows.push_back(time_bed(*base, base_label, o, t));
  if (o.scaling) {
    for (double target : o.scaling_grains) {
      std::string label;
      auto wide = make_tiled_bed(*base, target, o, bar, label);
      fmt::print("bed {}: {} grains (copies of the base bed's inscribed square, relaxed {} s)\n", label,
                 wide->particles.size(), o.tile_relax_s);
      for (int t : o.threads) rows.push_back(time_bed(*wide, label, o, t));
    }
  }
  fmt::print("\n{:<18} {:>9} {:>8} {:>22} {:>22} {:>20} {:>16} {:>18} {:>18} {:>18}\n", "bed", "grains", "threads",
             "ns_per_particle_step", "contacts_per_particle", "bytes_per_particle", "nlist_rebuilds",
             "force_region_pct", "barrier_wait_pct", "pair_barrier_pct");
  for (const auto& r : rows)
    fmt::print("{:<18} {:>9} {:>8} {:>22.1f} {:>22.2f} {:>20.0f} {:>16.0f} {:>18.1f} {:>18.1f} {:>18.1f}\n", r.bed,
               r.grains, r.threads, r.ns_per_particle_step, r.contacts_per_particle, r.bytes_per_particle,
               r.neighbour_builds, 100 * r.force_region_share, 100 * r.wait_share, 100 * r.pair_barrier_share);
  for (const auto& r : rows) {
    if (r.pair_loops_us.size() < 2) continue;
    std::string per;
    for (std::size_t k = 0; k < r.pair_loops_us.size(); ++k)
      per += fmt::format("{}thread {} {:.1f}", k ? ", " : "", k, r.pair_loops_us[k]);
    fmt::print("pair and wall loops a step, {} grains, {} threads (us): {}\n", r.grains, r.threads, per);
  }
  print_host(host);
  fmt::print(
      "force_region_pct: the step's wall time in the force region (pair and wall loops, force sums, end of step);\n"
      "barrier_wait_pct: the force region's thread-time spent waiting (for a block of the force sums, at the\n"
      "  region's end) or forking the team;\n"
      "pair_barrier_pct: the part of it after the pair and wall loops, waiting for a block of the sums that\n"
      "  another thread's loops still hold (their imbalance, less the blocks finished meanwhile).\n");
  fmt::print("\n{} steps at dt = {} s, Table 1 Chrono set (hertz + sunday rolling, mu_r = 0.09).\n", o.steps, o.dt_s);
  // The barrier wait of the threads moves the 2-thread figure by 10 % (main.cpp, BENCHMARKS.md).
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  const char* spins = std::getenv("GOMP_SPINCOUNT");
  fmt::print("OpenMP barrier waits: OMP_WAIT_POLICY={}, GOMP_SPINCOUNT={}.\n", policy ? policy : "(unset)",
             spins ? spins : "(unset)");
  fmt::print(
      "Pair filter without a branch from {} listed pairs in a thread's share; rows split by a work of {} a row,\n"
      "{} a touching pair beyond its distance test and {} a wall candidate (listed pair 1).\n",
      o.pair_filter_min_pairs, o.pair_work[0], o.pair_work[1], o.pair_work[2]);
}

}  // namespace

void setup_bench(CLI::App& app) {
  auto opt = std::make_shared<BenchOptions>();
  auto* sub = app.add_subcommand(
      "bench",
      "Time the engine on the paper's bed: prepares a settled bed (31.5 cm cylinder, grains\n"
      "1 +/- 0.05 cm, 10 cm fill, about 8,000 grains, Table 1 Chrono parameters), then times\n"
      "--steps steps at dt = 1 us with each thread count and prints ns per particle-step,\n"
      "contacts per particle, bytes per particle, the share of the step in the force region and\n"
      "the share of that region's thread-time spent waiting at barriers; then the host: CPU\n"
      "model, hardware threads, load and the memory bandwidth of a STREAM-like triad with each\n"
      "thread count (measured first, about a second).\n\n"
      "Example:\n"
      "  gravsweep bench --threads 1,2              # 1 and 2 threads on the paper's bed\n"
      "  gravsweep bench --bed runs/1g/bed.h5       # time a bed prepared by `gravsweep run`\n"
      "  gravsweep bench --scaling --steps 300      # also about 64,000 and 512,000 grains\n"
      "  gravsweep bench --bed BED --threads 1 --checkpoint-dir /shared/x  # a drop checkpoint's cost\n\n"
      "--scaling copies the settled base bed's inscribed square side by side into a wide box\n"
      "(tiles), relaxes it briefly and times it too: cost per particle-step against N at the\n"
      "settled bed's contact density (settling 500,000 poured grains would take hours).");
  sub->add_option("--steps", opt->steps, "timed steps per thread count")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--threads", opt->threads, "thread counts to time, comma separated")
      ->delimiter(',')
      ->capture_default_str();
  sub->add_option("--dt", opt->dt_s, "time step of the timed run, s")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--settle-cap", opt->settle_cap_s, "cap on simulated settling time, s")->capture_default_str();
  sub->add_option("--diameter", opt->diameter_m, "container diameter of the bed to build, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--bed", opt->bed_file, "time a bed written by `gravsweep run` (DIR/bed.h5) instead of building one")
      ->check(CLI::ExistingFile);
  sub->add_flag("--scaling", opt->scaling, "also time the base bed tiled to about 64,000 and 512,000 grains");
  sub->add_option("--scaling-grains", opt->scaling_grains, "target sizes of the tiled beds, comma separated")
      ->delimiter(',')
      ->capture_default_str();
  sub->add_option("--tile-relax", opt->tile_relax_s, "relaxation of a tiled bed before timing, s")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_option("--checkpoint-dir", opt->checkpoint_dir,
                  "also checkpoint the timed bed (as a running drop's, with --checkpoint-samples trace samples) "
                  "into this folder and print its size and the seconds to write, read and restore it")
      ->check(CLI::ExistingDirectory);
  sub->add_option("--checkpoint-samples", opt->checkpoint_samples, "trace samples in the measured checkpoint")
      ->capture_default_str();
  sub->add_option("--pair-filter-min-pairs", opt->pair_filter_min_pairs,
                  "listed pairs in a thread's share from which the pair loop filters them without a branch "
                  "(0: always, 4294967295: never); the results are bit for bit the same either way")
      ->capture_default_str();
  sub->add_option("--pair-work", opt->pair_work,
                  "the work model that splits the pair loop's rows between threads: ROW,TOUCHING,WALL in units of a "
                  "listed pair's distance test (compare the per-thread loop times it prints)")
      ->delimiter(',')
      ->expected(3)
      ->capture_default_str();
  sub->callback([opt]() { run_bench(*opt); });
}

}  // namespace gravsweep::cli
