#include "engine/scenario/impact.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "engine/core/error.h"

namespace gravsweep {

bool DropSamples::consistent() const {
  const std::size_t n = size();
  return depth_m.size() == n && velocity_down_m_s.size() == n && accel_up_m_s2.size() == n &&
         omega_rad_s.size() == 3 * n && position_m.size() == 3 * n && contacts.size() == n &&
         grain_kinetic_energy_J.size() == n;
}

void DropSamples::reserve(std::size_t n) {
  for (auto* c : {&t_s, &depth_m, &velocity_down_m_s, &accel_up_m_s2, &grain_kinetic_energy_J}) c->reserve(n);
  omega_rad_s.reserve(3 * n);
  position_m.reserve(3 * n);
  contacts.reserve(n);
}

void DropSamples::resize(std::size_t n) {
  for (auto* c : {&t_s, &depth_m, &velocity_down_m_s, &accel_up_m_s2, &grain_kinetic_energy_J}) c->resize(n);
  omega_rad_s.resize(3 * n);
  position_m.resize(3 * n);
  contacts.resize(n);
}

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
      // Centred above the rim (the wall acts only on centres within its height, geometry/walls.h),
      // beyond the wall's radius less its own, moving outward: nothing keeps it in the container.
      if (along_m <= top_m || radial.norm() <= w.radius_m - r || p.velocity_m_s[i].dot(radial) <= 0) continue;
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

namespace {

/// Checks the projectile and puts it at its start (at rest at the drop height, or start_gap_m
/// above the first grain it would meet with the speed that free fall turns into the impact
/// speed); fills the release facts of `res` and returns the projectile's index.
ParticleIndex release_projectile(System& sys, double surface_height_m, const ProjectileSpec& ps, DropResult& res) {
  if (ps.impact_speed_m_s.has_value() == ps.drop_height_m.has_value())
    throw ConfigError("projectile: give exactly one of impact_speed_m_s and drop_height_m");
  if (!(ps.diameter_m > 0) || !(ps.mass_kg > 0)) throw ConfigError("projectile: diameter_m and mass_kg must be > 0");
  const double g = -sys.config().gravity_m_s2.z();  // > 0: downward gravity
  const double R = 0.5 * ps.diameter_m;
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
  const ParticleIndex ip = sys.particles.add(centre, R, ps.mass_kg, ps.material, SizeClass::projectile);
  sys.particles.set_velocity(ip, Vec3(0, 0, -v0));
  sys.invalidate();
  sys.initialize();
  res.projectile = ip;
  return ip;
}

/// One drop from its release (or a checkpoint) to the stop criterion or the time cap.
class DropRun {
 public:
  DropRun(System& sys, const ProjectileSpec& ps, const DropStop& stop, double sample_rate_hz,
          const DropProgress& progress, const DropSnapshots& snapshots, const DropCheckpoints& checkpoints,
          const AdaptiveStep& time_step)
      : sys_(sys),
        ps_(ps),
        stop_(stop),
        progress_(progress),
        snapshots_(snapshots),
        checkpoints_(checkpoints),
        time_step_(time_step),
        dt_floor_s_(sys.config().dt_s) {
    if (!(sample_rate_hz > 0)) throw ConfigError("drop: sample_rate_hz must be > 0");
    const double dt = sys.config().dt_s;
    check_adaptive_step(time_step, dt, "drop");
    if (adaptive()) {
      sample_dt_ = 1.0 / sample_rate_hz;  // the grid; the steps fill each interval
    } else {
      steps_per_sample_ = std::max<long long>(1, std::llround(1.0 / (sample_rate_hz * dt)));
      sample_dt_ = static_cast<double>(steps_per_sample_) * dt;
    }
    hold_samples_ = std::max<long long>(1, std::llround(stop.hold_time_s / sample_dt_));
    max_samples_ = static_cast<long long>(std::ceil(stop.max_time_s / sample_dt_));
    // Snapshots every snapshot_every_ samples (0: off), the last one at the end of the run.
    const bool snap = snapshots.interval_s > 0 && snapshots.write;
    snapshot_every_ = snap ? std::max<long long>(1, std::llround(snapshots.interval_s / sample_dt_)) : 0;
  }

  /// The release: the projectile placed, sample 0 (the force at release: free fall unless
  /// something already touches) and the first snapshot.
  void release(double surface_height_m) {
    release_projectile(sys_, surface_height_m, ps_, st_.result);
    st_.release_time_s = sys_.time_s();
    st_.release_step = sys_.step_count();
    sys_.compute_forces();
    sample(sys_.particles.force_N[st_.result.projectile].z() / ps_.mass_kg);
    snapshot(0);
  }

  /// Continues a saved drop (DropCheckpoints::resume).
  void resume(const DropState& saved) {
    const Particles& p = saved.system.particles;
    const ParticleIndex ip = saved.loop.result.projectile;
    if (ip >= p.size() || ip >= p.size_class.size() || p.size_class[ip] != SizeClass::projectile ||
        saved.loop.result.samples.empty() || !saved.loop.result.samples.consistent() ||
        saved.loop.samples_done + 1 != static_cast<long long>(saved.loop.result.samples.size()))
      throw std::invalid_argument(fmt::format(
          "drop state cannot be continued: particle {} of {} is not the projectile, or its {} samples are not "
          "the {} taken in every column",
          ip, p.size(), saved.loop.result.samples.size(), saved.loop.samples_done + 1));
    sys_.restore_state(saved.system);
    st_ = saved.loop;
  }

