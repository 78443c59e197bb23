// A gravity-scaled law kept in a file and applied to a body and projectile of one's own: `model fit
// --save law.json` writes it, `model predict --law law.json` integrates it (Sunday et al. 2021
// Eq. 1 with the fitted resistance) for a gravity, speed, diameter and mass, with 95 % intervals
// and a flag that says whether the case lies inside what the law was fitted on. Format:
// docs/formats/law.md (JSON, "format": "gravsweep-law", "format_version": 1).
#pragma once
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/fit.h"
#include "results/model/model_spec.h"

namespace gravsweep::results {

inline constexpr const char* kLawFormat = "gravsweep-law";
inline constexpr int kLawFormatVersion = 1;
/// Bootstrap resamples of the constants saved with a law (`model fit --resamples`).
inline constexpr int kLawResamples = 200;

/// A case beyond the fitted range by at most these factors is an extrapolation (flagged); further
/// it is refused: gravity (a factor, either way), Froude number, projectile diameter and mass.
inline constexpr double kLawExtrapolateGravity = 10.0;
inline constexpr double kLawExtrapolateFroude = 2.0;
inline constexpr double kLawExtrapolateDiameter = 2.0;
inline constexpr double kLawExtrapolateMass = 4.0;

struct LawRange {
  double lo = NAN, hi = NAN;
  [[nodiscard]] bool holds(double x) const { return x >= lo * (1 - 1e-9) && x <= hi * (1 + 1e-9); }
};

/// The law's error by Froude number: per design Froude number of the campaign, the RMS over its
/// drops of 100 (predicted - measured) / measured, held out (leave one gravity level out) when the
/// campaign has two levels or more, in sample otherwise (`source` says which).
struct LawFormError {
  double froude = NAN;
  int drops = 0;
  double zstop_rms_pct = NAN, tstop_rms_pct = NAN, apeak_rms_pct = NAN;
};

struct SavedLaw {
  std::string model;                            ///< the law as `--model` writes it
  std::vector<std::string> constants;           ///< FittedModel::column_names
  std::vector<double> values;                   ///< fitted on every trial
  std::vector<std::vector<double>> covariance;  ///< cluster-robust over drops
  std::vector<std::vector<double>> bootstrap;   ///< resamples x constants (drops resampled within levels)
  std::vector<LawFormError> form_error;         ///< ascending Fr
  std::string form_error_source;                ///< "leave one gravity level out" or "in sample"
  LawRange gravity_m_s2, froude, diameter_m, mass_kg, grain_diameter_m;
  /// The bed the law was fitted on: its bulk density and fill height (the floor below the
  /// surface). Recorded for the user to compare with their ground; predict takes no bed and does
  /// not flag against them. NaN when the file predates them or no trial records them.
  LawRange bulk_density_kg_m3, fill_height_m;
  int trials = 0, levels = 0;
  std::string code_version;  ///< the build that fitted it
  std::string fitted_on;     ///< the inputs, as given
};

/// Fits `law` (one law for all levels: one_law_for_all_levels; std::invalid_argument otherwise) on
/// campaign `c` and gathers what a prediction needs.
SavedLaw make_saved_law(const ModelSpec& law, const Campaign& c, int resamples = kLawResamples, unsigned seed = 1);

/// The fitted law as a model (the saved constants and covariance).
FittedModel law_model(const SavedLaw& s);

void write_law(const std::filesystem::path& path, const SavedLaw& s);
/// Reads and checks a law file: ConfigError naming the file, and the JSON pointer of the field,
/// when it is not a gravsweep law, of another format version, or inconsistent.
SavedLaw read_law(const std::filesystem::path& path);

struct LawCase {
  double gravity_m_s2 = NAN, speed_m_s = NAN, diameter_m = NAN, mass_kg = NAN;
};

/// Where a case lies against the fitted ranges.
enum class LawRangeFlag { inside, extrapolated, refused };
const char* to_string(LawRangeFlag f);

struct LawPrediction {
  double froude = NAN;
  double zstop_m = NAN, zstop_lo_m = NAN, zstop_hi_m = NAN;
  double tstop_s = NAN, tstop_lo_s = NAN, tstop_hi_s = NAN;
  double apeak_m_s2 = NAN, apeak_lo_m_s2 = NAN, apeak_hi_m_s2 = NAN;
  LawRangeFlag range = LawRangeFlag::inside;
  std::string note;  ///< which ranges a case leaves, by how much
};

/// The context of a case for predict (predict.h): its gravity, speed, diameter and mass, on a bed
/// deep enough not to matter, of the grains the law was fitted on (the geometric middle of its
/// grain-diameter range; Table 1's 1 cm when the law records none).
TermContext law_case_context(const SavedLaw& law, const LawCase& c);

/// The law with no fitted ranges (--extrapolate: every case is predicted; the caller keeps the
/// flag of the real ranges).
SavedLaw without_ranges(SavedLaw law);

/// The law's RMS relative error, %, of metric k (0 zstop, 1 tstop, 2 apeak) at Froude number fr:
/// linear in ln Fr between the design's Froude numbers, the end values beyond them; NaN when the
/// law has none for that metric.
double form_error_at(const std::vector<LawFormError>& f, double fr, int k);

/// Integrates the law from the impact speed to the stop (predict, predict.h). The 95 % interval
/// holds the constants' uncertainty (the 2.5 and 97.5 % points of the predictions of the bootstrap
/// resamples) and the law's form error at the case's Froude number (1.96 times its RMS relative
/// error there, interpolated in ln Fr, held at the end values beyond them), added in quadrature
/// as relative half-widths about the prediction.
LawPrediction predict_case(const SavedLaw& law, const LawCase& c);

}  // namespace gravsweep::results
