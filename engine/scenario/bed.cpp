#include "engine/scenario/bed.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "engine/core/error.h"

namespace gravsweep {

const char* to_string(BedPhase p) {
  switch (p) {
    case BedPhase::fill:
      return "fill";
    case BedPhase::settle:
      return "settle";
    case BedPhase::flatten:
      return "flatten";
    case BedPhase::relax:
      return "relax";
  }
  return "?";
}

void add_container_walls(System& sys, const ContainerSpec& c, double height_m, std::uint8_t wall_material) {
  const double R = 0.5 * c.diameter_m;
  sys.walls.push_back(Wall::disk("bottom", Vec3::Zero(), Vec3::UnitZ(), R, wall_material));
  sys.walls.push_back(Wall::cylinder("side", Vec3::Zero(), Vec3::UnitZ(), R, height_m, wall_material));
  // A particle centre outside this box is a numerical failure ("left the container"): the
  // cylinder's width, 5 % of its radius below the floor, ten container radii above the wall's top.
  sys.mutable_config().domain = Domain{Vec3(-R, -R, -0.05 * R), Vec3(R, R, height_m + 10 * R)};
}

void add_lid(System& sys, const ContainerSpec& c, double height_m, std::uint8_t wall_material) {
  sys.walls.push_back(
      Wall::disk(kLidWallName, Vec3(0, 0, height_m), -Vec3::UnitZ(), 0.5 * c.diameter_m, wall_material));
  sys.invalidate();
}

void remove_lid(System& sys) {
  const auto n = std::erase_if(sys.walls, [](const Wall& w) { return w.name == kLidWallName; });
  if (n > 0) sys.invalidate();
}

std::size_t place_grains(System& sys, const BedSpec& spec) {
  const auto& g = spec.grains;
  const double R_c = 0.5 * spec.container.diameter_m;
  const double d_max = g.diameter_m + 2 * g.diameter_spread_m;
  const double grain_volume = kPi / 6 * std::pow(g.diameter_m, 3);
  const double bed_volume = kPi * R_c * R_c * spec.fill_height_m;
  const auto target =
      static_cast<std::size_t>(std::ceil(spec.overfill_factor * spec.packing_fraction * bed_volume / grain_volume));
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  const double spacing = spec.placement_spacing_diameters * d_max;
  const double jitter = 0.5 * (spacing - d_max) * 0.9;
  // Triangular lattice in each layer, layers offset; stop when the target count is reached.
  const double row = spacing * std::sqrt(3.0) / 2;
  const double r_free = R_c - 0.5 * d_max - 1e-4;
  std::size_t placed = 0;
  for (int layer = 0; placed < target; ++layer) {
    const double z = 0.5 * d_max + 1e-4 + layer * spacing;
    const double shift = (layer % 2) * 0.5 * spacing;
    const int n_rows = static_cast<int>(std::ceil(2 * r_free / row)) + 1;
    for (int r = -n_rows / 2; r <= n_rows / 2 && placed < target; ++r) {
      const double y = r * row;
      const double x0 = (r % 2 != 0 ? 0.5 * spacing : 0.0) + shift;
      const int n_cols = static_cast<int>(std::ceil(2 * r_free / spacing)) + 2;
      for (int c = -n_cols / 2; c <= n_cols / 2 && placed < target; ++c) {
        Vec3 pos(x0 + c * spacing + jitter * uni(rng), y + jitter * uni(rng), z + jitter * uni(rng));
        if (std::hypot(pos.x(), pos.y()) > r_free) continue;
        const double diameter = g.diameter_m + g.diameter_spread_m * uni(rng);
        const double radius = 0.5 * diameter;
        const ParticleIndex i = sys.particles.add(pos, radius, sphere_mass_kg(g.density_kg_m3, diameter),
                                                  spec.grain_material, SizeClass::grain);
        // Small random velocities mix the pour (paper: "mix and settle").
        sys.particles.velocity_m_s[i] = 0.05 * Vec3(uni(rng), uni(rng), uni(rng));
        ++placed;
      }
    }
  }
  sys.invalidate();
  return placed;
}

double core_packing_fraction(const Particles& p, double core_radius_m, double z_lo_m, double z_hi_m) {
  double v_m3 = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.size_class[i] != SizeClass::grain) continue;
    const Vec3& x = p.position_m[i];
    if (std::hypot(x.x(), x.y()) >= core_radius_m) continue;
    const double r = p.radius_m[i];
    // Volume of the sphere between a and b (relative to its centre): pi (r^2 u - u^3 / 3) from a to b.
    const double a = std::clamp(z_lo_m - x.z(), -r, r), b = std::clamp(z_hi_m - x.z(), -r, r);
    auto F = [r](double u) { return r * r * u - u * u * u / 3; };
    v_m3 += kPi * (F(b) - F(a));
  }
  return v_m3 / (kPi * core_radius_m * core_radius_m * (z_hi_m - z_lo_m));
}

