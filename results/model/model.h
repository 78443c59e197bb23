// Collision models as sums of registered terms (term.h), their fits to measurement campaigns,
// held-out errors, residual analysis and the ranking of candidate terms ("which effect is
// missing"). Formulas: Sunday et al. 2021 Eqs. 1-5, docs/physics/force-laws.md section 2.
#pragma once
#include <Eigen/Dense>
#include <cmath>
#include <string>
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/term.h"

namespace gravsweep::results {

/// The gravity a term's g-scaled constant is quoted at (ModelTerm::g_power): the constant is its
/// value at 9.81 m/s2, the paper's 1 g.
inline constexpr double kGPowerReference_m_s2 = 9.81;

struct ModelTerm {
  const TermInfo* term = nullptr;
  bool per_gravity = true;
  double scale = 1.0;  ///< for synth: multiplies the term's typical values
  /// Not NaN: one constant for all levels that carries a power of gravity, c (g / 9.81 m/s2)^p
  /// (written "term:g^p"; the scaling check's suggestion, results/model/scaling.h). NaN: none.
  double g_power = NAN;
  [[nodiscard]] bool g_scaled() const { return !std::isnan(g_power); }
};

struct ModelSpec {
  std::vector<ModelTerm> terms;
  /// Residuals of every trial in units of its own force, as one law for all levels is fitted
  /// (fit_model), even when a term has a value per level: the scaling check frees one constant of
  /// such a law per level and must weigh the trials as the law did.
  bool trial_force_units = false;
  [[nodiscard]] std::string name() const;                      ///< "base+depth_friction"
  [[nodiscard]] bool has(const std::string& term_name) const;  ///< a term of that name is in the spec
};

/// Parses "base+depth_friction" (":shared" or ":per_gravity" after a name sets the sharing,
/// ":g^0.3" one constant times (g / 9.81 m/s2)^0.3, "*2.5" a synth scale; "term.param" is one
/// parameter of a term, e.g. scaled_base.inv_d1_1_m), or a JSON spec file ({"terms": [{"name":
/// ..., "shared": bool, "g_power": p, "scale": x}]}, schemas/model.schema.json). A file is checked against its schema
/// (spec/schemas.h): spec::SpecError (a ConfigError) names the file and the JSON pointer of every problem; a bad name
/// in the text form throws ConfigError (find_term), a bad ":mode" std::invalid_argument.
ModelSpec parse_model(const std::string& text_or_path);
/// No term of the spec has a parameter per gravity level (scaled_base, terms with ":shared"): the
/// fitted law holds at any g, levels it was not fitted on included.
bool one_law_for_all_levels(const ModelSpec& spec);

/// A model with fitted coefficients for the gravity levels of a campaign.
struct FittedModel {
  ModelSpec spec;
  std::vector<double> gravity_levels;
  std::vector<std::string> column_names;  ///< "base.f0_N@g=9.81"
  Eigen::VectorXd coef;
  Eigen::MatrixXd cov;  ///< cluster-robust (trials as clusters)
  int trials_used = 0;
  std::size_t samples_used = 0;
  /// Resisting force R (N) at a state; throws std::invalid_argument at a gravity level the model
  /// was not fitted on, unless it is one law for all levels (one_law_for_all_levels).
  [[nodiscard]] double force(const TermContext& c) const;
  [[nodiscard]] int gravity_index(double g) const;  ///< -1 when unknown
};

/// Fits the spec to the trials' fit windows (each trial weighted equally), least squares on
/// m (a_up + g) = R(z, v), residuals in units of m g; for one law for all levels
/// (one_law_for_all_levels) in units of each trial's RMS force instead, as its trials span
/// Froude numbers 0.2-10 and forces 1-300 m g. `trial_mask` (same length as campaign.trials)
/// selects training trials.
FittedModel fit_model(const ModelSpec& spec, const Campaign& c, const std::vector<bool>& trial_mask);
FittedModel fit_model(const ModelSpec& spec, const Campaign& c);
/// The same with each trial counted `trial_count[i]` times (0: left out): a bootstrap resample
/// of whole trials.
FittedModel fit_model(const ModelSpec& spec, const Campaign& c, const std::vector<int>& trial_count);

/// Mean squared acceleration residual (m/s2)^2 of a trial's fit window (a_meas - a_model).
double trial_trace_mse(const FittedModel& m, const MeasuredTrial& t);

struct Prediction {
  double zstop_m = NAN, tstop_s = NAN, apeak_m_s2 = NAN;
  bool stopped = false;
};
/// How long predict integrates before it gives up on a stop (s): kPredictHorizonScaled collision
/// time scales sqrt(D/g) (D the projectile diameter; a drop at 0.001 m/s2 lasts 10 s and more),
/// and at least kPredictHorizonMin_s (the lab's 1 g collisions last well under a second).
inline constexpr double kPredictHorizonScaled = 50.0;
inline constexpr double kPredictHorizonMin_s = 10.0;
double prediction_horizon_s(const TermContext& trial);
/// Integrates m dv/dt = m g - R from the trial's impact speed (RK4) to the stop; apeak is the
/// largest deceleration of the integrated motion. t_max_s NaN: prediction_horizon_s.
Prediction predict(const FittedModel& m, const Trial& info);
Prediction predict(const FittedModel& m, const TermContext& trial, double t_max_s = NAN);
/// The metrics of a measured trial predicted the way it was measured: zstop and tstop
/// of the integrated motion, apeak read off the model's record (model_record) processed like the
/// trial (process_trial's options), so that the 500 Hz filter rounds both peaks alike.
Prediction predict(const FittedModel& m, const MeasuredTrial& t);
/// The same with the grain-scale fluctuation of other trials about the model (relative_residuals):
/// the measured apeak is the largest value of a fluctuating record (on synth campaigns 20 % of the
/// force, so 1.3-2 times the smooth peak), which the smooth model record never reaches; with the
/// fluctuations the model's record has the same kind of largest value. apeak is the mean of what
/// is read off the model's record with each sequence (of at least kMinFluctuationSamples) laid
/// over its collision, times the model's force per mass.
inline constexpr std::size_t kMinFluctuationSamples = 10;
Prediction predict(const FittedModel& m, const MeasuredTrial& t, const std::vector<const std::vector<double>*>& fluct);
/// A trial's fluctuation about the model over its fit window: (a_meas - a_model) / (R / m),
/// clamped to [-1, 1] (samples where the model's force is not positive are left out).
std::vector<double> relative_residuals(const FittedModel& m, const MeasuredTrial& t);
/// The model's record of a trial: on the trial's sample grid, free fall before the measured
/// collision start, Eq. 1 from the measured vc after it, rest after the model's stop; the trial's
/// source, and own velocity and depth when the trial's record has them (DEM).
Trace model_record(const FittedModel& m, const MeasuredTrial& t);

/// Up to kMaxFluctuationTrials of the sequences in `fluct` (one per trial of c, empty for those
/// not to use) from trials at trial i's gravity level other than i itself, in trial order.
inline constexpr std::size_t kMaxFluctuationTrials = 12;
std::vector<const std::vector<double>*> same_level_fluctuations(const Campaign& c,
                                                                const std::vector<std::vector<double>>& fluct,
                                                                std::size_t i);

/// Per-trial held-out results of grouped K-fold cross-validation (whole trials held out); apeak
/// as measured with the training trials' fluctuations at the trial's level.
struct HeldOut {
  std::vector<double> trace_mse;  ///< per trial
  std::vector<Prediction> pred;   ///< per trial, from the model fitted without that trial
};
/// The projectile of each trial: the index of its (diameter, mass), distinct to 1e-9 relative, in
/// order of first appearance; `count` receives how many there are.
std::vector<int> projectile_index(const Campaign& c, int* count = nullptr);
/// `folds` = kLeaveOneProjectileOut: one fold per projectile (its diameter and mass), so that each
/// projectile is predicted by the model fitted on the others.
inline constexpr int kLeaveOneProjectileOut = -1;
HeldOut cross_validate(const ModelSpec& spec, const Campaign& c, int folds = 6, unsigned seed = 1);
/// The same; without predictions (trace residuals only) when with_predictions is false.
HeldOut cross_validate(const ModelSpec& spec, const Campaign& c, int folds, unsigned seed, bool with_predictions);

/// Summary errors against the measured metrics (RMS over trials; relative in %).
struct ErrorSummary {
  double trace_rms_m_s2 = 0, trace_rel_pct = 0;
  double zstop_rms_mm = 0, zstop_rel_pct = 0;
  double tstop_rms_ms = 0, tstop_rel_pct = 0;
  double apeak_rms_m_s2 = 0, apeak_rel_pct = 0;
  int trials = 0;
};
ErrorSummary summarize(const Campaign& c, const HeldOut& h);

/// The paper's method (Sect. 4): per gravity level, Eq. 2 fitted to apeak(vc), Eqs. 3-4 predict
/// zstop and tstop, Eq. 5 gives vt, and zstop ~ H^alpha with H = drop height + zstop.
struct Table3Row {
  double g_m_s2 = 0;
  int trials = 0;
  double f0_N = NAN, f0_se_N = NAN, inv_d1_1_m = NAN, inv_d1_se_1_m = NAN, vt_m_s = NAN, vt_se_m_s = NAN;
  double alpha = NAN, alpha_se = NAN;
  /// Bootstrap over whole drops (kTable3BootstrapResamples, fixed seed): uncertainties that
  /// include the scatter between impact sites, which the OLS errors above understate when sites repeat.
  double f0_boot_se_N = NAN, inv_d1_boot_se_1_m = NAN;
  std::string note;  ///< why a level was not fitted (too few trials or speeds), and clipped trials left out; else empty
};
inline constexpr int kTable3BootstrapResamples = 2000;
inline constexpr unsigned kTable3BootstrapSeed = 1;
/// Eq. 2 is a line in vc^2: a level is fitted only with at least kTable3MinTrials trials whose
/// collision speeds span at least a factor kTable3MinSpeedRatio (one speed cannot separate f0
/// from 1/d1).
inline constexpr int kTable3MinTrials = 3;
inline constexpr double kTable3MinSpeedRatio = 1.5;
std::vector<Table3Row> table3(const Campaign& c);
/// Eqs. 3-4 predictions for a trial from its gravity level's row (NaN when f0 <= m g).
Prediction predict_paper(const Table3Row& row, double mass_kg, double vc_m_s);
/// Held-out Eqs. 2-4 (Table 3 refitted without each fold).
HeldOut cross_validate_paper(const Campaign& c, int folds = 6, unsigned seed = 1);

/// Residuals along one axis: bins (quantiles) with the trial-weighted mean residual / g, and the
/// fraction of the residual variance the binning explains (eta^2).
struct AxisResidual {
  std::string axis;  ///< "depth_m", "speed_m_s", "time_since_contact_s", "gravity_m_s2", ...
  std::vector<double> bin_center, bin_mean_r_over_g;
  double eta2 = 0;
  double slope_sign_trials_p = 1;  ///< sign test over trials of the within-trial slope
  int trials_positive = 0, trials_negative = 0;
  double split_half_r = 0;  ///< bin profile of even- vs odd-numbered trials (Pearson r)
};
std::vector<AxisResidual> residual_axes(const FittedModel& m, const Campaign& c);

/// One candidate's held-out improvement over the current model.
struct Candidate {
  std::string term;                 ///< as a model spec names it: "depth_friction:shared", "immersion_drag:g^1"
  ModelTerm form;                   ///< the term as it was tried (its sharing)
  double mean_rel_improvement = 0;  ///< mean over trials of (mse0 - mse1) / mse0
  int trials_better = 0, trials = 0;
  double p_value = 1;  ///< one-sided Wilcoxon signed-rank test over trials (not samples)
  bool significant = false;
  std::vector<double> trial_rel_gain;  ///< (mse0 - mse1) / mse0 per trial of the campaign, NaN where not finite
};
struct Discovery {
  std::string baseline;
  /// The baseline has no parameter per gravity level (one law for all levels): only such terms
  /// are candidates (scaled mode, `model rank --scaled`).
  bool gravity_scaled = false;
  std::vector<std::vector<Candidate>> rounds;  ///< ranking of the named terms per forward step
  std::vector<std::string> added;              ///< named winners, in order, as a model spec names them
  std::string named_model;                     ///< the baseline with the named winners (parse_model reads it)
  /// Per named winner, the other significant terms of its round that the held-out trials cannot
  /// tell apart from it (detail::cannot_tell_apart): the verdict names them beside it. The best
  /// form of the generated family added to the same model is judged the same way and, when the
  /// trials cannot tell it from the winner, listed as "c * <form>".
  std::vector<std::vector<std::string>> equivalent;
  std::string verdict;          ///< the sentence for users
  bool structure_left = false;  ///< residuals structured after the named additions
  /// A trend too weak for the binned tests (eta^2) but the same in almost every trial (sign test
  /// over trials p < kConsistentTrendP), described ("along depth_m: 41 of 42 trials ..."); empty
  /// when there is none. It also starts the search beyond the named library.
  std::string consistent_trend;
  std::vector<AxisResidual> residual_before, residual_after;
  /// The search beyond the named library (generated.h), run when the named terms were added or
  /// left structure: the nested-CV test of choosing a form (its `term` is the form chosen on all
  /// trials), every form by in-sample improvement, the form added (empty when the test is not
  /// significant), the model with it, whether structure is still left with it, and the held-out
  /// errors without and with it.
  bool generated_searched = false;
  Candidate generated_test;
  std::vector<Candidate> generated_screened;
  std::string generated;
  std::vector<std::string> generated_equivalent;  ///< forms the trials cannot tell apart from it
  bool generated_worsens_metrics = false;         ///< significant on the trace, but zstop or tstop worse held out
  std::string generated_model;
  bool structure_left_after_generated = false;
  ErrorSummary errors_without_generated, errors_with_generated;
};
/// A within-trial residual slope of the same sign in this many trials (sign test p below it) is a
/// trend, however small its share of the residual variance (eta^2): DEM traces carry force-chain
/// noise that keeps eta^2 low while the trend holds in 41 of 42 trials (the full Chrono
/// campaign).
inline constexpr double kConsistentTrendP = 1e-6;

/// Forward selection from `baseline` over all other registered terms by grouped-CV improvement,
/// adding a term while one is significant (signed-rank test over trials, Bonferroni over candidates, at
/// level alpha, and at least min_improvement mean relative gain). When a named term was added or
/// the residuals are still structured (the tests of residual_axes) or trend consistently
/// (kConsistentTrendP), one more step runs over the
/// generated family (model_internal.h, search_generated: nested grouped CV, one signed-rank test at
/// level alpha), and a significant form is reported by its formula: the residuals of the named
/// winners are tested again, and structure they leave makes the verdict "partly explained".
Discovery discover(const Campaign& c, const ModelSpec& baseline, int folds = 6, double alpha = 0.01,
                   double min_improvement = 0.03, int max_rounds = 2, bool search_generated = true);

}  // namespace gravsweep::results
