// `gravsweep pile`: the angle of repose of Table 1's Chrono grains for a list of rolling-friction
// coefficients, the calibration Sunday et al. 2020 made against piles of glass beads, or of the
// pkdgrav set against Sunday et al. 2021 Table 2 (engine/scenario/pile.h).
#include <fmt/format.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/scenario/paper_params.h"
#include "engine/scenario/pile.h"
#include "scheduler/cli/progress.h"
#include "results/io/table.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/format_option.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

/// Time steps of the pile for each set: Chrono's Hertz contact of two beads lasts about 0.2 ms,
/// pkdgrav's Hooke contact (k_N = 7.48e5 N/m) 93 us.
constexpr double kChronoPileDt_s = 1e-5;
constexpr double kPkdgravPileDt_s = 4e-6;

struct PileOptions {
  std::string set = "chrono";
  std::vector<double> mu_rolling;    ///< empty: the set's default list
  std::optional<double> mu_static;   ///< unset: the set's (Chrono 0.16, pkdgrav 1.0)
  std::optional<double> shape_beta;  ///< pkdgrav only; unset: 0.05 (Table 1)
  std::size_t grains = 2000;
  double base_radius_m = 0.15;
  std::optional<double> dt_s;  ///< unset: the set's
  int threads = 1;
  std::uint64_t seed = 7;
  std::string format = "table";
  bool quiet = false;
};

void run_pile(const PileOptions& o) {
  ProgressBar bar(!o.quiet);
  const bool pkdgrav = o.set == "pkdgrav";
  if (o.shape_beta && !pkdgrav)
    throw UsageError(fmt::format("--beta {:g}: the shape parameter applies to --set pkdgrav only (found --set {})",
                                 *o.shape_beta, o.set));
  const double beta = o.shape_beta.value_or(0.05);
  const std::vector<double> mu_rolling = !o.mu_rolling.empty() ? o.mu_rolling
                                         : pkdgrav             ? std::vector<double>{1.05}
                                                               : std::vector<double>{0.0, 0.09};
  results::Table t({"set", "mu_rolling", "shape_beta", "mu_static", "repose_angle_deg", "apex_height_m",
                    "grains_on_base", "flank_bins", "rms_speed_m_s", "simulated_time_s", "wall_time_s"},
                   results::kRuledText);
  for (double mu_r : mu_rolling) {
    SystemConfig cfg = pkdgrav ? pkdgrav_table1_config(mu_r, beta) : chrono_table1_config(mu_r);
    const double mu_s = o.mu_static.value_or(cfg.materials[kGrainMaterial].mu_static);
    cfg.materials[kGrainMaterial].mu_static = mu_s;
    cfg.dt_s = o.dt_s.value_or(pkdgrav ? kPkdgravPileDt_s : kChronoPileDt_s);
    cfg.threads = o.threads;
    System sys(cfg);
    PileSpec spec;
    if (pkdgrav) spec.grains.diameter_spread_m = 0;  // Table 1: 1 cm beads
    spec.grains_poured = o.grains;
    spec.base_radius_m = o.base_radius_m;
    spec.seed = o.seed;
    const auto t0 = std::chrono::steady_clock::now();
    const PileResult r =
        pour_pile(sys, spec, [&](double f, const std::string& d) { bar.update(fmt::format("mu_r={:g}", mu_r), f, d); });
    bar.finish();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    t.add({o.set, fmt::format("{:g}", mu_r), pkdgrav ? fmt::format("{:g}", beta) : "-", fmt::format("{:g}", mu_s),
           fmt::format("{:.1f}", r.angle_deg), fmt::format("{:.4f}", r.apex_height_m), std::to_string(r.grains_on_base),
           std::to_string(r.flank_bins), fmt::format("{:.1e}", r.rms_speed_m_s),
           fmt::format("{:.2f}", r.simulated_time_s), fmt::format("{:.1f}", wall)});
  }
  t.print(o.format);
}

}  // namespace

void setup_pile(CLI::App& app) {
  auto opt = std::make_shared<PileOptions>();
  auto* sub =
      app.add_subcommand("pile",
                         "Angle of repose of Table 1's Chrono grains (Hertz, E = 700 MPa, 1 +/- 0.05 cm glass beads)\n"
                         "for each rolling-friction coefficient given: the grains are poured through a 2 cm outlet\n"
                         "onto a rough base of fixed grains, what rolls off the base is removed, and the angle is the\n"
                         "least-squares slope of the heap's flank (20-80 % of the apex height). This is the piling\n"
                         "test with which Sunday et al. 2020 calibrated mu_r = 0.09 against glass beads (about\n"
                         "20-26 degrees); about a minute per value on one core.\n"
                         "--set pkdgrav piles Table 1's pkdgrav grains instead (Hooke, k_N = 7.48e5 N/m, 1 cm beads,\n"
                         "mu_s = 1.0, Zhang rolling with shape parameter --beta, mu_t = 1.3): Sunday et al. 2021\n"
                         "Table 2 gives 20.6-24.7 degrees for mu_r = 1.05 and beta 0.025-0.1 (22.1 at beta = 0.05).\n\n"
                         "Examples:\n"
                         "  gravsweep pile                                  # mu_r = 0 and 0.09\n"
                         "  gravsweep pile --mu-r 0,0.05,0.09,0.13,0.2 --format csv > repose.csv\n"
                         "  gravsweep pile --set pkdgrav --mu-r 1.05 --beta 0.05   # Table 2: 22.1 degrees");
  sub->add_option("--set", opt->set, "Table 1 parameter set: chrono or pkdgrav")
      ->check(CLI::IsMember({"chrono", "pkdgrav"}))
      ->capture_default_str();
  sub->add_option("--mu-r", opt->mu_rolling,
                  "rolling-friction coefficients, comma separated (default: 0,0.09 for chrono, 1.05 for pkdgrav)")
      ->delimiter(',');
  sub->add_option("--mu-s", opt->mu_static, "grain-grain sliding friction (default: Table 1's, 0.16 / 1.0)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--beta", opt->shape_beta,
                  "pkdgrav's rolling shape parameter beta, --set pkdgrav only (default 0.05, Table 1; Table 2 "
                  "tries 0.025-0.3)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--grains", opt->grains, "grains poured")->check(CLI::Range(100, 1000000))->capture_default_str();
  sub->add_option("--base-radius", opt->base_radius_m, "radius of the rough base, m")
      ->check(CLI::Range(0.03, 10.0))
      ->capture_default_str();
  sub->add_option("--dt", opt->dt_s,
                  "time step, s, checked against the law's stability bound (default: 1e-5 chrono, 4e-6 pkdgrav)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--threads", opt->threads, "OpenMP threads")->check(CLI::Range(1, 1024))->capture_default_str();
  sub->add_option("--seed", opt->seed, "random seed of the base and the pour")->capture_default_str();
  add_format_option(sub, opt->format);
  sub->add_flag("--quiet", opt->quiet, "no progress bar");
  sub->callback([opt]() { run_pile(*opt); });
}

}  // namespace gravsweep::cli
