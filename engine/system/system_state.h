// The dynamic state of a running System, as a plain struct: everything its next steps read
// besides the configuration and the walls. System::save_state() fills it between two steps;
// System::restore_state() puts it into a System made with the same configuration and walls, and
// the run continues bit for bit as if it had never stopped (same thread count). The engine
// writes no file: results/io/checkpoint_file.h stores this struct in HDF5.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/contact/contact.h"
#include "engine/core/particles.h"
#include "engine/core/types.h"

namespace gravsweep {

/// Axis-aligned region; a particle centre outside it is a numerical failure ("left the container").
struct Domain {
  Vec3 lo_m, hi_m;
};

/// Where the threads' time in the force region goes, summed over the regions run while a
/// System::set_region_timing target is set (`gravsweep bench`): the region's wall time, the
/// thread-seconds of work in it (pair and wall loops, then the sums and the end of step), and the
/// team size. 1 - busy_s / (threads * wall_s) is the share spent waiting (for a block of the sums
/// that another thread's loops still hold, and at the region's end) and forking the team.
struct RegionTiming {
  double wall_s = 0;
  double busy_s = 0;
  double pair_barrier_wait_s = 0;  ///< thread-seconds waiting after the pair and wall loops for a ready block
  /// Seconds of the pair and wall loops per thread (the first kTimedThreads): which one waits.
  static constexpr int kTimedThreads = 8;
  std::array<double, kTimedThreads> pair_loops_s{};
  int threads = 0;
  long long regions = 0;
  [[nodiscard]] double wait_share() const { return wall_s > 0 ? 1 - busy_s / (threads * wall_s) : 0; }
};

/// Per-step counters from the force evaluation.
struct StepStats {
  long long contacts = 0;       ///< touching particle-particle pairs
  long long wall_contacts = 0;  ///< touching particle-wall pairs
  double elastic_energy_J = 0;  ///< sum of normal spring energies (track_energy only)
};

struct SystemState {
  /// Every particle array, forces and torques of the last evaluation included (the velocity
  /// Verlet and leapfrog integrators start a step from them), and the predicted velocities.
  Particles particles;
  double time_s = 0;
  long long step = 0;
  /// Configuration a run may change between steps: gravity (System::set_gravity), the domain (a
  /// drop raises its top) and the Verlet skin (0 in a config: chosen at the first initialize()).
  Vec3 gravity_m_s2 = Vec3::Zero();
  std::optional<Domain> domain;
  double skin_m = 0;

  // The neighbour list as its last build left it (engine/neighbor/verlet_list.h): CSR rows,
  // the pair histories beside the pairs, the work prefix that splits the rows between threads,
  // the positions of that build (they decide the next rebuild) and the build count.
  std::vector<std::uint32_t> list_offset, list_neighbor, list_work_offset;
  std::vector<ContactHistory> pair_history;
  std::vector<FrameHistory> pair_frame_history;  ///< empty unless the law keeps frame histories
  std::vector<Vec3> position_at_build_m;
  long long list_builds = 0;

  // Particle-wall candidates (codes particle * walls + wall) with their histories.
  std::vector<std::uint32_t> wall_candidates;
  std::vector<ContactHistory> wall_history;
  std::vector<FrameHistory> wall_frame_history;
  std::uint64_t wall_count_at_build = 0;

  // What the next step must still do (System's private flags).
  bool initialized = false;       ///< false: the next step re-initialises (particles were removed)
  bool rebuild_due = true;        ///< a particle moved more than skin/2: rebuild before the forces
  bool have_step_checks = false;  ///< the last step measured every displacement
  bool have_forces = false;       ///< force_N / torque_N_m hold the forces on the current state
  StepStats stats;                ///< counters of the last force evaluation
};

}  // namespace gravsweep
