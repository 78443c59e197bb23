// `gravsweep model lolo` and `model regimes`: one gravity-scaled law across gravity levels,
// predicting each level with the law fitted on the others (results/model/level_out.h), and the
// share of quasi-static friction and inertial drag along each drop (results/model/regimes.h).
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "results/model/fit.h"
#include "results/model/level_out.h"
#include "results/model/regimes.h"
#include "results/io/table.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/model_inputs.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

using results::num;

constexpr const char* kLawHelp =
    "the law: scaled_base (phi m g + m v^2/d1, one law for all levels) or a term list with no parameter per level: "
    "terms shared by all levels or carried by a power of g (':g^p'), e.g. 'scaled_base+gravity_depth_friction' or "
    "'scaled_base+gravity_depth_friction+viscous_drag:g^0.5'";

struct LawOptions {
  ModelInputs in;
  std::string law = "scaled_base";
  bool per_froude = false;  ///< lolo: the table by held-out level and Froude number instead
};

/// Signed mean errors by held-out level and Froude number (results::LevelOutFroude).
results::Table froude_table(const std::vector<results::LevelOutRow>& rows) {
  results::Table t({"held_out_g_m_s2", "impact_fr", "drops", "zstop_mean_err_pct", "zstop_min_err_pct",
                    "zstop_max_err_pct", "tstop_mean_err_pct", "beyond_target"});
  for (const auto& r : rows)
    for (const auto& f : r.by_froude)
      t.add({num(r.g_m_s2), num(f.froude, 3), std::to_string(f.drops), num(f.zstop_mean_err_pct, 3),
             num(f.zstop_min_err_pct, 3), num(f.zstop_max_err_pct, 3), num(f.tstop_mean_err_pct, 3),
             f.misses ? "yes" : "no"});
  return t;
}

/// The fitted constants of a law, "phi=1.59 inv_d1_1_m=24.8".
std::string constants(const results::FittedModel& m) {
  std::string s;
  for (Eigen::Index j = 0; j < m.coef.size(); ++j) {
    std::string name = m.column_names[static_cast<std::size_t>(j)];
    if (m.spec.terms.size() == 1) name = name.substr(name.find('.') + 1);
    s += fmt::format("{}{}={}", s.empty() ? "" : " ", name, num(m.coef(j), 3));
  }
  return s;
}

