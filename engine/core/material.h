// Materials and per-pair contact coefficients.
//
// Each particle and each wall has a material. Contact coefficients are stored per *pair* of
// materials (grain-grain, grain-wall, grain-projectile, projectile-wall, ...), built in one of two
// ways (docs/physics/contact-laws.md section 1.2):
//   - explicit_pair: the user gives restitution and friction per pair type; elastic moduli combine
//     with the Hertz formulas;
//   - chrono_min: Chrono's default ChContactMaterialCompositionStrategy, min(a, b) of the two
//     materials for restitution and all frictions.
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace gravsweep {

struct Material {
  std::string name;
  double young_modulus_Pa = 7.0e8;  ///< E (Hertz law)
  double poisson_ratio = 0.24;      ///< nu in (0, 0.5)
  double density_kg_m3 = 2480.0;
  double cor_normal = 0.9;      ///< normal coefficient of restitution, (0, 1]
  double cor_tangential = 1.0;  ///< pkdgrav eps_t, (0, 1]
  double mu_static = 0.16;      ///< sliding (Coulomb) friction
  double mu_rolling = 0.0;      ///< rolling friction (Chrono: lever fraction; pkdgrav: mu_r)
  double mu_twisting = 0.0;     ///< twisting / spinning friction
  double kn_N_m = 0.0;          ///< pkdgrav normal spring constant (Hooke law)
  double kt_N_m = 0.0;          ///< pkdgrav tangential spring; 0 means 2/7 kn (pkdgrav default)
  double shape_beta = 0.05;     ///< pkdgrav/Zhang 2017 shape parameter beta
};

/// Restitution and friction for one pair type, used by explicit_pair composition. Unset fields
/// fall back to the chrono_min value.
struct PairOverride {
  std::optional<double> cor_normal, cor_tangential, mu_static, mu_rolling, mu_twisting, kn_N_m, kt_N_m, shape_beta;
};

enum class Composition { explicit_pair, chrono_min };

/// Coefficients of one contact between materials a and b; symmetric in (a, b).
struct PairCoefficients {
  double E_eff_Pa = 0;  ///< 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2 (docs/physics/contact-laws.md 1.2)
  double G_eff_Pa = 0;  ///< 1/G* = 2(2-nu1)(1+nu1)/E1 + 2(2-nu2)(1+nu2)/E2
  double kn_N_m = 0;    ///< Hooke normal stiffness
  double kt_N_m = 0;    ///< Hooke tangential stiffness
  double cor_normal = 1;
  double cor_tangential = 1;
  double mu_static = 0;
  double mu_rolling = 0;
  double mu_twisting = 0;
  double shape_beta = 0;
  /// Dimensionless damping prefactors derived once per pair by the law's prepare() from the
  /// restitution coefficients, so the contact loop does no logarithms. Both laws damp with
  /// prefactor x sqrt(stiffness x m*): Hertz (Chrono) gn = damping_prefactor_n sqrt(Sn m*) and
  /// gt = damping_prefactor_t sqrt(Sn m*) (the sqrt(4 G*/E*) of St/Sn is folded into the
  /// prefactor); Hooke (pkdgrav) C_N = damping_prefactor_n sqrt(k_N m*), C_T =
  /// damping_prefactor_t sqrt(k_T m*) (docs/physics/contact-laws.md sections 1.3, 2.1-2.2).
  double damping_prefactor_n = 0;
  double damping_prefactor_t = 0;
};

/// Symmetric table of PairCoefficients indexed by two material ids.
class PairTable {
 public:
  PairTable() = default;
  explicit PairTable(std::size_t n_materials) : n_(n_materials), table_(n_materials * n_materials) {}
  [[nodiscard]] const PairCoefficients& operator()(std::size_t a, std::size_t b) const { return table_[a * n_ + b]; }
  void set(std::size_t a, std::size_t b, const PairCoefficients& c) {
    table_[a * n_ + b] = c;
    table_[b * n_ + a] = c;
  }
  [[nodiscard]] std::size_t materials() const { return n_; }
  /// Applies f to every entry (both halves of the symmetric table).
  template <class F>
  void for_each(F&& f) {
    for (auto& c : table_) f(c);
  }

 private:
  std::size_t n_ = 0;
  std::vector<PairCoefficients> table_;
};

/// Builds the coefficients of a pair: moduli by the Hertz composition formulas, the rest by
/// Chrono's min() strategy, then any explicit override applied on top.
PairCoefficients compose_pair(const Material& a, const Material& b, const PairOverride* override_or_null);

/// Range checks of a material; throws ConfigError naming the material and the parameter.
void validate_material(const Material& m);

}  // namespace gravsweep
