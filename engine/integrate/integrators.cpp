#include "engine/integrate/integrators.h"

#include <fmt/format.h>

#include <algorithm>

#include "engine/core/error.h"
#include "engine/core/registry.h"

namespace gravsweep {

namespace {

/// Runs body(i) on particles [begin, end); body returns the particle's new position, which the
/// step checks read from registers (re-reading it from memory right after the store stalls).
template <class Body>
GRAVSWEEP_INLINE void end_loop(const StepCheck& check, std::size_t begin, std::size_t end, StepFindings& found,
                               Body&& body) {
  double max_d2 = found.max_displacement2_m2;
  for (std::size_t i = begin; i < end; ++i) {
    const Vec3 x = body(i);
    const StateFault c = check.visit(x, i, &max_d2);
    if (c != StateFault::none && found.bad_particle < 0) {
      found.bad_particle = static_cast<long long>(i);
      found.bad_cause = c;
    }
  }
  found.max_displacement2_m2 = max_d2;
}

/// The closing half kick v += dt/2 a, w += dt/2 alpha of velocity Verlet and of the kick-drift-kick
/// leapfrog on particles [begin, end), with the step checks.
void closing_half_kick(Particles& p, double dt, const StepCheck& check, std::size_t begin, std::size_t end,
                       StepFindings& found) {
  end_loop(check, begin, end, found, [&](std::size_t i) -> Vec3 {
    const Vec3 v = p.velocity_m_s[i] + 0.5 * dt * p.inv_mass_1_kg[i] * p.force_N[i];
    p.velocity_m_s[i] = v;
    p.omega_rad_s[i] += 0.5 * dt * p.inv_inertia_1_kg_m2[i] * p.torque_N_m[i];
    // Positions moved in begin_step; a NaN velocity shows in the position next step.
    return std::isfinite(v.x() + v.y() + v.z()) ? p.position_m[i] : v;
  });
}

/// Chrono::Multicore: v_{n+1} = v_n + h a(x_n, v_n); x_{n+1} = x_n + h v_{n+1}
/// (docs/physics/contact-laws.md section 1.6).
class SemiImplicitEuler final : public Integrator {
 public:
  void begin_step(Particles&, double) override {}
  void end_range(Particles& p, double dt, const StepCheck& check, std::size_t begin, std::size_t end,
                 StepFindings& found) const override {
    end_loop(check, begin, end, found, [&](std::size_t i) -> Vec3 {
      const Vec3 v = p.velocity_m_s[i] + dt * p.inv_mass_1_kg[i] * p.force_N[i];
      p.velocity_m_s[i] = v;
      p.omega_rad_s[i] += dt * p.inv_inertia_1_kg_m2[i] * p.torque_N_m[i];
      const Vec3 x = p.inv_mass_1_kg[i] > 0 ? Vec3(p.position_m[i] + dt * v) : p.position_m[i];
      p.position_m[i] = x;
      return x;
    });
  }
};

/// Velocity Verlet (kick-drift-kick); forces are evaluated with the half-step velocities.
class VelocityVerlet final : public Integrator {
 public:
  bool needs_initial_forces() const override { return true; }
  void begin_step(Particles& p, double dt) override {
    const std::size_t n = p.size();
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      p.velocity_m_s[i] += 0.5 * dt * p.inv_mass_1_kg[i] * p.force_N[i];
      p.omega_rad_s[i] += 0.5 * dt * p.inv_inertia_1_kg_m2[i] * p.torque_N_m[i];
      if (p.inv_mass_1_kg[i] > 0) p.position_m[i] += dt * p.velocity_m_s[i];
    }
  }
  void end_range(Particles& p, double dt, const StepCheck& check, std::size_t begin, std::size_t end,
                 StepFindings& found) const override {
    closing_half_kick(p, dt, check, begin, end, found);
  }
};

/// pkdgrav: kick-drift-kick leapfrog; forces at x_{n+1} with predicted velocities
/// v_pred = v_n + dt a_n, w_pred = w_n + dt wdot_n (docs/physics/contact-laws.md section 2.4).
class LeapfrogKdk final : public Integrator {
 public:
  bool needs_initial_forces() const override { return true; }
  bool uses_eval_velocities() const override { return true; }
  void begin_step(Particles& p, double dt) override {
    const std::size_t n = p.size();
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 a = p.inv_mass_1_kg[i] * p.force_N[i];
      const Vec3 alpha = p.inv_inertia_1_kg_m2[i] * p.torque_N_m[i];
      p.eval_velocity_m_s[i] = p.velocity_m_s[i] + dt * a;
      p.eval_omega_rad_s[i] = p.omega_rad_s[i] + dt * alpha;
      p.velocity_m_s[i] += 0.5 * dt * a;
      p.omega_rad_s[i] += 0.5 * dt * alpha;
      if (p.inv_mass_1_kg[i] > 0) p.position_m[i] += dt * p.velocity_m_s[i];
    }
  }
  void end_range(Particles& p, double dt, const StepCheck& check, std::size_t begin, std::size_t end,
                 StepFindings& found) const override {
    closing_half_kick(p, dt, check, begin, end, found);
  }
};

template <class T>
std::unique_ptr<Integrator> make() {
  return std::make_unique<T>();
}

}  // namespace

void StepCheck::merge(const StepFindings& f) {
  if (f.bad_particle >= 0 && (found.bad_particle < 0 || f.bad_particle < found.bad_particle)) {
    found.bad_particle = f.bad_particle;
    found.bad_cause = f.bad_cause;
  }
  found.max_displacement2_m2 = std::max(found.max_displacement2_m2, f.max_displacement2_m2);
}

const std::vector<IntegratorEntry>& integrator_table() {
  static const std::vector<IntegratorEntry> table = {
      {"semi_implicit_euler", "symplectic Euler, velocity first (Chrono::Multicore)", &make<SemiImplicitEuler>},
      {"leapfrog_kdk", "kick-drift-kick leapfrog with predicted velocities (pkdgrav)", &make<LeapfrogKdk>},
      {"velocity_verlet", "velocity Verlet, forces with half-step velocities", &make<VelocityVerlet>},
  };
  return table;
}

std::unique_ptr<Integrator> make_integrator(std::string_view name) {
  return find_row(integrator_table(), name, "integrator").make();
}

}  // namespace gravsweep