void grain_speeds(const System& sys, double& rms_m_s, double& max_m_s) {
  double sum2 = 0, mx2 = 0;
  std::size_t n = 0;
  const auto& p = sys.particles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.size_class[i] != SizeClass::grain || p.inv_mass_1_kg[i] == 0) continue;
    const double v2 = p.velocity_m_s[i].squaredNorm();
    sum2 += v2;
    mx2 = std::max(mx2, v2);
    ++n;
  }
  rms_m_s = n > 0 ? std::sqrt(sum2 / static_cast<double>(n)) : 0.0;
  max_m_s = std::sqrt(mx2);
}

BedRestState bed_rest_state(const System& sys, double surface_height_m, double grain_diameter_m,
                            const SurfaceWindow& window) {
  BedRestState r;
  const auto& p = sys.particles;
  const double layer_bottom_m = surface_height_m - kSurfaceLayerDiameters * grain_diameter_m;
  double sum2_m2_s2 = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.size_class[i] != SizeClass::grain || p.inv_mass_1_kg[i] == 0) continue;
    if (std::hypot(p.position_m[i].x() - window.x_m, p.position_m[i].y() - window.y_m) > window.radius_m) continue;
    const double speed_m_s = p.velocity_m_s[i].norm();
    sum2_m2_s2 += speed_m_s * speed_m_s;
    r.max_speed_m_s = std::max(r.max_speed_m_s, speed_m_s);
    ++n;
    if (p.position_m[i].z() < layer_bottom_m) continue;
    r.max_surface_speed_m_s = std::max(r.max_surface_speed_m_s, speed_m_s);
    ++r.surface_grains;
  }
  r.rms_speed_m_s = n > 0 ? std::sqrt(sum2_m2_s2 / static_cast<double>(n)) : 0.0;
  return r;
}

const char* to_string(SettleEnd e) {
  switch (e) {
    case SettleEnd::criteria:
      return "criteria";
    case SettleEnd::plateau:
      return "plateau";
    case SettleEnd::time_cap:
      return "time_cap";
  }
  return "?";
}

SettleEnd settle(System& sys, const SettleCriteria& c, double min_time_s, const BedProgress& progress, BedPhase phase,
                 double* rms_out, double* max_out, const AdaptiveStep& step, StageCursor* cursor,
                 const IntervalHook& after) {
  const double dt = sys.config().dt_s;  // the adaptive step's floor, and the step after this phase
  const AdaptiveStepScope step_scope(sys);
  // The settling threshold of rolling friction holds for this phase only (SettleCriteria).
  struct ThresholdScope {
    System& sys;
    double kept_m_s;
    ThresholdScope(System& s, double v) : sys(s), kept_m_s(s.config().options.min_roll_vel_m_s) {
      sys.mutable_config().options.min_roll_vel_m_s = v;
    }
    ~ThresholdScope() { sys.mutable_config().options.min_roll_vel_m_s = kept_m_s; }
  } threshold(sys, c.min_roll_vel_m_s);
  const auto check_steps = std::max<long long>(1, std::llround(c.check_interval_s / dt));
  StageCursor local;
  StageCursor& at = cursor != nullptr ? *cursor : local;
  if (at.intervals == 0) at = StageCursor{0, sys.time_s()};
  double rms = 0, mx = 0;
  SettleEnd end = SettleEnd::time_cap;
  // A minimum time above the cap wins: the phase runs at least min_time_s (BedSpec::relax_time_s).
  const double cap_s = std::max(c.max_time_s, min_time_s);
  while (sys.time_s() - at.start_s < cap_s) {
    sys.advance(step.on() ? choose_step(sys, step, dt, c.check_interval_s) : check_steps);
    ++at.intervals;
    grain_speeds(sys, rms, mx);
    const double elapsed = sys.time_s() - at.start_s;
    bool ended = false;
    if (elapsed >= min_time_s && rms < c.rms_speed_m_s && mx < c.max_speed_m_s) {
      end = SettleEnd::criteria;
      ended = true;
    } else if (rms >= c.max_speed_m_s) {  // not quiet yet (pour, avalanche of the whole bed): no floor
      at.low_m_s = kInf;
    } else if (rms < kPlateauNewLow * at.low_m_s) {
      // Creep floor: the lowest RMS speed since the bed became quiet, and when it was last lowered.
      at.low_m_s = rms;
      at.low_at_s = elapsed;
    } else if (c.plateau_window_s > 0 && elapsed >= min_time_s && elapsed - at.low_at_s >= c.plateau_window_s &&
               rms < at.low_m_s / kPlateauNewLow) {  // at the floor now, not in a burst above it
      end = SettleEnd::plateau;
      ended = true;
    }
    if (!ended && after && elapsed < cap_s) after(at);
    if (progress) {
      // Progress: the larger of the time fraction and how close the RMS speed is to its target
      // on a log scale (settling is roughly exponential).
      const double speed_frac = rms > 0 ? std::clamp(1.0 - std::log10(rms / c.rms_speed_m_s) / 4.0, 0.0, 1.0) : 1.0;
      progress(phase, std::max(elapsed / cap_s, speed_frac),
               fmt::format("t={:.3f}s rms={:.2e}m/s max={:.2e}m/s", elapsed, rms, mx));
    }
    if (ended) break;
  }
  if (rms_out) *rms_out = rms;
  if (max_out) *max_out = mx;
  return end;
}

