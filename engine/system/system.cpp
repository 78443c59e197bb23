#include "engine/system/system.h"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <cmath>

#include "engine/system/law_registry.h"
#include "engine/core/error.h"
#include "engine/system/force_loop.h"

namespace gravsweep {

System::System(SystemConfig config) : config_(std::move(config)) {}
System::~System() = default;

int System::threads() const {
  if (particles.size() < config_.parallel_min_particles) return 1;
  return config_.threads > 0 ? config_.threads : omp_get_max_threads();
}

void System::invalidate() {
  initialized_ = false;
  rebuild_due_ = true;
  have_step_checks_ = false;
  have_forces_ = false;
  nlist_.clear();
  wall_candidates_.clear();
  wall_history_.clear();
  wall_frame_history_.clear();
}

void System::particles_appended() {
  nlist_.extend(particles.size());
  // Wall candidate codes (particle * walls + wall) of the existing particles are unchanged.
  initialized_ = false;  // thread buffers follow the new size
  rebuild_due_ = true;
  have_step_checks_ = false;
  have_forces_ = false;
}

void System::remove_particles(const std::vector<bool>& remove) {
  const std::size_t n = particles.size();
  std::vector<long long> new_index(n, -1);
  long long next = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!remove[i]) new_index[i] = next++;
  nlist_.remap(new_index);
  // Renumber the wall candidates; the order is kept because new indices are monotone.
  const std::size_t nw = wall_count_at_build_;
  std::size_t kept = 0;
  const bool frames = !wall_frame_history_.empty();
  for (std::size_t k = 0; k < wall_candidates_.size(); ++k) {
    const std::size_t i = wall_candidates_[k] / nw, w = wall_candidates_[k] % nw;
    if (i >= n || new_index[i] < 0) continue;
    wall_candidates_[kept] = static_cast<std::uint32_t>(static_cast<std::size_t>(new_index[i]) * nw + w);
    wall_history_[kept] = wall_history_[k];
    if (frames) wall_frame_history_[kept] = wall_frame_history_[k];
    ++kept;
  }
  wall_candidates_.resize(kept);
  wall_history_.resize(kept);
  if (frames) wall_frame_history_.resize(kept);
  particles.remove_if(remove);
  initialized_ = false;  // thread buffers and checks follow the new size; histories are kept
  rebuild_due_ = true;   // wall candidates are rebuilt (their histories carried over)
  have_step_checks_ = false;
}

