// Time integrators, selected by name from one table (integrate/integrators.cpp).
// Each splits a step into begin_step (before forces) and end_range (after forces, run by the force
// loop on each thread's share); forces already include gravity. Rotations use the sphere's scalar
// inertia (no gyroscopic term for spheres).
#pragma once
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/core/particles.h"

namespace gravsweep {

/// What the end-of-step check found wrong with a particle's state.
enum class StateFault : unsigned char {
  none = 0,
  non_finite,      ///< NaN or inf in the position (a bad velocity reaches it in the same step)
  outside_domain,  ///< the centre left the domain: the particle left the container
};

/// What the end-of-step checks found: on one thread's share of the particles, or on all of them
/// once merged into StepCheck::found.
struct StepFindings {
  long long bad_particle = -1;  ///< the first particle whose state is bad
  StateFault bad_cause = StateFault::none;
  double max_displacement2_m2 = 0;
};

/// Checks made on every particle in the integrator's last loop of a step, so the state is read
/// once: non-finite values, a centre outside the domain, and the largest displacement since the
/// neighbour list was built (drives the rebuild).
struct StepCheck {
  // Inputs.
  bool have_domain = false;
  Vec3 lo_m = Vec3::Zero(), hi_m = Vec3::Zero();
  const Vec3* position_at_build = nullptr;  ///< null: no list yet (rebuild anyway)
  // Output: every thread's findings merged (merge).
  StepFindings found;

  /// Per-particle check on the particle's new position (a NaN or inf in a velocity reaches the
  /// position in the same step); returns what is wrong (none = fine) and updates *max_d2.
  GRAVSWEEP_INLINE StateFault visit(const Vec3& x, std::size_t i, double* max_d2) const {
    if (!std::isfinite(x.x() + x.y() + x.z())) return StateFault::non_finite;
    if (have_domain && ((x.array() < lo_m.array()).any() || (x.array() > hi_m.array()).any()))
      return StateFault::outside_domain;
    if (position_at_build != nullptr) *max_d2 = std::max(*max_d2, (x - position_at_build[i]).squaredNorm());
    return StateFault::none;
  }
  /// Adds one share's findings to `found` (not thread-safe: the force loop merges each thread's
  /// findings after its parallel region): the lowest bad particle wins, displacements take the
  /// maximum.
  void merge(const StepFindings& f);
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  /// Called before the force evaluation of the step.
  virtual void begin_step(Particles& p, double dt_s) = 0;
  /// The end of step of particles [begin, end), checked with `check`, findings into `found`;
  /// called by each thread of a parallel region on its share (System::step runs it inside the
  /// force loop's region).
  virtual void end_range(Particles& p, double dt_s, const StepCheck& check, std::size_t begin, std::size_t end,
                         StepFindings& found) const = 0;
  /// True when the force loop must read Particles::eval_velocity/eval_omega (predicted velocities).
  [[nodiscard]] virtual bool uses_eval_velocities() const { return false; }
  /// True when begin_step needs the forces of the previous step (evaluated once before step 1).
  [[nodiscard]] virtual bool needs_initial_forces() const { return false; }
};

struct IntegratorEntry {
  const char* name;
  const char* description;
  std::unique_ptr<Integrator> (*make)();
};

/// The table of integrators.
const std::vector<IntegratorEntry>& integrator_table();

/// Creates an integrator by name; an unknown name is a ConfigError listing the valid ones.
std::unique_ptr<Integrator> make_integrator(std::string_view name);

}  // namespace gravsweep