void stop_grains(System& sys) {
  auto& p = sys.particles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.size_class[i] != SizeClass::grain || p.inv_mass_1_kg[i] == 0) continue;
    // Power of the force (gravity included) and of the torque of the last step: negative when the
    // grain moves or spins against them, past the bottom of its potential well.
    if (p.force_N[i].dot(p.velocity_m_s[i]) < 0) p.velocity_m_s[i].setZero();
    if (p.torque_N_m[i].dot(p.omega_rad_s[i]) < 0) p.omega_rad_s[i].setZero();
  }
}

namespace {

/// The cursor a loop runs on: the caller's, or a fresh one; a cursor at 0 intervals starts now.
StageCursor& cursor_or(StageCursor* cursor, StageCursor& local, const System& sys) {
  StageCursor& at = cursor != nullptr ? *cursor : local;
  if (at.intervals == 0) at = StageCursor{0, sys.time_s()};
  return at;
}

/// `total` steps in chunks of `chunk`, from the cursor on: `before(k)` ahead of chunk k (the ramp's
/// gravity), `after(k)` behind it (the quench), then the hook (every chunk but the last: the state
/// it sees is complete), then `report(k)` (progress, which may throw on a stop request: after the
/// hook, so that a stop is saved first).
template <class Before, class After, class Report>
void run_chunks(System& sys, long long total, long long chunk, StageCursor& at, const IntervalHook& hook,
                const Before& before, const After& after, const Report& report) {
  for (long long k = at.intervals * chunk; k < total; k += chunk) {
    before(k);
    sys.advance(std::min(chunk, total - k));
    ++at.intervals;
    after(k);
    if (hook && k + chunk < total) hook(at);
    report(k);
  }
}

}  // namespace

void quench(System& sys, double time_s, double interval_s, const BedProgress& progress, const AdaptiveStep& step,
            StageCursor* cursor, const IntervalHook& after) {
  const double dt = sys.config().dt_s;
  StageCursor local;
  StageCursor& at = cursor_or(cursor, local, sys);
  const auto report = [&](double done_s) {
    if (progress) progress(BedPhase::relax, done_s / time_s, fmt::format("quench: {:.3f} of {:.3f} s", done_s, time_s));
  };
  if (step.on()) {
    const AdaptiveStepScope step_scope(sys);
    const auto intervals = std::max<long long>(1, std::llround(time_s / interval_s));
    for (long long k = at.intervals; k < intervals; ++k) {
      sys.advance(choose_step(sys, step, dt, interval_s));
      stop_grains(sys);
      ++at.intervals;
      if (after && k + 1 < intervals) after(at);
      report(static_cast<double>(k + 1) * interval_s);
    }
    return;
  }
  const long long chunk = std::max<long long>(1, std::llround(interval_s / dt));
  const auto steps = static_cast<long long>(std::llround(time_s / dt));
  run_chunks(
      sys, steps, chunk, at, after, [](long long) {}, [&](long long) { stop_grains(sys); },
      [&](long long k) { report(static_cast<double>(k) * dt); });
}

