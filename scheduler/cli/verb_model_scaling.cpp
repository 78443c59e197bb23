// `gravsweep model scaling`: which constant of a gravity-scaled law does not scale the way the law
// assumes (results/model/scaling.h): each constant freed per gravity level in turn, a power law
// in g fitted to its values, the power's 95 % bootstrap interval, and the model to try instead.
#include <fmt/format.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "results/model/model_spec.h"
#include "results/io/table.h"
#include "results/model/scaling.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/model_inputs.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

using results::num;

struct ScalingOptions {
  ModelInputs in;
  std::string law = "scaled_base+gravity_depth_friction";
  int resamples = results::kScalingResamples;
  unsigned seed = 1;
};

void run_scaling(const ScalingOptions& o) {
  const auto c = load_model_campaign(o.in);
  const results::ModelSpec law = model_of(o.law);
  results::ScalingCheck r;
  try {
    r = results::scaling_check(law, c, o.resamples, o.seed);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  results::Table t({"constant", "gravity_m_s2", "value", "value_se", "law_value", "power_of_g", "power_se", "power_lo",
                    "power_hi", "resamples", "scales_as_assumed", "note"});
  for (const auto& row : r.rows)
    for (std::size_t gi = 0; gi < row.gravity_m_s2.size(); ++gi)
      t.add({row.constant, num(row.gravity_m_s2[gi]), num(row.value[gi], 4), num(row.value_se[gi], 2),
             num(row.law_value, 4), num(row.power, 3), num(row.power_se, 2), num(row.power_lo, 3), num(row.power_hi, 3),
             std::to_string(row.resamples_used),
             std::isfinite(row.power_lo) ? (row.differs ? "no" : "yes") : "untested", row.note});
  t.print(o.in.format);
  if (o.in.format == "table") fmt::print("\nverdict: {}\n", r.verdict);
}

}  // namespace

void setup_model_scaling(CLI::App& model) {
  auto o = std::make_shared<ScalingOptions>();
  auto* sub = model.add_subcommand(
      "scaling",
      "Which constant of a gravity-scaled law does not scale the way the law assumes. A law for all\n"
      "gravity levels (default scaled_base+gravity_depth_friction: phi m g + kappa g z + m v^2/d1)\n"
      "holds each constant the same at every level. Each constant is freed in turn (a value per\n"
      "level, the others shared, the trials weighted as the law's fit weighs them: residuals in units\n"
      "of each trial's RMS force), a power law c(g) = c0 (g / 9.81 m/s2)^p is fitted to its values\n"
      "(least squares on ln c, weights (c/se)^2), and the 95 % interval of p comes from a bootstrap\n"
      "over whole drops, resampled within each level (--resamples). A constant whose interval\n"
      "excludes 0 does not scale as assumed: the verdict gives its power and the model to try, the\n"
      "constant carried by g^p ('scaled_base.inv_d1_1_m:g^0.2': one parameter of a term, written\n"
      "term.parameter, times (g / 9.81 m/s2)^0.2), which `model fit` and `model lolo` take as they\n"
      "are. One row per constant and level: its value there, the law's value, the power, its SE and\n"
      "interval. Needs at least three gravity levels.\n\n"
      "Examples:\n"
      "  gravsweep model scaling data/gravity_sweep/g9.81 data/gravity_sweep/g1.62 data/gravity_sweep/g0.1\n"
      "  gravsweep model scaling runs/gravity_sweep/sweep.db --law scaled_base --format csv\n"
      "  gravsweep model lolo data/gravity_sweep/g* --law 'scaled_base.phi+scaled_base.inv_d1_1_m:g^0.2'");
  add_model_inputs(sub, o->in);
  sub->add_option("--law", o->law,
                  "the law: terms all shared or carried by g^p, e.g. scaled_base, "
                  "'scaled_base+gravity_depth_friction', 'scaled_base.phi+scaled_base.inv_d1_1_m:g^0.2'")
      ->capture_default_str();
  sub->add_option("--resamples", o->resamples, "bootstrap resamples of each power's interval")
      ->check(CLI::Range(20, 100000))
      ->capture_default_str();
  sub->add_option("--seed", o->seed, "seed of the bootstrap")->capture_default_str();
  sub->callback([o]() { run_scaling(*o); });
}

}  // namespace gravsweep::cli
