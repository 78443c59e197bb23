// What one impact says about the ground (`gravsweep model infer`): the constants of a saved
// gravity-scaled law (results/model/law.h) that are consistent with a measured stopping depth,
// and optionally the collision's duration and peak deceleration, of one projectile at one
// gravity and speed (Sunday et al. 2022, paper II, conclusions: constrain the surface from a
// lander's or a projectile's penetration).
//
// Bayesian, with the campaign's constants as the prior: each positive constant log-normal about
// its campaign value (geometric standard deviation `prior_width`), any other constant normal
// (standard deviation (prior_width - 1) |value|), independent. The likelihood of a measured
// metric is log-normal about the law's prediction with the law's form error at the impact's
// Froude number (its RMS relative error held out by gravity level, law.h) and the measurement's
// own error in quadrature. The posterior is sampled by importance sampling: a pilot from the
// prior, then rounds from a normal proposal fitted to the samples so far (widened, mixed with the
// prior). A constant whose 95 % interval shrinks by less than half of the prior's is reported as
// not constrained by the impact: its posterior is the prior.
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include "results/model/law.h"

namespace gravsweep::results {

/// Geometric standard deviation of the prior of a positive constant about the campaign's value.
inline constexpr double kInferPriorWidth = 2.0;
/// Importance samples: a pilot of half as many from the prior, then rounds of half as many from a
/// proposal refitted each round (at most four), until the effective sample size reaches a tenth.
inline constexpr int kInferSamples = 2000;
/// A constant is constrained when its 95 % posterior interval is narrower than this share of the
/// prior's (in the prior's scale: logarithmic for positive constants).
inline constexpr double kInferConstrainedShare = 0.5;
/// Below this effective sample size the posterior's quantiles are rough (said in the note).
inline constexpr double kInferMinEffectiveSamples = 100.0;

/// One impact's measurement: NaN for what was not measured. Errors are 1-sigma relative, %.
struct InferMeasurement {
  double zstop_m = NAN, tstop_s = NAN, apeak_m_s2 = NAN;
  double zstop_error_pct = 0, tstop_error_pct = 0, apeak_error_pct = 0;
};

struct InferOptions {
  double prior_width = kInferPriorWidth;
  int samples = kInferSamples;
  unsigned seed = 1;
};

/// A constant's prior and posterior: medians and 95 % intervals (2.5 and 97.5 % points).
struct ConstantPosterior {
  std::string name;
  double campaign = NAN;  ///< the saved law's value: the prior's median
  bool log_scale = true;  ///< positive constant: prior log-normal
  double prior_lo = NAN, prior_hi = NAN;
  double median = NAN, lo = NAN, hi = NAN;
  double shrink = NAN;  ///< 1 - posterior width / prior width (0: nothing learned)
  bool constrained = false;
};

/// A measured metric beside the law's prediction with the campaign's constants and its posterior
/// predictive median and 95 % interval.
struct MetricPosterior {
  std::string name;  ///< zstop_m, tstop_s or apeak_m_s2
  double measured = NAN, sigma_pct = NAN;
  double campaign = NAN;
  double median = NAN, lo = NAN, hi = NAN;
};

struct Inference {
  LawPrediction campaign;  ///< the case's prediction with the campaign's law, and its range flag
  std::vector<ConstantPosterior> constants;
  std::vector<MetricPosterior> metrics;
  double effective_samples = NAN;
  std::string note;
};

/// Infers the ground's constants from one impact. std::invalid_argument when nothing is measured
/// or a measured value is not positive. A case refused by the law's ranges (predict_case) is
/// returned with its flag and no posterior unless `extrapolate`.
Inference infer_ground(const SavedLaw& law, const LawCase& c, const InferMeasurement& m, const InferOptions& o = {},
                       bool extrapolate = false);

}  // namespace gravsweep::results
