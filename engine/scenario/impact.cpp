#include "engine/scenario/impact.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"

namespace gravsweep {

double grain_kinetic_energy_J(const System& sys) {
  const auto& p = sys.particles;
  double e = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.size_class[i] != SizeClass::grain || p.inv_mass_1_kg[i] == 0) continue;
    e += 0.5 * p.mass_kg[i] * p.velocity_m_s[i].squaredNorm() +
         0.5 / p.inv_inertia_1_kg_m2[i] * p.omega_rad_s[i].squaredNorm();
  }
  return e;
}

std::size_t remove_spilled_grains(System& sys, ParticleIndex& projectile) {
  const auto& p = sys.particles;
  std::vector<bool> spilled;
  std::size_t n = 0, before_projectile = 0;
  for (const Wall& w : sys.walls) {
    if (w.kind != WallKind::cylinder || !std::isfinite(w.height_m)) continue;
    const Vec3 axis = w.normal.normalized();
    const double top_m = w.height_m;  // along the axis, from point_m
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p.size_class[i] != SizeClass::grain || p.inv_mass_1_kg[i] == 0) continue;
      const Vec3 rel = p.position_m[i] - w.point_m;
      const double along_m = rel.dot(axis);
      const Vec3 radial = rel - along_m * axis;
      const double r = p.radius_m[i];
      // Wholly above the rim, beyond the wall's radius less its own, moving outward.
      if (along_m - r <= top_m || radial.norm() <= w.radius_m - r || p.velocity_m_s[i].dot(radial) <= 0) continue;
      if (spilled.empty()) spilled.assign(p.size(), false);
      if (spilled[i]) continue;
      spilled[i] = true;
      ++n;
      if (i < projectile) ++before_projectile;
    }
  }
  if (n == 0) return 0;
  sys.remove_particles(spilled);  // keeps the order and the contact histories of the others
  projectile -= static_cast<ParticleIndex>(before_projectile);
  return n;
}

std::optional<FirstTouch> first_touch_bottom(const System& sys, double x_m, double y_m, double radius_m) {
  const auto& p = sys.particles;
  std::optional<FirstTouch> best;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.size_class[i] != SizeClass::grain) continue;
    const double dx = p.position_m[i].x() - x_m, dy = p.position_m[i].y() - y_m;
    const double reach = radius_m + p.radius_m[i];
    const double d2 = dx * dx + dy * dy;
    if (d2 >= reach * reach) continue;
    // Centre height at which the falling sphere touches grain i: |c - x_i| = R + r_i.
    const double bottom = p.position_m[i].z() + std::sqrt(reach * reach - d2) - radius_m;
    if (!best || bottom > best->bottom_height_m) best = FirstTouch{bottom, static_cast<ParticleIndex>(i)};
  }
  return best;
}

