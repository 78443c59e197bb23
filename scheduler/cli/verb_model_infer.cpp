// `gravsweep model infer`: what one impact says about the ground. A saved gravity-scaled law
// (results/model/law.h) and one measured stopping depth (optionally the duration and the peak
// deceleration) of a projectile at a gravity and speed give the law's constants consistent with
// the measurement, with 95 % intervals, and which of them one impact cannot constrain
// (results/model/infer.h).
#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include "engine/core/error.h"
#include "results/io/table.h"
#include "results/model/infer.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/format_option.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

using results::num;

struct InferVerbOptions {
  std::string law;
  results::LawCase c{NAN, NAN, 0.1, 1.0};
  results::InferMeasurement m;
  results::InferOptions o;
  bool extrapolate = false;
  std::string format = "table";
};

/// A value as a typed cell: rounded to `digits` significant digits for the eye (table), at full
/// precision for a script (`full`: csv and json), or null (an empty cell in text and CSV) when
/// `known` is false or the value is not finite.
nlohmann::json rounded(double x, int digits, bool full, bool known = true) {
  if (!known || !std::isfinite(x)) return nullptr;
  return full ? x : std::stod(num(x, digits));
}

results::Table constants_table(const results::Inference& r, bool full) {
  const auto cell = [full](double x, int digits, bool known = true) { return rounded(x, digits, full, known); };
  results::Table t({"constant", "campaign", "prior_lo", "prior_hi", "posterior_median", "posterior_lo", "posterior_hi",
                    "interval_shrink_pct", "constrained"});
  for (const auto& c : r.constants) {
    // An unconstrained constant gets no number (null in JSON): the measurement says nothing the
    // prior did not.
    const bool say = c.constrained;
    t.add_values({c.name, cell(c.campaign, 4), cell(c.prior_lo, 4), cell(c.prior_hi, 4), cell(c.median, 4, say),
                  cell(c.lo, 4, say), cell(c.hi, 4, say), cell(100 * c.shrink, 3),
                  say ? "yes" : "no: one impact does not constrain it (posterior = prior)"});
  }
  return t;
}

results::Table metrics_table(const results::Inference& r, bool full) {
  results::Table t(
      {"metric", "measured", "sigma_pct", "campaign_law", "posterior_median", "posterior_lo", "posterior_hi"});
  for (const auto& m : r.metrics) {
    if (!full) {  // the table keeps `nan` for a metric not measured
      t.add({m.name, num(m.measured, 4), num(m.sigma_pct, 3), num(m.campaign, 4), num(m.median, 4), num(m.lo, 4),
             num(m.hi, 4)});
      continue;
    }
    t.add_values({m.name, rounded(m.measured, 0, true), rounded(m.sigma_pct, 0, true), rounded(m.campaign, 0, true),
                  rounded(m.median, 0, true), rounded(m.lo, 0, true), rounded(m.hi, 0, true)});
  }
  return t;
}

void run_infer(const InferVerbOptions& v) {
  const results::SavedLaw law = results::read_law(v.law);
  results::Inference r;
  try {
    r = results::infer_ground(law, v.c, v.m, v.o, v.extrapolate);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (r.campaign.range == results::LawRangeFlag::refused && r.constants.empty()) {
    std::fprintf(stderr,
                 "error: the case is far beyond the law's fitted ranges (%s): nothing inferred. --extrapolate infers "
                 "all the same\n",
                 r.campaign.note.c_str());
    throw ExitWith{kExitUsage};
  }
  if (r.campaign.range != results::LawRangeFlag::inside)
    std::fprintf(stderr, "warning: range = %s: %s\n", results::to_string(r.campaign.range), r.campaign.note.c_str());
  if (v.format == "table") {
    fmt::print(
        "Law {} ({}), case g = {:.4g} m/s2, v = {:.4g} m/s, D = {:.4g} m, m = {:.4g} kg: Fr = {:.3g}, range {}\n",
        law.model, v.law, v.c.gravity_m_s2, v.c.speed_m_s, v.c.diameter_m, v.c.mass_kg, r.campaign.froude,
        results::to_string(r.campaign.range));
    fmt::print("\nThe ground's constants (95 % intervals; prior: the campaign's constants, x/÷ {:g} geometric sd):\n",
               v.o.prior_width);
    constants_table(r, false).print("table");
    fmt::print("\nThe measurement beside the campaign's law and the posterior's prediction:\n");
    metrics_table(r, false).print("table");
    fmt::print(
        "\nPosterior by importance sampling ({:.0f} effective samples). sigma: the law's error at this Froude "
        "number ({}) and the measurement's own, in quadrature.{}\n",
        r.effective_samples, law.form_error_source, r.note.empty() ? "" : "\nnote: " + r.note);
    return;
  }
  // csv and json: the constants (the table a script reads); the metrics with --format json only.
  if (v.format == "csv") {
    constants_table(r, true).print("csv");
    return;
  }
  fmt::print("{{\"constants\": ");
  constants_table(r, true).print("json");
  fmt::print(", \"metrics\": ");
  metrics_table(r, true).print("json");
  fmt::print(", \"impact_froude\": {}, \"range\": \"{}\", \"effective_samples\": {:.1f}}}\n", r.campaign.froude,
             results::to_string(r.campaign.range), r.effective_samples);
}

}  // namespace