void run_lolo(const LawOptions& o) {
  const auto c = load_model_campaign(o.in);
  const auto spec = model_of(o.law);
  std::vector<results::LevelOutRow> rows;
  try {
    rows = results::leave_level_out(spec, c);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  results::Table t({"held_out_g_m_s2", "trials", "fitted_g_m_s2", "range", "zstop_median_err_pct",
                    "tstop_median_err_pct", "apeak_median_err_pct", "zstop_all_levels_err_pct",
                    "tstop_all_levels_err_pct", "zstop_law_sd_pct", "tstop_law_sd_pct", "law_fitted_on_the_others",
                    "verdict"});
  for (const auto& r : rows) {
    std::string fitted;
    for (double g : r.fitted_g_m_s2) {
      if (!fitted.empty()) fitted += ',';  // appended, not "," + num(g): GCC 12 warns on the latter (-Wrestrict)
      fitted += num(g);
    }
    t.add({num(r.g_m_s2), std::to_string(r.trials), fitted, r.inside ? "inside" : "outside",
           num(r.zstop_median_abs_err_pct, 3), num(r.tstop_median_abs_err_pct, 3), num(r.apeak_median_abs_err_pct, 3),
           num(r.zstop_all_levels_median_abs_err_pct, 3), num(r.tstop_all_levels_median_abs_err_pct, 3),
           num(r.zstop_law_sd_pct, 2), num(r.tstop_law_sd_pct, 2), constants(r.law), r.verdict});
  }
  if (o.per_froude) {
    froude_table(rows).print(o.in.format);
    return;
  }
  if (o.in.format == "table")
    fmt::print(
        "Leave one gravity level out: {} fitted on the other levels, each drop of the held-out level predicted "
        "(median |error| over its drops; targets zstop {:g} %, tstop {:g} % inside the fitted range):\n",
        spec.name(), results::kLevelOutZstopTargetPct, results::kLevelOutTstopTargetPct);
  t.print(o.in.format);
  if (o.in.format == "table") {
    fmt::print("\nBy Froude number (signed mean error, predicted - measured, over the drops of each Fr):\n");
    froude_table(rows).print(o.in.format);
  }
}

/// The summary under the regime table: the law's crossover at the surface, the median along the
/// drops, and paper II's.
std::string crossover_summary(const results::FittedModel& law, const results::Campaign& c,
                              const std::vector<results::RegimeTrial>& map) {
  std::vector<double> surface, along;
  for (const auto& r : map) {
    surface.push_back(r.surface_crossover_froude);
    along.push_back(r.crossover_froude);
  }
  const auto [lo, hi] = std::minmax_element(surface.begin(), surface.end());
  // One crossover at every level (a law whose terms all follow g at equal Fr): with its SD.
  std::string law_fr = num(*lo, 3) + "-" + num(*hi, 3);
  if (num(*lo, 3) == num(*hi, 3)) {
    const auto e = results::surface_crossover(law, c.trials[map.front().trial].info);
    law_fr = fmt::format("{} +- {}", num(*lo, 3), num(e.sd, 2));
  }
  const std::size_t crossing =
      static_cast<std::size_t>(std::count_if(along.begin(), along.end(), [](double x) { return std::isfinite(x); }));
  const auto range = [&](results::CrossoverShare s) {
    const auto e = results::whole_collision_crossover(law, c, s);
    return fmt::format("Fr {} +- {}", num(e.froude, 3), num(e.sd, 2));
  };
  return fmt::format(
      "Crossover (inertial drag = quasi-static resistance): Fr {} by the law at the surface ({}); along the {} "
      "drops that start in the inertial regime, median Fr {}; {} start quasi-static. Over whole collisions the drag "
      "does half the work at {} and carries half the impulse at {} (SD from the law's covariance); paper II: Fr ~ "
      "{:g}",
      law_fr, constants(law), crossing, num(results::median_abs(along), 3), map.size() - crossing,
      range(results::CrossoverShare::work), range(results::CrossoverShare::impulse), results::kPaperIICrossoverFroude);
}

void run_regimes(const LawOptions& o) {
  const auto c = load_model_campaign(o.in);
  const auto law = results::fit_model(model_of(o.law), c);
  const auto map = results::regime_map(law, c);
  results::Table t({"trial_id", "gravity_m_s2", "vc_m_s", "impact_fr", "quasi_static_impulse_pct", "drag_impulse_pct",
                    "quasi_static_work_pct", "drag_work_pct", "crossover_fr", "crossover_depth_mm", "law_crossover_fr",
                    "paper_ii_fr"});
  for (const auto& r : map)
    t.add({c.trials[r.trial].info.trial_id, num(r.g_m_s2), num(r.vc_m_s, 3), num(r.impact_froude, 3),
           num(r.quasi_static_impulse_pct, 3), num(100 - r.quasi_static_impulse_pct, 3),
           num(r.quasi_static_work_pct, 3), num(100 - r.quasi_static_work_pct, 3),
           std::isfinite(r.crossover_froude) ? num(r.crossover_froude, 3) : "-",
           std::isfinite(r.crossover_depth_m) ? num(1e3 * r.crossover_depth_m, 3) : "-",
           num(r.surface_crossover_froude, 3), num(results::kPaperIICrossoverFroude)});
  if (o.in.format == "table")
    fmt::print("Regime map of {} fitted on all {} trials (quasi-static: R(z, v=0); drag: the speed-dependent rest):\n",
               law.spec.name(), law.trials_used);
  t.print(o.in.format);
  if (o.in.format == "table")
    fmt::print("\n{}\n", crossover_summary(law, c, map));
  else
    std::fprintf(stderr, "%s\n", crossover_summary(law, c, map).c_str());
}

CLI::App* add_law_inputs(CLI::App* sub, LawOptions& o) {
  add_model_inputs(sub, o.in);
  sub->add_option("--law", o.law, kLawHelp)->capture_default_str();
  return sub;
}

}  // namespace