  DropResult run();

 private:
  System& sys_;
  const ProjectileSpec& ps_;
  const DropStop& stop_;
  const DropProgress& progress_;
  const DropSnapshots& snapshots_;
  const DropCheckpoints& checkpoints_;
  const AdaptiveStep& time_step_;
  double dt_floor_s_ = 0;  ///< the System's configured step: the adaptive step's floor
  long long steps_per_sample_ = 1, hold_samples_ = 1, max_samples_ = 0, snapshot_every_ = 0;
  double sample_dt_ = 0;
  DropLoopState st_;

  /// Appends the projectile's state now as one sample to every column of the record.
  void sample(double accel_up) {
    const auto& p = sys_.particles;
    const ParticleIndex ip = st_.result.projectile;
    DropSamples& c = st_.result.samples;
    c.t_s.push_back(sys_.time_s() - st_.release_time_s);
    c.depth_m.push_back(st_.result.surface_height_m - (p.position_m[ip].z() - 0.5 * ps_.diameter_m));
    c.velocity_down_m_s.push_back(-p.velocity_m_s[ip].z());
    c.accel_up_m_s2.push_back(accel_up);
    push_xyz(c.omega_rad_s, p.omega_rad_s[ip]);
    push_xyz(c.position_m, p.position_m[ip]);
    c.contacts.push_back(sys_.contact_count(ip));
    c.grain_kinetic_energy_J.push_back(grain_kinetic_energy_J(sys_));
  }

  void snapshot(long long k) {
    if (snapshot_every_ == 0 || k == st_.last_snapshot) return;
    snapshots_.write(sys_, st_.result.projectile, sys_.time_s() - st_.release_time_s);
    st_.last_snapshot = k;
  }

  bool adaptive() const { return time_step_.on(); }

  /// With the adaptive step: sets the step for the next sample interval (AdaptiveStep).
  void choose_step() {
    if (adaptive()) steps_per_sample_ = gravsweep::choose_step(sys_, time_step_, dt_floor_s_, sample_dt_);
  }

  /// Advances one sample interval and records it; true when the stop criterion ends the drop.
  bool next_sample(long long k);
};

bool DropRun::next_sample(long long k) {
  DropResult& res = st_.result;
  const double vz_before = sys_.particles.velocity_m_s[res.projectile].z();
  choose_step();
  sys_.advance(steps_per_sample_);
  res.grains_spilled += remove_spilled_grains(sys_, res.projectile);
  const double vz_after = sys_.particles.velocity_m_s[res.projectile].z();
  sample((vz_after - vz_before) / sample_dt_);
  const double t_s = res.samples.t_s.back();
  st_.samples_done = k;
  if (snapshot_every_ > 0 && k % snapshot_every_ == 0) snapshot(k);
  if (res.samples.contacts.back() > 0 && !res.first_contact_s) res.first_contact_s = t_s;
  if (res.first_contact_s) {
    const double speed = sys_.particles.velocity_m_s[res.projectile].norm();
    st_.below_stop = speed < stop_.speed_m_s ? st_.below_stop + 1 : 0;
    if (st_.below_stop >= hold_samples_) {
      res.stopped = true;
      res.rest_s = t_s - static_cast<double>(hold_samples_ - 1) * sample_dt_;
      return true;
    }
  }
  // Between two samples the loop's state is whole: a checkpoint may be taken here.
  if (checkpoints_.save && checkpoints_.due && checkpoints_.due()) checkpoints_.save(sys_, st_);
  if (progress_ && k % 50 == 0)
    progress_(static_cast<double>(k) / static_cast<double>(max_samples_),
              fmt::format("t={:.4f}s of {:.4g}s cap step={} dt={:.3g}s depth={:.2f}cm v={:.3f}m/s contacts={}", t_s,
                          static_cast<double>(max_samples_) * sample_dt_, sys_.step_count(), sys_.config().dt_s,
                          100 * res.samples.depth_m.back(), res.samples.velocity_down_m_s.back(),
                          res.samples.contacts.back()));
  return false;
}

DropResult DropRun::run() {
  const AdaptiveStepScope step_scope(sys_);  // the System leaves the drop at its configured step
  st_.result.samples.reserve(static_cast<std::size_t>(std::min<long long>(max_samples_ + 2, 1 << 22)));
  for (long long k = st_.samples_done + 1; k <= max_samples_; ++k)
    if (next_sample(k)) break;
  snapshot(st_.samples_done);
  st_.result.steps = sys_.step_count() - st_.release_step;
  if (progress_) progress_(1.0, st_.result.stopped ? "projectile at rest" : "time cap reached");
  return std::move(st_.result);
}

}  // namespace

DropResult drop_projectile(System& sys, double surface_height_m, const ProjectileSpec& ps, const DropStop& stop,
                           double sample_rate_hz, const DropProgress& progress, const DropSnapshots& snapshots,
                           const DropCheckpoints& checkpoints, const AdaptiveStep& time_step) {
  DropRun run(sys, ps, stop, sample_rate_hz, progress, snapshots, checkpoints, time_step);
  if (checkpoints.resume != nullptr)
    run.resume(*checkpoints.resume);
  else
    run.release(surface_height_m);
  return run.run();
}

}  // namespace gravsweep
