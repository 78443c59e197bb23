// A collision model as a sum of registered terms (term.h): which terms, each one's sharing across
// gravity levels (per level, shared, or carried by a power of g), parsed from "base+depth_friction"
// or a JSON spec file (schemas/model.schema.json). Sunday et al. 2021 Eq. 1; docs/physics/force-laws.md.
#pragma once
#include <cmath>
#include <string>
#include <vector>

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

/// The units of each trial's residuals in a fit (fit_model), trials weighted equally in them.
enum class ResidualUnits {
  automatic,    ///< one law for all levels: trial_force; a law per level: gravity
  trial_force,  ///< the trial's own RMS force (m times the RMS of a_up + g over its fit window)
  gravity,      ///< m g: a fast drop's residuals count as much more as its force is larger
};

struct ModelSpec {
  std::vector<ModelTerm> terms;
  /// automatic, unless a caller fixes them: the scaling check frees one constant of a law for all
  /// levels per level and must weigh the trials as the law did (trial_force); `model fit --weight`
  /// gives a law's sensitivity to the weighting.
  ResidualUnits residual_units = ResidualUnits::automatic;
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

}  // namespace gravsweep::results
