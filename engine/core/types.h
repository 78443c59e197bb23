// Basic numeric types and named constants shared by the whole engine.
// Conventions: SI units everywhere; z is up in the engine's frame (gravity along -z by default).
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

/// Contact kernels are inlined into the one pair loop (engine/system/force_loop.h).
/// GRAVSWEEP_INLINE_LAMBDA goes after a lambda's parameter list: `[&]() GRAVSWEEP_INLINE_LAMBDA {`.
#if defined(__GNUC__)
#define GRAVSWEEP_INLINE [[gnu::always_inline]] inline
#define GRAVSWEEP_INLINE_LAMBDA __attribute__((always_inline))
#else
#define GRAVSWEEP_INLINE inline
#define GRAVSWEEP_INLINE_LAMBDA
#endif

namespace gravsweep {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

inline constexpr double kPi = std::numbers::pi;
/// Earth's gravity as the paper uses it (Sunday et al. 2021: 9.81 m/s2): the reference of the
/// values that are scaled with gravity (stop speed, rolling threshold).
inline constexpr double kEarthGravity_m_s2 = 9.81;
inline constexpr double kInf = std::numeric_limits<double>::infinity();
/// Small-number guard used by Chrono for |delta_t| and contact-circle radii
/// (docs/physics/contact-laws.md sections 1.4, 1.5).
inline constexpr double kTinyLength_m = 1e-12;

/// Mass of a solid sphere, rho pi d^3 / 6.
inline double sphere_mass_kg(double density_kg_m3, double diameter_m) {
  return density_kg_m3 * kPi / 6 * diameter_m * diameter_m * diameter_m;
}

/// Appends a Vec3 as the three values of one row of a row-major (N, 3) column held flat.
inline void push_xyz(std::vector<double>& column, const Vec3& v) {
  for (int k = 0; k < 3; ++k) column.push_back(v[k]);
}

/// Index of a particle inside Particles (structure of arrays).
using ParticleIndex = std::uint32_t;

}  // namespace gravsweep