void System::initialize() {
  const std::size_t nm = config_.materials.size();
  if (nm == 0) throw ConfigError("system: no materials defined");
  if (!(config_.dt_s > 0)) throw ConfigError(fmt::format("system: dt_s = {} must be > 0", config_.dt_s));
  for (const auto& m : config_.materials) validate_material(m);
  // Pair table.
  pairs_ = PairTable(nm);
  for (std::size_t a = 0; a < nm; ++a)
    for (std::size_t b = a; b < nm; ++b) {
      const PairOverride* ov = nullptr;
      if (config_.composition == Composition::explicit_pair) {
        auto it = config_.pair_overrides.find({static_cast<int>(a), static_cast<int>(b)});
        if (it != config_.pair_overrides.end()) ov = &it->second;
      }
      const PairCoefficients pc = compose_pair(config_.materials[a], config_.materials[b], ov);
      auto bad = [&](const char* f, double v, const char* e) {
        throw ConfigError(fmt::format("pair {}-{}: {} = {} is invalid; expected {}", config_.materials[a].name,
                                      config_.materials[b].name, f, v, e));
      };
      if (!(pc.cor_normal > 0 && pc.cor_normal <= 1)) bad("cor_normal", pc.cor_normal, "COR in (0, 1]");
      if (!(pc.cor_tangential > 0 && pc.cor_tangential <= 1)) bad("cor_tangential", pc.cor_tangential, "COR in (0, 1]");
      if (!(pc.mu_static >= 0)) bad("mu_static", pc.mu_static, ">= 0");
      pairs_.set(a, b, pc);
    }
  // Per-material extremes for the law's checks.
  auto& min_r = material_min_radius_m_;
  auto& min_m = material_min_mass_kg_;
  auto& is_wall = material_is_wall_;
  min_r.assign(nm, 0);
  min_m.assign(nm, 0);
  is_wall.assign(nm, false);
  for (const auto& w : walls) {
    if (w.material >= nm)
      throw ConfigError(fmt::format("wall '{}': material id {} is not defined", w.name, w.material));
    is_wall[w.material] = true;
  }
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const auto m = particles.material[i];
    if (m >= nm) throw ConfigError(fmt::format("particle {}: material id {} is not defined", i, m));
    if (!(particles.radius_m[i] > 0) || !(particles.mass_kg[i] > 0))
      throw ConfigError(fmt::format("particle {}: radius {} m and mass {} kg must be > 0", i, particles.radius_m[i],
                                    particles.mass_kg[i]));
    min_r[m] = min_r[m] == 0 ? particles.radius_m[i] : std::min(min_r[m], particles.radius_m[i]);
    min_m[m] = min_m[m] == 0 ? particles.mass_kg[i] : std::min(min_m[m], particles.mass_kg[i]);
    is_wall[m] = false;  // a material used by particles is checked as a particle material
  }
  check_contact_law(config_.contact_law,
                    LawSetup{config_.materials, pairs_, min_r, min_m, is_wall,
                             adaptive_step_ ? fixed_dt_s_ : config_.dt_s, config_.check_time_step});
  force_fn_ = select_force_function(config_.contact_law, config_.rolling_model);
  prepare_contact_law(config_.contact_law, pairs_);
  integrator_ = make_integrator(config_.integrator);

  if (config_.skin_m <= 0) {
    double rmin = kInf;
    for (double r : particles.radius_m) rmin = std::min(rmin, r);
    config_.skin_m = std::isfinite(rmin) ? 0.2 * rmin : 1e-3;
  }
  const int nt = threads();
  // Thread 0 writes into particles.force_N / torque_N_m: buffers for the other threads only.
  thread_force_.assign(nt, {});
  thread_torque_.assign(nt, {});
  for (int t = 1; t < nt; ++t) {
    thread_force_[t].assign(particles.size(), Vec3::Zero());
    thread_torque_[t].assign(particles.size(), Vec3::Zero());
  }
  const bool frames = uses_frame_history(config_.contact_law, config_.rolling_model);
  if (nlist_.offset.size() != particles.size() + 1) nlist_.clear();
  nlist_.set_frame_history(frames);
  nlist_.work = config_.pair_work;
  if (wall_count_at_build_ != walls.size() || wall_history_.size() != wall_candidates_.size()) {
    wall_candidates_.clear();  // walls changed without invalidate(): their histories end
    wall_history_.clear();
  }
  wall_frame_history_.resize(frames ? wall_history_.size() : 0);
  initialized_ = true;
  rebuild_neighbors();
}

void System::rebuild_neighbors() {
  nlist_.build(particles, config_.skin_m, threads());
  const std::size_t nw = walls.size();
  std::vector<std::uint32_t> cand;
  cand.reserve(wall_candidates_.size() + 16);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (particles.inv_mass_1_kg[i] == 0) continue;
    for (std::size_t w = 0; w < nw; ++w) {
      const double reach = particles.radius_m[i] + config_.skin_m;
      WallTouch touch;
      // A wall is a candidate when the particle, grown by the skin, touches it.
      if (touch_wall(walls[w], particles.position_m[i], reach, touch))
        cand.push_back(static_cast<std::uint32_t>(i * nw + w));
    }
  }
  // Carry the histories of pairs still within reach over (both code lists are increasing); the
  // others end now (they cannot be touching).
  const bool frames = nlist_.keeps_frame_history();
  std::vector<ContactHistory> hist(cand.size());
  std::vector<FrameHistory> frame(frames ? cand.size() : 0);
  if (wall_count_at_build_ == nw) {
    std::size_t a = 0;
    for (std::size_t b = 0; b < cand.size() && a < wall_candidates_.size(); ++b) {
      while (a < wall_candidates_.size() && wall_candidates_[a] < cand[b]) ++a;
      if (a < wall_candidates_.size() && wall_candidates_[a] == cand[b]) {
        hist[b] = wall_history_[a];
        if (frames && a < wall_frame_history_.size()) frame[b] = wall_frame_history_[a];
      }
    }
  }
  wall_candidates_ = std::move(cand);
  wall_history_ = std::move(hist);
  wall_frame_history_ = std::move(frame);
  wall_count_at_build_ = nw;
  nlist_.add_wall_work(wall_candidates_, nw);
  rebuild_due_ = false;
}

void System::compute_forces() { force_pass(false, nullptr); }