DropResult drop_projectile(System& sys, double surface_height_m, const ProjectileSpec& ps, const DropStop& stop,
                           double sample_rate_hz, const DropProgress& progress, const DropSnapshots& snapshots) {
  if (ps.impact_speed_m_s.has_value() == ps.drop_height_m.has_value())
    throw ConfigError("projectile: give exactly one of impact_speed_m_s and drop_height_m");
  if (!(ps.diameter_m > 0) || !(ps.mass_kg > 0)) throw ConfigError("projectile: diameter_m and mass_kg must be > 0");
  if (!(sample_rate_hz > 0)) throw ConfigError("drop: sample_rate_hz must be > 0");
  const double dt = sys.config().dt_s;
  const double g = -sys.config().gravity_m_s2.z();  // > 0: downward gravity
  const double R = 0.5 * ps.diameter_m;

  DropResult res;
  res.surface_height_m = surface_height_m;
  double v0 = 0;  // downward speed at release
  double bottom = 0;
  // The grain the projectile meets first, falling straight down at its lateral offset: the start
  // gap is measured from there, not from the mean surface (a grain standing proud of the mean
  // surface would otherwise be inside the projectile at release).
  const std::optional<FirstTouch> touch = first_touch_bottom(sys, ps.lateral_offset_x_m, ps.lateral_offset_y_m, R);
  const double touch_bottom = touch ? touch->bottom_height_m : surface_height_m;
  res.first_touch_height_m = touch_bottom;
  if (ps.impact_speed_m_s) {
    const double gap = ps.start_gap_m + ps.vertical_offset_m;
    const double v2 = (*ps.impact_speed_m_s) * (*ps.impact_speed_m_s) - 2 * g * gap;
    if (v2 < 0)
      throw ConfigError(
          fmt::format("projectile: impact speed {} m/s cannot be reached from a start {} m above the surface "
                      "at g = {} m/s2 (free fall alone gives more); lower start_gap_m or the vertical offset",
                      *ps.impact_speed_m_s, gap, g));
    v0 = std::sqrt(v2);
    bottom = touch_bottom + gap;
  } else {
    bottom = surface_height_m + *ps.drop_height_m + ps.vertical_offset_m;
  }
  if (touch && bottom < touch_bottom)
    throw ConfigError(
        fmt::format("projectile: at release (bottom at z = {:.4f} m, lateral offset ({:.4f}, {:.4f}) m) it would "
                    "overlap grain {} whose top under the projectile reaches z = {:.4f} m ({:.2f} mm above the "
                    "mean surface); start it higher (drop_height_m, start_gap_m or the vertical offset)",
                    bottom, ps.lateral_offset_x_m, ps.lateral_offset_y_m, touch->grain, touch_bottom,
                    1e3 * (touch_bottom - surface_height_m)));
  res.release_height_m = bottom;
  res.release_speed_m_s = v0;
  const Vec3 centre(ps.lateral_offset_x_m, ps.lateral_offset_y_m, bottom + R);

  // The domain must hold the projectile: extend its top above the release point.
  {
    SystemConfig& cfg = sys.mutable_config();
    if (cfg.domain) cfg.domain->hi_m.z() = std::max(cfg.domain->hi_m.z(), centre.z() + 2 * R);
  }
  ParticleIndex ip = sys.particles.add(centre, R, ps.mass_kg, ps.material, SizeClass::projectile);
  sys.particles.set_velocity(ip, Vec3(0, 0, -v0));
  sys.invalidate();
  sys.initialize();
  res.projectile = ip;

  const long long steps_per_sample = std::max<long long>(1, std::llround(1.0 / (sample_rate_hz * dt)));
  const double sample_dt = static_cast<double>(steps_per_sample) * dt;
  const long long hold_samples = std::max<long long>(1, std::llround(stop.hold_time_s / sample_dt));
  const long long max_samples = static_cast<long long>(std::ceil(stop.max_time_s / sample_dt));
  const double t0 = sys.time_s();
  const long long step0 = sys.step_count();

  auto sample = [&](double accel_up) {
    const auto& p = sys.particles;
    DropSample s;
    s.t_s = sys.time_s() - t0;
    s.position_m = p.position_m[ip];
    s.depth_m = surface_height_m - (p.position_m[ip].z() - R);
    s.velocity_down_m_s = -p.velocity_m_s[ip].z();
    s.accel_up_m_s2 = accel_up;
    s.omega_rad_s = p.omega_rad_s[ip];
    s.contacts = sys.contact_count(ip);
    s.grain_kinetic_energy_J = grain_kinetic_energy_J(sys);
    res.samples.push_back(s);
    return s;
  };

  // Snapshots every snapshot_every samples (0: off), the last one at the end of the run.
  const bool snap = snapshots.interval_s > 0 && snapshots.write;
  const long long snapshot_every = snap ? std::max<long long>(1, std::llround(snapshots.interval_s / sample_dt)) : 0;
  long long last_snapshot = -1;
  auto snapshot = [&](long long k) {
    if (!snap || k == last_snapshot) return;
    snapshots.write(sys, ip, sys.time_s() - t0);
    last_snapshot = k;
  };

  // Sample 0: the force at release (free fall unless something already touches).
  sys.compute_forces();
  sample(sys.particles.force_N[ip].z() / ps.mass_kg);
  snapshot(0);
  long long k_done = 0;
  res.samples.reserve(static_cast<std::size_t>(std::min<long long>(max_samples + 2, 1 << 22)));
  long long below = 0;
  for (long long k = 1; k <= max_samples; ++k) {
    const double vz_before = sys.particles.velocity_m_s[ip].z();
    sys.advance(steps_per_sample);
    res.grains_spilled += remove_spilled_grains(sys, ip);
    res.projectile = ip;
    const double vz_after = sys.particles.velocity_m_s[ip].z();
    const DropSample s = sample((vz_after - vz_before) / sample_dt);
    k_done = k;
    if (snap && k % snapshot_every == 0) snapshot(k);
    if (s.contacts > 0 && !res.first_contact_s) res.first_contact_s = s.t_s;
    if (res.first_contact_s) {
      const double speed = sys.particles.velocity_m_s[ip].norm();
      below = speed < stop.speed_m_s ? below + 1 : 0;
      if (below >= hold_samples) {
        res.stopped = true;
        res.rest_s = s.t_s - static_cast<double>(hold_samples - 1) * sample_dt;
        break;
      }
    }
    if (progress && k % 50 == 0)
      progress(static_cast<double>(k) / static_cast<double>(max_samples),
               fmt::format("t={:.4f}s depth={:.2f}cm v={:.3f}m/s contacts={}", s.t_s, 100 * s.depth_m,
                           s.velocity_down_m_s, s.contacts));
  }
  snapshot(k_done);
  res.steps = sys.step_count() - step0;
  if (progress) progress(1.0, res.stopped ? "projectile at rest" : "time cap reached");
  return res;
}

}  // namespace gravsweep