void run_for(System& sys, double time_s, double interval_s, const BedProgress& progress, StageCursor* cursor,
             const IntervalHook& after) {
  const double dt = sys.config().dt_s;
  StageCursor local;
  StageCursor& at = cursor_or(cursor, local, sys);
  const long long chunk = std::max<long long>(1, std::llround(interval_s / dt));
  const auto steps = static_cast<long long>(std::llround(time_s / dt));
  run_chunks(
      sys, steps, chunk, at, after, [](long long) {}, [](long long) {},
      [&](long long k) {
        if (progress)
          progress(BedPhase::relax, static_cast<double>(std::min(k + chunk, steps)) / static_cast<double>(steps),
                   fmt::format("surface relax: {:.3f} of {:.3f} s", static_cast<double>(k + chunk) * dt, time_s));
      });
}

void ramp_gravity(System& sys, const Vec3& to_m_s2, double ramp_s, double interval_s, const BedProgress& progress,
                  bool quench_grains, StageCursor* cursor, const IntervalHook& after) {
  const Vec3 g0 = sys.config().gravity_m_s2;
  StageCursor local;
  StageCursor& at = cursor_or(cursor, local, sys);
  const double dt = sys.config().dt_s;
  const auto steps = static_cast<long long>(std::llround(ramp_s / dt));
  const long long chunk = std::max<long long>(1, std::llround(interval_s / dt));
  // The ramp runs from the gravity at its start (kept with the cursor: a resumed ramp is on its way).
  if (at.intervals == 0) at.from_m_s2 = g0.norm();
  const double n0 = at.from_m_s2, n1 = to_m_s2.norm();
  const bool same_direction = n0 > 0 && n1 > 0 && g0.dot(to_m_s2) > (1 - 1e-12) * g0.norm() * n1;
  if (steps > 0 && same_direction) {
    run_chunks(
        sys, steps, chunk, at, after,
        [&](long long k) {
          const double f = static_cast<double>(k) / static_cast<double>(steps);
          sys.set_gravity(to_m_s2 / n1 * (n0 * std::pow(n1 / n0, f)));  // geometric: equal ratios per step
        },
        [&](long long) {
          if (quench_grains) stop_grains(sys);
        },
        [&](long long) {
          if (progress)
            progress(BedPhase::relax, 0.0, fmt::format("gravity ramp: {:.3g} m/s2", sys.config().gravity_m_s2.norm()));
        });
  }
  sys.set_gravity(to_m_s2);
}

double surface_height(const System& sys, double container_radius_m) {
  // Mean top height of the grains within 60 % of the container radius that stand highest in
  // their column: bin the central disk on a grid of ~1.5 grain diameters and average bin maxima.
  const auto& p = sys.particles;
  double d = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.size_class[i] == SizeClass::grain) {
      d += 2 * p.radius_m[i];
      ++n;
    }
  if (n == 0) return 0;
  d /= static_cast<double>(n);
  const double reach = 0.6 * container_radius_m;
  const double bin = 1.5 * d;
  const int nb = static_cast<int>(std::ceil(2 * reach / bin));
  std::vector<double> top(static_cast<std::size_t>(nb * nb), -kInf);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.size_class[i] != SizeClass::grain) continue;
    const Vec3& x = p.position_m[i];
    if (std::hypot(x.x(), x.y()) > reach) continue;
    const int bx = std::clamp(static_cast<int>((x.x() + reach) / bin), 0, nb - 1);
    const int by = std::clamp(static_cast<int>((x.y() + reach) / bin), 0, nb - 1);
    double& t = top[static_cast<std::size_t>(by * nb + bx)];
    t = std::max(t, x.z() + p.radius_m[i]);
  }
  double sum = 0;
  std::size_t cnt = 0;
  for (double t : top)
    if (std::isfinite(t)) {
      sum += t;
      ++cnt;
    }
  return cnt > 0 ? sum / static_cast<double>(cnt) : 0.0;
}

}  // namespace gravsweep
