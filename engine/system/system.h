// The DEM system: particles, walls, the selected contact law, rolling model and integrator, and
// the neighbour list. It knows nothing of files or databases.
#pragma once
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/contact/contact.h"
#include "engine/core/material.h"
#include "engine/core/particles.h"
#include "engine/geometry/walls.h"
#include "engine/integrate/integrators.h"
#include "engine/neighbor/verlet_list.h"
#include "engine/system/force_function.h"
#include "engine/system/system_state.h"

namespace gravsweep {

struct SystemConfig {
  std::string contact_law = "hertz";               ///< see contact_law_names() (system/law_registry.h)
  std::string rolling_model = "sunday";            ///< see rolling_model_names() (system/law_registry.h)
  std::string integrator = "semi_implicit_euler";  ///< see integrator_table()
  double dt_s = 1e-6;
  Vec3 gravity_m_s2 = Vec3(0, 0, -9.81);
  std::vector<Material> materials;  ///< indexed by material id
  Composition composition = Composition::explicit_pair;
  /// explicit_pair overrides, keyed by (material a, material b) with a <= b.
  std::map<std::pair<int, int>, PairOverride> pair_overrides;
  ContactOptions options;
  double skin_m = 0;  ///< Verlet skin; 0 = 0.2 x smallest radius
  int threads = 0;    ///< OpenMP threads; 0 = OpenMP default
  /// Systems smaller than this run on one thread (thread start-up costs more than it saves).
  std::size_t parallel_min_particles = 512;
  /// Listed pairs of a thread's share from which the pair loop filters touching pairs without a
  /// branch before it visits them (force_loop.h, kFilterMinPairs); results are the same either way.
  std::uint32_t pair_filter_min_pairs = kFilterMinPairs;
  /// The work model the pair loop's rows are split between threads by (verlet_list.h).
  PairWork pair_work{};
  std::optional<Domain> domain;
  bool track_energy = false;    ///< accumulate the normal spring energy
  bool check_time_step = true;  ///< reject dt above the law's stability bound
};

class System {
 public:
  explicit System(SystemConfig config);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  Particles particles;
  std::vector<Wall> walls;

  /// Validates parameters, builds the pair table and the neighbour list. Called by step() when
  /// needed; call it after changing particles, walls or config (or use invalidate()).
  void initialize();
  /// Marks particle indices as changed (after adding particles, moving particles by hand or
  /// changing walls): contact histories are dropped.
  void invalidate();
  /// Call after appending particles with particles.add() (a pour): the indices of the others are
  /// unchanged, so their contact histories are kept; the neighbour list is rebuilt at the next step.
  void particles_appended();
  /// Removes the flagged particles, keeping the order and the contact histories of the others.
  void remove_particles(const std::vector<bool>& remove);

  void step();
  void advance(long long steps);

  /// The dynamic state between two steps (system_state.h): a checkpoint of the run.
  [[nodiscard]] SystemState save_state() const;
  /// Continues the run saved by save_state(): this System must have the configuration and the
  /// walls of the saved one (its particles are replaced). The next steps are bit-identical to
  /// those of the saved run for the same thread count. Throws std::invalid_argument naming the
  /// first inconsistency (array sizes, wall count, frame histories the law does not keep); the
  /// state is checked before anything is replaced, so a refused state changes nothing.
  void restore_state(SystemState state);

