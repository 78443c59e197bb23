// Time integrators, selected by name from one table (integrate/integrators.cpp).
// Each splits a step into begin_step (before forces) and end_step (after forces); forces already
// include gravity. Rotations use the sphere's scalar inertia (no gyroscopic term for spheres).
#pragma once
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/particles.h"

namespace gravsweep {

class Integrator {
 public:
  virtual ~Integrator() = default;
  /// Called before the force evaluation of the step.
  virtual void begin_step(Particles& p, double dt_s) = 0;
  /// Called after the forces at the new positions are known.
  virtual void end_step(Particles& p, double dt_s) = 0;
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
