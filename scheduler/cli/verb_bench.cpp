// `gravsweep bench`: engine speed on the paper's bed (Sunday et al. 2021 Sect. 3.4).
#include <fmt/format.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "engine/scenario/bed.h"
#include "engine/scenario/paper_params.h"
#include "results/io/bed_file.h"
#include "scheduler/pipeline/impact_job.h"
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
  double diameter_m = 0.315;
  std::string bed_file;
};

struct BenchRow {
  std::string bed;
  std::size_t grains;
  int threads;
  double ns_per_particle_step;
  double contacts_per_particle;
  double bytes_per_particle;
  double neighbour_builds;
};

/// Times `steps` steps of a copy of the bed with `threads` threads.
BenchRow time_bed(const System& bed, const std::string& label, const BenchOptions& o, int threads) {
  SystemConfig cfg = bed.config();
  cfg.dt_s = o.dt_s;
  cfg.threads = threads;
  System sys(cfg);
  sys.particles = bed.particles;
  sys.walls = bed.walls;
  sys.initialize();
  sys.advance(50);  // warm-up: caches, first neighbour list
  const long long builds0 = sys.neighbor_list().builds();
  double contacts = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int s = 0; s < o.steps; ++s) {
    sys.step();
    contacts += static_cast<double>(2 * sys.stats().contacts + sys.stats().wall_contacts);
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double n = static_cast<double>(sys.particles.size());
  return BenchRow{label,
                  sys.particles.size(),
                  threads,
                  1e9 * secs / (n * o.steps),
                  contacts / (o.steps * n),  // each pair counts for both grains, a wall contact for one
                  sys.bytes_per_particle(),
                  static_cast<double>(sys.neighbor_list().builds() - builds0)};
}

std::unique_ptr<System> make_bed(double container_diameter_m, bool full_settle, const BenchOptions& o,
                                 ProgressBar& bar, std::string& note) {
  SystemConfig cfg = chrono_table1_config();
  cfg.dt_s = o.settle_dt_s;
  auto sys = std::make_unique<System>(cfg);
  BedSpec spec;
  spec.container.diameter_m = container_diameter_m;
  spec.fill_height_m = o.fill_height_m;
  spec.settle.max_time_s = full_settle ? o.settle_cap_s : 0.03;
  spec.relax_time_s = full_settle ? 0.05 : 0.01;
  const auto t0 = std::chrono::steady_clock::now();
  const BedReport rep = prepare_bed(*sys, spec, [&](BedPhase ph, double f, const std::string& d) {
    bar.update(to_string(ph), f, d);
  });
  bar.finish();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  note = fmt::format("{} grains, bulk density {:.0f} kg/m3, surface {:.2f} cm, {} (rms {:.1e} m/s), "
                     "prepared in {} wall",
                     rep.grains_kept, rep.bulk_density_kg_m3, 100 * rep.surface_height_m,
                     rep.settled ? "settled to the paper's criteria" : "settling capped",
                     rep.rms_speed_m_s, format_duration(wall));
  return sys;
}

/// A bed written by `gravsweep run` (bed.h5), in a system with Table 1's Chrono set.
std::unique_ptr<System> load_bed_file(const std::string& path) {
  auto sys = std::make_unique<System>(chrono_table1_config());
  pipeline::load_bed(*sys, results::read_bed(path));
  return sys;
}

void run_bench(const BenchOptions& o) {
  ProgressBar bar;
  std::vector<BenchRow> rows;
  struct BedCase {
    std::string label;
    double diameter_m;
    bool full_settle;
  };
  std::vector<BedCase> cases;
  if (!o.bed_file.empty()) {
    auto bed = load_bed_file(o.bed_file);
    fmt::print("bed {}: {} grains loaded\n", o.bed_file, bed->particles.size());
    for (int t : o.threads) rows.push_back(time_bed(*bed, "file", o, t));
  } else {
    cases.push_back({fmt::format("{:.1f} cm", 100 * o.diameter_m), o.diameter_m, true});
  }
  if (o.scaling) {
    cases.push_back({"x8 wide 89 cm", 0.315 * std::sqrt(8.0), false});
    cases.push_back({"x64 wide 252 cm", 0.315 * 8.0, false});
  }
  for (const auto& c : cases) {
    std::string note;
    auto bed = make_bed(c.diameter_m, c.full_settle, o, bar, note);
    fmt::print("bed {}: {}\n", c.label, note);
    for (int t : o.threads) rows.push_back(time_bed(*bed, c.label, o, t));
  }
  fmt::print("\n{:<18} {:>9} {:>8} {:>22} {:>22} {:>20} {:>16}\n", "bed", "grains", "threads",
             "ns_per_particle_step", "contacts_per_particle", "bytes_per_particle", "nlist_rebuilds");
  for (const auto& r : rows)
    fmt::print("{:<18} {:>9} {:>8} {:>22.1f} {:>22.2f} {:>20.0f} {:>16.0f}\n", r.bed, r.grains,
               r.threads, r.ns_per_particle_step, r.contacts_per_particle, r.bytes_per_particle,
               r.neighbour_builds);
  fmt::print("\n{} steps at dt = {} s, Table 1 Chrono set (hertz + sunday rolling, mu_r = 0.09).\n",
             o.steps, o.dt_s);
}

}  // namespace

void setup_bench(CLI::App& app) {
  auto opt = std::make_shared<BenchOptions>();
  auto* sub = app.add_subcommand(
      "bench",
      "Time the engine on the paper's bed: prepares a settled bed (31.5 cm cylinder, grains\n"
      "1 +/- 0.05 cm, 10 cm fill, about 8,000 grains, Table 1 Chrono parameters), then times\n"
      "--steps steps at dt = 1 us with each thread count and prints ns per particle-step,\n"
      "contacts per particle and bytes per particle.\n\n"
      "Example:\n"
      "  gravsweep bench --threads 1,2              # the issue's figures\n"
      "  gravsweep bench --bed runs/1g/bed.h5       # time a bed prepared by `gravsweep run`\n"
      "  gravsweep bench --scaling --steps 200      # also 64,000 and 512,000 grains");
  sub->add_option("--steps", opt->steps, "timed steps per thread count")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--threads", opt->threads, "thread counts to time, comma separated")->delimiter(',')->capture_default_str();
  sub->add_option("--dt", opt->dt_s, "time step of the timed run, s")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--settle-cap", opt->settle_cap_s, "cap on simulated settling time, s")->capture_default_str();
  sub->add_option("--diameter", opt->diameter_m, "container diameter of the bed to build, m")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--bed", opt->bed_file, "time a bed written by `gravsweep run` (DIR/bed.h5) instead of building one")->check(CLI::ExistingFile);
  sub->add_flag("--scaling", opt->scaling, "also time 8x and 64x wider beds (about 64,000 and 512,000 grains)");
  sub->callback([opt]() { run_bench(*opt); });
}

}  // namespace gravsweep::cli