  [[nodiscard]] double time_s() const { return time_s_; }
  [[nodiscard]] long long step_count() const { return step_; }
  [[nodiscard]] const SystemConfig& config() const { return config_; }
  SystemConfig& mutable_config() {
    initialized_ = false;
    return config_;
  }
  /// Changes gravity between steps without re-initialising (gravity enters only the force sum).
  void set_gravity(const Vec3& g_m_s2) { config_.gravity_m_s2 = g_m_s2; }
  /// Changes the time step between steps without re-initialising (an adaptive step, bounded by
  /// its caller). The contact law's step check keeps testing the step configured before the first
  /// change (a re-initialisation mid-run, after grains are removed, must not hold a grown step
  /// against the fixed-step bound) until end_adaptive_step() puts that step back.
  void set_dt_s(double dt_s) {
    if (!adaptive_step_) fixed_dt_s_ = config_.dt_s;
    adaptive_step_ = true;
    config_.dt_s = dt_s;
  }
  /// Back to the step configured before set_dt_s (no-op when the step was never changed).
  void end_adaptive_step() {
    if (adaptive_step_) config_.dt_s = fixed_dt_s_;
    adaptive_step_ = false;
  }
  /// The contact law's shortest contact time over the pairs present at relative normal speed
  /// v_rel_m_s (contact registry, shortest_contact_time_s), initialising first if needed.
  [[nodiscard]] double shortest_contact_time_s(double v_rel_m_s);
  /// Fastest particle speed (walls do not move).
  [[nodiscard]] double max_particle_speed_m_s() const;
  /// A bound of the relative normal speed (m/s) of every pair that can touch within the next
  /// interval_s, from the contacts actually present: the largest approach speed -(v_j - v_i) . n
  /// over the listed pairs (|(v_j - v_i) . n| for a pair that touches), and the speed of each
  /// particle within reach of a wall. Only listed pairs can touch before the list is rebuilt; when
  /// a rebuild could come within the interval (the largest displacement since the last build plus
  /// twice the fastest speed times interval_s reaches half the skin), or no list is built, it is
  /// twice the fastest particle's speed instead (max_particle_speed_m_s).
  [[nodiscard]] double max_approach_speed_m_s(double interval_s) const;
  [[nodiscard]] const StepStats& stats() const { return stats_; }
  /// Adds the force regions' timing to *timing from now on (nullptr: stops; the default). For
  /// benchmarks: two clock reads per thread and region.
  void set_region_timing(RegionTiming* timing) { region_timing_ = timing; }
  [[nodiscard]] const PairTable& pair_table() const { return pairs_; }
  [[nodiscard]] const VerletList& neighbor_list() const { return nlist_; }
  [[nodiscard]] int threads() const;

  /// Translational + rotational kinetic energy.
  [[nodiscard]] double kinetic_energy_J() const;
  /// Gravitational potential energy -m g.x, relative to the origin.
  [[nodiscard]] double potential_energy_J() const;
  /// Number of contacts of particle i at the last force evaluation (walls included).
  [[nodiscard]] int contact_count(ParticleIndex i) const;
  /// The same for every particle at once, in one pass over the pairs (grain snapshots).
  [[nodiscard]] std::vector<int> contact_counts() const;
  /// Approximate memory held per particle by the engine (state + neighbour list + histories).
  [[nodiscard]] double bytes_per_particle() const;

  /// Evaluates forces on the current state without advancing (used by integrators and tests).
  void compute_forces();

 private:
  SystemConfig config_;
  PairTable pairs_;
  /// Per material: smallest particle radius and mass (0: no particle), whether only walls use it.
  std::vector<double> material_min_radius_m_, material_min_mass_kg_;
  std::vector<bool> material_is_wall_;
  VerletList nlist_;
  std::unique_ptr<Integrator> integrator_;
  ForceFunction force_fn_ = nullptr;
  std::vector<std::vector<Vec3>> thread_force_, thread_torque_;
  std::vector<int> contact_count_;
  StepStats stats_;
  RegionTiming* region_timing_ = nullptr;
  double time_s_ = 0;
  long long step_ = 0;
  bool initialized_ = false;
  bool adaptive_step_ = false;  ///< set_dt_s changed the step; fixed_dt_s_ is the configured one
  double fixed_dt_s_ = 0;
  bool have_forces_ = false;

  /// Particle-wall pairs within reach (radius + skin) of the wall at the last list build; only
  /// these are tested each step. Encoded as particle * walls + wall, in increasing order; the
  /// contact histories of these pairs are stored beside them (sparse: a grain away from every
  /// wall holds none) and carried over, by code, when the candidates are rebuilt.
  std::vector<std::uint32_t> wall_candidates_;
  std::vector<ContactHistory> wall_history_;      ///< [candidate]
  std::vector<FrameHistory> wall_frame_history_;  ///< [candidate], when frame histories are kept
  std::size_t wall_count_at_build_ = 0;           ///< walls.size() the codes were made with
  bool rebuild_due_ = true;                       ///< set by the step checks when a particle moved more than skin/2
  /// The last step's end checks measured every displacement. Particles edited between steps
  /// (positions, walls) must be followed by invalidate() or compute_forces().
  bool have_step_checks_ = false;
  /// Forces on the current state; with `finish`, the integrator's end of step follows in the same
  /// parallel region, checked against `finish` (inside step()).
  void force_pass(bool displacement_checked, StepCheck* finish);
  void rebuild_neighbors();
  void check_restorable(const SystemState& s) const;
  void raise_state_failure(long long particle, StateFault cause);
};

}  // namespace gravsweep
