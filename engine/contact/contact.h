// What a contact law sees and returns. Laws are stateless: they read an immutable ContactGeometry
// and the pair's coefficients, update the contact's own ContactHistory, and return a ContactForce.
// Body 1 is the particle with the smaller index (or the particle in a particle-wall contact);
// body 2 is the other particle or the wall. The unit normal n points from body 1 to body 2.
#pragma once
#include <cmath>
#include <vector>

#include "engine/core/material.h"
#include "engine/core/types.h"

namespace gravsweep {

struct ContactGeometry {
  Vec3 n;             ///< unit normal, body 1 -> body 2
  double overlap_m;   ///< delta_n > 0 while touching
  double distance_m;  ///< centre distance (wall: centre-to-surface distance)
  double r1_m, r2_m;  ///< radii (r2 unused for walls)
  double R_eff_m;     ///< effective radius R* (wall: R, or R Rc/(Rc-R) on a concave cylinder)
  double m_eff_kg;    ///< effective mass m* (wall: the particle's mass, wall of infinite mass)
  Vec3 v1, v2;        ///< centre velocities used for forces (wall: v2 = 0)
  Vec3 w1, w2;        ///< angular velocities (wall: w2 = 0)
  bool wall;          ///< body 2 is a fixed wall
};

/// The effective mass m* = m1 m2 / (m1 + m2) of two bodies, kg; a fixed body (mass +inf) gives
/// the other's mass.
GRAVSWEEP_INLINE double effective_mass_kg(double m1_kg, double m2_kg) {
  return std::isinf(m1_kg) ? m2_kg : std::isinf(m2_kg) ? m1_kg : m1_kg * m2_kg / (m1_kg + m2_kg);
}

/// Per-contact state that survives from step to step (and across neighbour-list rebuilds): the
/// part every law and model uses, 48 bytes, stored for every listed pair.
struct ContactHistory {
  Vec3 shear_m = Vec3::Zero();  ///< tangential spring (Chrono delta_t / pkdgrav S)
  double duration_s = 0;        ///< time since first touch (Chrono contact_duration)
  double gate_s = 0;            ///< Chrono's rolling/spinning activation time t_collision
  bool active = false;          ///< false: no history yet (new contact)
};

/// The history of the rotating contact frame (pkdgrav's n_old and Zhang's rolling and twisting
/// springs), 56 bytes. Stored beside ContactHistory only when the law or the rolling model declares
/// `uses_frame_history` (hooke, zhang); the others get a scratch record that nothing reads.
/// The force loop resets it together with a new contact's ContactHistory.
struct FrameHistory {
  Vec3 n_old = Vec3::Zero();     ///< normal of the previous step (pkdgrav frame rotation)
  Vec3 roll_rad = Vec3::Zero();  ///< rolling spring angle phi_R (Zhang 2017)
  double twist_rad = 0;          ///< twisting spring angle phi_Q (Zhang 2017)
};

/// Law-wide switches, shared by all pairs.
struct ContactOptions {
  bool clamp_normal = false;         ///< clamp F_n >= 0 (Chrono does not; docs/physics/contact-laws.md 4.2)
  double min_slip_vel_m_s = 1e-4;    ///< Chrono min_slip_vel
  double min_roll_vel_m_s = 1e-4;    ///< Chrono min_roll_vel
  double min_spin_vel_rad_s = 1e-4;  ///< Chrono min_spin_vel
};

/// Result of one contact evaluation, plus the quantities the rolling models need.
struct ContactForce {
  Vec3 force_on_2 = Vec3::Zero();  ///< body 1 receives the opposite
  Vec3 torque_1 = Vec3::Zero();
  Vec3 torque_2 = Vec3::Zero();
  double normal_force_N = 0;               ///< signed damped normal force (> 0 repulsive)
  double kn_N_m = 0, kt_N_m = 0;           ///< instantaneous stiffnesses
  double cn_N_s_m = 0, ct_N_s_m = 0;       ///< instantaneous damping coefficients
  Vec3 u_contact = Vec3::Zero();           ///< relative contact-point velocity (2 minus 1)
  double lever1_m = 0, lever2_m = 0;       ///< distances from centres to the contact plane
  Quat frame_rotation = Quat::Identity();  ///< rotation of the contact frame this step
};

}  // namespace gravsweep

namespace gravsweep {

/// What a law needs to check its parameters and the time step before a run.
struct LawSetup {
  const std::vector<Material>& materials;
  const PairTable& pairs;
  /// Smallest radius and mass of the particles of each material (0 when no particle has it);
  /// walls use their material with is_wall_material true.
  const std::vector<double>& min_radius_m;
  const std::vector<double>& min_mass_kg;
  const std::vector<bool>& is_wall_material;
  double dt_s;
  bool check_time_step;
};

/// A pair of materials whose smallest particles can touch: the smallest bodies' effective mass
/// m* = m_a m_b / (m_a + m_b) and radius R* = r_a r_b / (r_a + r_b), a wall counting as infinite
/// mass and radius (so m* and R* are the particle's own).
struct SmallestPair {
  std::size_t a, b;  ///< material indices, a <= b
  double m_eff_kg;
  double r_eff_m;
};

/// Calls f(SmallestPair) for every pair of materials that can touch in this run: both present
/// (a particle of each, or a wall), not both walls. The laws' step checks and shortest contact
/// times walk the pairs through this one loop.
template <class F>
void for_each_smallest_pair(const LawSetup& s, F&& f) {
  const auto harmonic = [](double x, double y) { return std::isinf(x) ? y : std::isinf(y) ? x : x * y / (x + y); };
  const std::size_t nm = s.materials.size();
  for (std::size_t a = 0; a < nm; ++a)
    for (std::size_t b = a; b < nm; ++b) {
      const bool wall_a = s.is_wall_material[a], wall_b = s.is_wall_material[b];
      if (wall_a && wall_b) continue;
      const double ma = wall_a ? kInf : s.min_mass_kg[a], mb = wall_b ? kInf : s.min_mass_kg[b];
      if (ma <= 0 || mb <= 0) continue;  // no particle of this material
      const double ra = wall_a ? kInf : s.min_radius_m[a], rb = wall_b ? kInf : s.min_radius_m[b];
      f(SmallestPair{a, b, harmonic(ma, mb), harmonic(ra, rb)});
    }
}

}  // namespace gravsweep