void System::force_pass(bool displacement_checked, StepCheck* finish) {
  if (!initialized_) initialize();
  // Inside step() the previous end-of-step checks measured the displacements; otherwise (a call
  // from outside, positions possibly edited) measure them now.
  if (rebuild_due_ || (!displacement_checked && nlist_.needs_rebuild(particles))) rebuild_neighbors();
  // The end of step compares with the positions of this (possibly just rebuilt) list.
  if (finish != nullptr) finish->position_at_build = nlist_.positions_at_build(particles.size());
  ForceContext ctx{particles,
                   walls,
                   nlist_,
                   wall_history_,
                   wall_frame_history_,
                   wall_candidates_,
                   pairs_,
                   config_.options,
                   thread_force_,
                   thread_torque_,
                   config_.gravity_m_s2,
                   config_.dt_s,
                   integrator_->uses_eval_velocities() && have_forces_,
                   config_.track_energy,
                   threads(),
                   config_.pair_filter_min_pairs,
                   finish != nullptr ? integrator_.get() : nullptr,
                   finish,
                   region_timing_};
  force_fn_(ctx);
  stats_ = ctx.stats;
  have_forces_ = true;
  if (const OverlapFailure& f = ctx.failure; f.failed()) {
    const std::string other = f.wall >= 0 ? fmt::format("wall '{}'", walls[static_cast<std::size_t>(f.wall)].name)
                                          : fmt::format("particle {}", f.other);
    throw NumericalFailure(fmt::format("step {} (t = {:.6g} s): particle {} overlaps {} by {:.0f} % of the smaller "
                                       "radius (limit {:.0f} %): the time step is too large or the contact too soft",
                                       step_, time_s_, f.particle, other, 100 * f.ratio, 100 * kMaxOverlapFraction),
                           step_, f.particle);
  }
}

void System::raise_state_failure(long long bad, StateFault cause) {
  const Vec3& x = particles.position_m[bad];
  if (cause == StateFault::non_finite)
    throw NumericalFailure(fmt::format("step {} (t = {:.6g} s): particle {} has a non-finite "
                                       "position or velocity (NaN/inf)",
                                       step_, time_s_, bad),
                           step_, bad);
  throw NumericalFailure(fmt::format("step {} (t = {:.6g} s): particle {} left the container: position ({:.4g}, "
                                     "{:.4g}, {:.4g}) m is outside the domain",
                                     step_, time_s_, bad, x.x(), x.y(), x.z()),
                         step_, bad);
}

double System::shortest_contact_time_s(double v_rel_m_s) {
  if (!initialized_) initialize();
  return gravsweep::shortest_contact_time_s(
      config_.contact_law,
      LawSetup{config_.materials, pairs_, material_min_radius_m_, material_min_mass_kg_, material_is_wall_,
               config_.dt_s, config_.check_time_step},
      v_rel_m_s);
}

double System::max_particle_speed_m_s() const {
  double v2 = 0;
  for (const Vec3& v : particles.velocity_m_s) v2 = std::max(v2, v.squaredNorm());
  return std::sqrt(v2);
}

double System::max_approach_speed_m_s(double interval_s) const {
  const double v_fast_m_s = max_particle_speed_m_s();
  if (!initialized_ || rebuild_due_ || wall_count_at_build_ != walls.size())
    return 2 * v_fast_m_s;  // the list is not the one the next step uses
  // A list built for other particles gives an infinite displacement.
  if (std::sqrt(nlist_.max_displacement2_m2(particles)) + 2 * v_fast_m_s * interval_s >= 0.5 * config_.skin_m)
    return 2 * v_fast_m_s;
  const std::size_t n = particles.size();
  const Vec3* X = particles.position_m.data();
  const Vec3* V = particles.velocity_m_s.data();
  const double* R = particles.radius_m.data();
  const std::uint32_t* off = nlist_.offset.data();
  const std::uint32_t* nbr = nlist_.neighbor.data();
  double v_m_s = 0;  // a maximum: the same for any thread count (about 0.6 % of a 0.01 m/s2 drop)
  const int nt = n >= config_.parallel_min_particles ? threads() : 1;
#pragma omp parallel for reduction(max : v_m_s) schedule(static) num_threads(nt)
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t k = off[i]; k < off[i + 1]; ++k) {
      const std::uint32_t j = nbr[k];
      const Vec3 d = X[j] - X[i];
      const Vec3 dv = V[j] - V[i];
      const double dist = d.norm();
      if (!(dist > 0)) {  // coincident centres: no normal, so the whole relative speed
        v_m_s = std::max(v_m_s, dv.norm());
        continue;
      }
      const double closing = -dv.dot(d) / dist;  // > 0: approaching
      v_m_s = std::max(v_m_s, dist < R[i] + R[j] ? std::abs(closing) : closing);
    }
  if (!walls.empty())
    for (const std::uint32_t code : wall_candidates_) v_m_s = std::max(v_m_s, V[code / walls.size()].norm());
  return v_m_s;
}

