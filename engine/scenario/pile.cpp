#include "engine/scenario/pile.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "engine/core/error.h"

namespace gravsweep {

namespace {

/// The fixed base: grains of the mean size on a triangular lattice at contact spacing, centres
/// jittered by 10 % of a diameter sideways and 30 % of a radius in height (a rough surface
/// without holes). Returns the height of the base's top.
double add_rough_base(System& sys, const PileSpec& spec, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double d = spec.grains.diameter_m, r = 0.5 * d;
  const double mass = sphere_mass_kg(spec.grains.density_kg_m3, d);
  const double row = d * std::sqrt(3.0) / 2;
  const int n = static_cast<int>(std::ceil(spec.base_radius_m / row)) + 1;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) {
      const double x = i * d + (j % 2 != 0 ? 0.5 * d : 0.0), y = j * row;
      if (std::hypot(x, y) > spec.base_radius_m) continue;
      const Vec3 pos(x + 0.1 * d * u(rng), y + 0.1 * d * u(rng), r + 0.3 * r * u(rng));
      sys.particles.add(pos, r, mass, spec.grain_material, SizeClass::grain, /*fixed=*/true);
    }
  return 2.3 * r;  // highest possible top of a base grain
}

/// Removes the free grains that fell off the base; returns how many.
std::size_t remove_fallen(System& sys) {
  std::vector<bool> fallen(sys.particles.size(), false);
  std::size_t n = 0;
  for (std::size_t i = 0; i < fallen.size(); ++i)
    if (sys.particles.inv_mass_1_kg[i] > 0 && sys.particles.position_m[i].z() < 0) {
      fallen[i] = true;
      ++n;
    }
  if (n > 0) sys.remove_particles(fallen);
  return n;
}

}  // namespace

PileResult measure_pile(const System& sys, double base_top_m, double base_radius_m) {
  const auto& p = sys.particles;
  PileResult res;
  double d = 0;
  std::size_t n_free = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.inv_mass_1_kg[i] > 0 && p.position_m[i].z() > 0) {
      d += 2 * p.radius_m[i];
      ++n_free;
    }
  res.grains_on_base = n_free;
  if (n_free == 0) return res;
  d /= static_cast<double>(n_free);
  const double bin = 1.5 * d;
  const int nb = static_cast<int>(std::ceil(2 * base_radius_m / bin));
  std::vector<double> top(static_cast<std::size_t>(nb * nb), -kInf);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.inv_mass_1_kg[i] == 0 || p.position_m[i].z() <= 0) continue;
    const Vec3& x = p.position_m[i];
    const int bx = static_cast<int>(std::floor((x.x() + base_radius_m) / bin));
    const int by = static_cast<int>(std::floor((x.y() + base_radius_m) / bin));
    if (bx < 0 || by < 0 || bx >= nb || by >= nb) continue;
    double& t = top[static_cast<std::size_t>(by * nb + bx)];
    t = std::max(t, x.z() + p.radius_m[i] - base_top_m);
  }
  for (double t : top) res.apex_height_m = std::max(res.apex_height_m, t);
  // Least squares h = a + b r over the flank bins.
  double sr = 0, sh = 0, srr = 0, srh = 0;
  std::size_t m = 0;
  for (int by = 0; by < nb; ++by)
    for (int bx = 0; bx < nb; ++bx) {
      const double h = top[static_cast<std::size_t>(by * nb + bx)];
      if (!(h >= 0.2 * res.apex_height_m && h <= 0.8 * res.apex_height_m)) continue;
      const double r = std::hypot(-base_radius_m + (bx + 0.5) * bin, -base_radius_m + (by + 0.5) * bin);
      if (r > base_radius_m - bin) continue;
      sr += r, sh += h, srr += r * r, srh += r * h;
      ++m;
    }
  res.flank_bins = m;
  const double den = static_cast<double>(m) * srr - sr * sr;
  if (m >= 3 && den > 0) {
    const double slope = (static_cast<double>(m) * srh - sr * sh) / den;
    res.angle_deg = std::atan(-slope) * 180.0 / kPi;
  }
  double rms = 0, mx = 0;
  grain_speeds(sys, rms, mx);
  res.rms_speed_m_s = rms;
  return res;
}

