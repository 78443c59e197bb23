// Collision-model terms: m dv/dt = m g - R(z, v, g, ...), R = sum over terms of
// theta_j * phi_j(state) (Sunday et al. 2021 Eq. 1 and the library of
// docs/physics/force-laws.md section 2.2). Each term is linear in its parameters, so trace-level
// fits are (weighted) least squares and every candidate can be compared on the same footing.
//
// Adding a term = one file in results/model/terms/ defining `TermInfo <name>_term()` and one row
// in the GRAVSWEEP_MODEL_TERMS list below (see ARCHITECTURE.md, "Collision-model terms").
#pragma once
#include <functional>
#include <string>
#include <vector>

namespace gravsweep::results {

/// The state a term sees: z down (m), v down (m/s), the trial's gravity and geometry.
struct TermContext {
  double z_m = 0;
  double v_m_s = 0;
  double g_m_s2 = 9.81;
  double t_since_contact_s = 0;
  double fill_height_m = 0.1;
  double diameter_m = 0.1;
  double mass_kg = 1.0;
  double grain_diameter_m = 0.01;  ///< the bed's grains (Table 1: 1 cm)
  double vc_m_s = 0;               ///< impact speed of the trial
};

struct TermInfo {
  std::string name;                 ///< as used in model specs: "depth_friction"
  std::string meaning;              ///< one line of physics
  std::string references;           ///< where it comes from
  std::string signature;            ///< what the residual looks like when it is missing
  std::vector<std::string> params;  ///< parameter names with units: "k_N_m"
  bool per_gravity = true;          ///< default sharing: one value per gravity level, or shared
  /// Resisting force (N, positive up, i.e. opposing a downward motion) per unit of each parameter.
  std::function<void(const TermContext&, double* out)> features;
  /// Typical parameter values at gravity g, used as the hidden truth by `gravsweep synth` (empty
  /// for generated terms: they have no typical size).
  std::function<std::vector<double>(double g_m_s2, double mass_kg, double diameter_m)> typical;
  /// A form of the generated family (generated.h), not a named effect of the library.
  bool generated = false;
  /// A baseline to start from (`--baseline`), never ranked as a missing effect: scaled_base is
  /// the whole Poncelet law again, collinear with base's per-level f0 and 1/d1.
  bool baseline_only = false;
  /// The registered term that is this one's constant times g, when there is one
  /// (depth_friction: gravity_depth_friction; base: scaled_base). The scaled mode of `model rank`
  /// tries a per-level term shared by all levels and carried by g; where a registered term is the
  /// latter, that term is tried instead (and a term whose g-form is a baseline is not tried).
  std::string gravity_form;
};

// The registry: one row per term (the function is defined in terms/<name>.cpp).
#define GRAVSWEEP_MODEL_TERMS(X) \
  X(base)                        \
  X(scaled_base)                 \
  X(area_scaled_base)            \
  X(depth_friction)              \
  X(gravity_depth_friction)      \
  X(viscous_drag)                \
  X(immersion_drag)              \
  X(bottom_stiffening)           \
  X(cohesion)                    \
  X(grain_drag)

#define GRAVSWEEP_DECLARE_TERM(name) TermInfo name##_term();
GRAVSWEEP_MODEL_TERMS(GRAVSWEEP_DECLARE_TERM)
#undef GRAVSWEEP_DECLARE_TERM

/// All registered terms, in registry order.
const std::vector<TermInfo>& term_registry();
/// The term of that name: a registered one, or a form of the generated family (generated.h, e.g.
/// "z^1*v^1"); throws ConfigError listing the known names otherwise (engine/core/registry.h).
const TermInfo& find_term(const std::string& name);

}  // namespace gravsweep::results