void System::step() {
  if (!initialized_) initialize();
  const double dt = config_.dt_s;
  omp_set_num_threads(threads());  // integrators use the default team size
  if (integrator_->needs_initial_forces() && !have_forces_) compute_forces();
  integrator_->begin_step(particles, dt);
  StepCheck check;
  if (config_.domain) {
    check.have_domain = true;
    check.lo_m = config_.domain->lo_m;
    check.hi_m = config_.domain->hi_m;
  }
  force_pass(have_step_checks_, &check);  // forces, then the integrator's end of step on them
  ++step_;
  time_s_ += dt;
  if (check.found.bad_particle >= 0) raise_state_failure(check.found.bad_particle, check.found.bad_cause);
  if (check.position_at_build == nullptr || check.found.max_displacement2_m2 > 0.25 * config_.skin_m * config_.skin_m)
    rebuild_due_ = true;
  have_step_checks_ = true;
}

void System::advance(long long steps) {
  for (long long s = 0; s < steps; ++s) step();
}

double System::kinetic_energy_J() const {
  double e = 0;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (particles.inv_mass_1_kg[i] == 0) continue;
    e += 0.5 * particles.mass_kg[i] * particles.velocity_m_s[i].squaredNorm();
    e += 0.5 / particles.inv_inertia_1_kg_m2[i] * particles.omega_rad_s[i].squaredNorm();
  }
  return e;
}

double System::potential_energy_J() const {
  double e = 0;
  for (std::size_t i = 0; i < particles.size(); ++i)
    if (particles.inv_mass_1_kg[i] > 0) e -= particles.mass_kg[i] * config_.gravity_m_s2.dot(particles.position_m[i]);
  return e;
}

int System::contact_count(ParticleIndex i) const {
  int count = 0;
  const std::size_t n = particles.size();
  if (nlist_.offset.size() != n + 1) return 0;  // no list yet: no contact was evaluated
  // Row i holds the pairs with larger partners; the others are listed under their partner's row.
  // One pass over the partners (called at every trace sample: O(pairs), no per-row loop).
  for (std::uint32_t k = nlist_.offset[i]; k < nlist_.offset[i + 1]; ++k) count += nlist_.history[k].active;
  const std::uint32_t* nbr = nlist_.neighbor.data();
  const std::size_t below = nlist_.offset[i];  // rows before i end here
  for (std::size_t k = 0; k < below; ++k)
    if (nbr[k] == i && nlist_.history[k].active) ++count;
  const std::size_t nw = wall_count_at_build_;
  const auto first =
      std::lower_bound(wall_candidates_.begin(), wall_candidates_.end(), static_cast<std::uint32_t>(i * nw));
  for (auto it = first; it != wall_candidates_.end() && *it < (i + 1) * nw; ++it)
    if (wall_history_[static_cast<std::size_t>(it - wall_candidates_.begin())].active) ++count;
  return count;
}

std::vector<int> System::contact_counts() const {
  const std::size_t n = particles.size();
  std::vector<int> count(n, 0);
  for (std::size_t a = 0; a + 1 < nlist_.offset.size() && a < n; ++a)
    for (std::uint32_t k = nlist_.offset[a]; k < nlist_.offset[a + 1]; ++k)
      if (nlist_.history[k].active) ++count[a], ++count[nlist_.neighbor[k]];
  const std::size_t nw = std::max<std::size_t>(1, wall_count_at_build_);
  for (std::size_t c = 0; c < wall_candidates_.size(); ++c)
    if (wall_history_[c].active && wall_candidates_[c] / nw < n) ++count[wall_candidates_[c] / nw];
  return count;
}

double System::bytes_per_particle() const {
  const std::size_t n = std::max<std::size_t>(1, particles.size());
  const std::size_t per_particle_state =
      7 * sizeof(Vec3) + 4 * sizeof(double) + sizeof(std::uint8_t) + sizeof(SizeClass);
  std::size_t bytes =
      particles.size() * per_particle_state + nlist_.bytes() + wall_candidates_.capacity() * sizeof(std::uint32_t) +
      wall_history_.capacity() * sizeof(ContactHistory) + wall_frame_history_.capacity() * sizeof(FrameHistory);
  for (const auto& v : thread_force_) bytes += v.capacity() * sizeof(Vec3);
  for (const auto& v : thread_torque_) bytes += v.capacity() * sizeof(Vec3);
  return static_cast<double>(bytes) / static_cast<double>(n);
}

}  // namespace gravsweep
