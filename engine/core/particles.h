// Particle storage as a structure of arrays: one contiguous array per field, indexed by ParticleIndex.
// Every particle is a sphere with its own radius, mass, moment of inertia and material; the projectile
// is a particle like the grains, with its own size class and material.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/core/types.h"

namespace gravsweep {

/// Size class of a particle, used to pick the pair parameters (grain-grain, grain-projectile, ...).
enum class SizeClass : std::uint8_t { grain = 0, projectile = 1 };

struct Particles {
  // State (engine frame, z up).
  std::vector<Vec3> position_m;
  std::vector<Vec3> velocity_m_s;
  std::vector<Vec3> omega_rad_s;
  // Velocities used by the force evaluation. Equal to the state for semi-implicit Euler and
  // velocity Verlet; pkdgrav's predicted velocities v_n + dt a_n for the KDK leapfrog.
  std::vector<Vec3> eval_velocity_m_s;
  std::vector<Vec3> eval_omega_rad_s;
  // Accumulated this step (contact + gravity for force; contact for torque).
  std::vector<Vec3> force_N;
  std::vector<Vec3> torque_N_m;
  // Properties.
  std::vector<double> radius_m;
  std::vector<double> mass_kg;
  std::vector<double> inv_mass_1_kg;        ///< 0 for a fixed particle
  std::vector<double> inv_inertia_1_kg_m2;  ///< solid sphere I = 2/5 m r^2; 0 for fixed
  std::vector<std::uint8_t> material;       ///< index into the material table
  std::vector<SizeClass> size_class;

  [[nodiscard]] std::size_t size() const { return position_m.size(); }

  /// Appends a free (or fixed) solid sphere at rest and returns its index.
  ParticleIndex add(const Vec3& pos, double radius, double mass, std::uint8_t material_id, SizeClass cls,
                    bool fixed = false) {
    position_m.push_back(pos);
    velocity_m_s.push_back(Vec3::Zero());
    omega_rad_s.push_back(Vec3::Zero());
    eval_velocity_m_s.push_back(Vec3::Zero());
    eval_omega_rad_s.push_back(Vec3::Zero());
    force_N.push_back(Vec3::Zero());
    torque_N_m.push_back(Vec3::Zero());
    radius_m.push_back(radius);
    mass_kg.push_back(mass);
    inv_mass_1_kg.push_back(fixed ? 0.0 : free_inv_mass_1_kg(mass));
    inv_inertia_1_kg_m2.push_back(fixed ? 0.0 : free_inv_inertia_1_kg_m2(mass, radius));
    material.push_back(material_id);
    size_class.push_back(cls);
    return static_cast<ParticleIndex>(position_m.size() - 1);
  }

  /// Completes the particles from index `first` on whose state (position, velocity, spin) and
  /// properties (radius, mass, material) were filled column by column, as a saved bed is read
  /// back: free solid spheres of class `cls`, with add()'s inverse mass and inertia, whose force
  /// evaluation reads the saved velocities (as after set_velocity), no force yet. The same state
  /// as add() and set_velocity() give, bit for bit.
  void complete_columns(std::size_t first, SizeClass cls) {
    const std::size_t n = size();
    for (auto* v : {&eval_velocity_m_s, &eval_omega_rad_s, &force_N, &torque_N_m}) v->resize(first);
    for (auto* v : {&inv_mass_1_kg, &inv_inertia_1_kg_m2}) v->resize(first);
    size_class.resize(first);
    for (std::size_t i = first; i < n; ++i) {
      eval_velocity_m_s.push_back(velocity_m_s[i]);
      eval_omega_rad_s.push_back(omega_rad_s[i]);
      force_N.push_back(Vec3::Zero());
      torque_N_m.push_back(Vec3::Zero());
      inv_mass_1_kg.push_back(free_inv_mass_1_kg(mass_kg[i]));
      inv_inertia_1_kg_m2.push_back(free_inv_inertia_1_kg_m2(mass_kg[i], radius_m[i]));
      size_class.push_back(cls);
    }
  }

  static double free_inv_mass_1_kg(double mass_kg_) { return 1.0 / mass_kg_; }
  /// A solid sphere's I = 2/5 m r^2, inverted.
  static double free_inv_inertia_1_kg_m2(double mass_kg_, double radius_m_) {
    const double inertia = 0.4 * mass_kg_ * radius_m_ * radius_m_;
    return 1.0 / inertia;
  }

  /// Sets the state velocities of particle i and the copies the force evaluation reads (so a
  /// particle added between steps moves with them from its first force evaluation).
  void set_velocity(ParticleIndex i, const Vec3& v_m_s, const Vec3& omega_rad_s_ = Vec3::Zero()) {
    velocity_m_s[i] = eval_velocity_m_s[i] = v_m_s;
    omega_rad_s[i] = eval_omega_rad_s[i] = omega_rad_s_;
  }

  /// Applies f to every per-particle array (a generic lambda taking `auto& vec`).
  template <class F>
  void for_each_array(F&& f) {
    f(position_m), f(velocity_m_s), f(omega_rad_s), f(eval_velocity_m_s), f(eval_omega_rad_s);
    f(force_N), f(torque_N_m), f(radius_m), f(mass_kg), f(inv_mass_1_kg), f(inv_inertia_1_kg_m2);
    f(material), f(size_class);
  }
  template <class F>
  void for_each_array(F&& f) const {
    f(position_m), f(velocity_m_s), f(omega_rad_s), f(eval_velocity_m_s), f(eval_omega_rad_s);
    f(force_N), f(torque_N_m), f(radius_m), f(mass_kg), f(inv_mass_1_kg), f(inv_inertia_1_kg_m2);
    f(material), f(size_class);
  }

  /// Removes the particles whose flag is true, keeping the order of the others.
  void remove_if(const std::vector<bool>& remove) {
    const std::size_t n = size();
    for_each_array([&](auto& v) {
      std::size_t w = 0;
      for (std::size_t r = 0; r < n; ++r)
        if (!remove[r]) v[w++] = v[r];
      v.resize(w);
    });
  }
};

}  // namespace gravsweep