void setup_model_infer(CLI::App& model) {
  auto v = std::make_shared<InferVerbOptions>();
  auto* sub = model.add_subcommand(
      "infer",
      "What one impact says about the ground: the constants of a saved law (`model fit ... --save\n"
      "law.json`) consistent with a measured stopping depth (and, if measured, the duration and the\n"
      "peak deceleration) of a projectile at a gravity and impact speed. Bayesian: the campaign's\n"
      "constants are the prior (positive constants log-normal, geometric sd --prior-width; others\n"
      "normal); a measured metric is log-normal about the law's prediction with the law's error at\n"
      "the impact's Froude number (held out by gravity level) and the measurement's own error\n"
      "(--zstop-error ...) in quadrature. Prints each constant's prior and posterior 95 % interval;\n"
      "a constant whose interval shrinks by less than half is not constrained by one impact and gets\n"
      "no number. The same range flags and exit codes as `model predict` (refused: exit 2 unless\n"
      "--extrapolate).\n\n"
      "Examples:\n"
      "  gravsweep model infer --law law.json --gravity 0.01 --speed 0.3 --zstop 0.09\n"
      "  gravsweep model infer --law law.json --gravity 1.62 --speed 0.5 --zstop 0.04 --tstop 0.6 "
      "--zstop-error 5");
  sub->add_option("--law", v->law, "the law file (model fit --save)")->required()->check(CLI::ExistingFile);
  sub->add_option("--gravity", v->c.gravity_m_s2, "gravity, m/s2")->required()->check(CLI::PositiveNumber);
  sub->add_option("--speed", v->c.speed_m_s, "impact speed, m/s")->required()->check(CLI::PositiveNumber);
  sub->add_option("--diameter", v->c.diameter_m, "projectile diameter, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--mass", v->c.mass_kg, "projectile mass, kg")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--zstop", v->m.zstop_m, "measured stopping depth below the surface at contact, m")
      ->required()
      ->check(CLI::PositiveNumber);
  sub->add_option("--tstop", v->m.tstop_s, "measured collision duration, s")->check(CLI::PositiveNumber);
  sub->add_option("--apeak", v->m.apeak_m_s2, "measured peak deceleration, m/s2")->check(CLI::PositiveNumber);
  sub->add_option("--zstop-error", v->m.zstop_error_pct, "the depth's own 1-sigma error, %")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  sub->add_option("--tstop-error", v->m.tstop_error_pct, "the duration's own 1-sigma error, %")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  sub->add_option("--apeak-error", v->m.apeak_error_pct, "the peak's own 1-sigma error, %")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  sub->add_option("--prior-width", v->o.prior_width,
                  "geometric standard deviation of the prior of a positive constant about the campaign's value")
      ->check(CLI::Range(1.01, 1000.0))
      ->capture_default_str();
  sub->add_option("--samples", v->o.samples, "importance samples of the posterior")
      ->check(CLI::Range(100, 10000000))
      ->capture_default_str();
  sub->add_option("--seed", v->o.seed, "random seed of the sampler")->capture_default_str();
  sub->add_flag("--extrapolate", v->extrapolate, "infer for cases far beyond the fitted ranges too (still flagged)");
  add_format_option(sub, v->format);
  sub->callback([v]() { run_infer(*v); });
}

}  // namespace gravsweep::cli