void setup_model_lolo(CLI::App& model) {
  auto o = std::make_shared<LawOptions>();
  auto* lolo = model.add_subcommand(
      "lolo",
      "Leave one gravity level out: for each gravity level, fit one law for all levels (default\n"
      "scaled_base: R = phi m g + m v^2/d1) on the trials of every OTHER level, predict zstop, tstop and\n"
      "apeak of each drop of the held-out level the way it was measured (as the held-out errors of\n"
      "`model rank`; apeak with the fluctuations of the nearest fitted levels), and print per level the\n"
      "median |error| over its drops, whether its g lies inside the fitted range, the law's constants\n"
      "and a verdict: zstop within 10 % and tstop within 15 % inside the range; a miss names the regime\n"
      "(impact Fr below or above the law's crossover) that misses, and whether the law misses the level\n"
      "as much when fitted on every level, this one included (*_all_levels_*: its form misses), by less\n"
      "than twice the fitted law's own uncertainty (*_law_sd_*: the standard deviation of a prediction\n"
      "propagated from the covariance of the law's constants, median over the drops; the fit's noise),\n"
      "or by more (its gravity scaling misses); outside the range it is an extrapolation. A law with a\n"
      "parameter per level (base) is refused: a held-out level has none. The fit takes each trial's\n"
      "residuals in units of its own RMS force, so that the Froude 10 drops do not outweigh the rest.\n"
      "A median hides a Froude number the law misses: the verdict names every Froude number whose\n"
      "signed mean error is beyond a target, and the second table (--per-froude: that table alone, for\n"
      "csv and json) gives the signed errors by held-out level and Froude number.\n\n"
      "Examples:\n"
      "  gravsweep model lolo data/gravity_sweep/g9.81 data/gravity_sweep/g1.62\n"
      "  gravsweep model lolo runs/gravity_sweep/sweep.db --law scaled_base+cohesion --format csv");
  add_law_inputs(lolo, *o)->callback([o]() { run_lolo(*o); });
  lolo->add_flag("--per-froude", o->per_froude,
                 "print the signed mean errors by held-out level and Froude number instead of the table by level");

  auto orm = std::make_shared<LawOptions>();
  auto* regimes = model.add_subcommand(
      "regimes",
      "The regime map: fit the law (default scaled_base) on all trials, integrate each drop from its\n"
      "impact speed to its stop, and split the resistance along the motion into its quasi-static part\n"
      "R(z, v=0) (phi m g and any depth term) and its drag part R(z, v) - R(z, 0) (m v^2/d1 and any\n"
      "other speed-dependent term). Per drop: the share of each in the impulse and in the work, and the\n"
      "Froude number Fr = v/sqrt(g D) (D the projectile diameter) where the drag falls below the\n"
      "quasi-static part, beside the law's crossover at the surface (sqrt(phi d1/D) for scaled_base) and\n"
      "paper II's Fr ~ 1.5. Under the table (table format): the crossover by the two whole-collision\n"
      "definitions, the impact Fr at which the drag does half the work and the one at which it carries\n"
      "half the impulse, each with its SD from the law's covariance (GRAVITY.md, the crossover by three\n"
      "definitions).\n\n"
      "Examples:\n"
      "  gravsweep model regimes data/gravity_sweep/g9.81 data/gravity_sweep/g1.62\n"
      "  gravsweep model regimes campaign.db --law scaled_base+gravity_depth_friction --format json");
  add_law_inputs(regimes, *orm)->callback([orm]() { run_regimes(*orm); });
}

}  // namespace gravsweep::cli