PileResult pour_pile(System& sys, const PileSpec& spec, const PileProgress& progress) {
  if (!sys.particles.position_m.empty() || !sys.walls.empty()) throw ConfigError("pile: the system must start empty");
  if (!(spec.base_radius_m > 2 * spec.grains.diameter_m) || !(spec.outlet_radius_m > 0) ||
      !(spec.pour_rate_per_s > 0) || spec.grains_poured == 0)
    throw ConfigError(
        "pile: base_radius_m > 2 grain diameters, outlet_radius_m, pour_rate_per_s and "
        "grains_poured must be positive");
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double base_top = add_rough_base(sys, spec, rng);
  const double R = spec.base_radius_m;
  // Grains leaving the base fly off at up to ~1 m/s; they are removed once below the base (z < 0).
  const double reach = 2 * R + 0.5;
  sys.mutable_config().domain = Domain{Vec3(-reach, -reach, -0.5), Vec3(reach, reach, reach + 1.0)};
  sys.invalidate();
  const double dt = sys.config().dt_s;
  const double d = spec.grains.diameter_m;
  const auto chunk = std::max<long long>(1, std::llround(5e-4 / dt));  // release every 0.5 ms
  std::size_t poured = 0;
  double owed = 0;
  const double t0 = sys.time_s();
  while (poured < spec.grains_poured) {
    sys.advance(chunk);
    remove_fallen(sys);
    owed = std::min(owed + spec.pour_rate_per_s * static_cast<double>(chunk) * dt, 5.0);
    if (owed < 1) continue;
    // Outlet height: release_gap_m above the resting grains below it (falling ones ignored).
    double top = base_top;
    const auto& p = sys.particles;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Vec3& x = p.position_m[i];
      if (p.velocity_m_s[i].norm() < 0.05 && std::hypot(x.x(), x.y()) < spec.outlet_radius_m + d)
        top = std::max(top, x.z() + p.radius_m[i]);
    }
    std::size_t released = 0;
    for (int attempt = 0; attempt < 20 && released < static_cast<std::size_t>(owed) && poured < spec.grains_poured;
         ++attempt) {
      const double rr = spec.outlet_radius_m * std::sqrt(0.5 * (u(rng) + 1)), phi = kPi * u(rng);
      const double dia = d + spec.grains.diameter_spread_m * u(rng);
      const Vec3 x(rr * std::cos(phi), rr * std::sin(phi), top + spec.release_gap_m + d * (u(rng) + 1));
      bool free = true;
      for (std::size_t i = 0; i < p.size() && free; ++i)
        free = (p.position_m[i] - x).norm() > 0.5 * dia + p.radius_m[i] + 1e-4;
      if (!free) continue;
      const ParticleIndex k = sys.particles.add(x, 0.5 * dia, sphere_mass_kg(spec.grains.density_kg_m3, dia),
                                                spec.grain_material, SizeClass::grain);
      sys.particles.set_velocity(k, Vec3(0, 0, -spec.release_speed_m_s));
      ++released;
      ++poured;
    }
    if (released > 0) sys.particles_appended();
    owed -= static_cast<double>(released);
    if (progress)
      progress(0.8 * static_cast<double>(poured) / static_cast<double>(spec.grains_poured),
               fmt::format("pour: {} of {} grains", poured, spec.grains_poured));
  }
  // Settle, removing what rolls off.
  const auto settle_chunk = std::max<long long>(1, std::llround(0.02 / dt));
  double rms = 0, mx = 0;
  const double t_pour = sys.time_s();
  while (sys.time_s() - t_pour < spec.max_settle_time_s) {
    sys.advance(settle_chunk);
    remove_fallen(sys);
    grain_speeds(sys, rms, mx);
    if (progress)
      progress(0.8 + 0.2 * (sys.time_s() - t_pour) / spec.max_settle_time_s,
               fmt::format("settle: rms {:.1e} m/s", rms));
    if (rms < spec.settle_rms_speed_m_s && mx < spec.settle_max_speed_m_s) break;
  }
  PileResult res = measure_pile(sys, base_top, R);
  res.simulated_time_s = sys.time_s() - t0;
  return res;
}

}  // namespace gravsweep
