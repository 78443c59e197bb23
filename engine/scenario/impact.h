// The drop of the projectile into a prepared bed (Sunday et al. 2021 Sect. 2.2): the projectile
// starts at a set height above the bed surface (at rest, "drop height"), or just above it with the
// requested impact speed, and the run stops when the projectile's speed stays below the stop speed
// after contact (paper: 0.1 cm/s). The projectile is recorded at a fixed sample rate (paper,
// Chrono: 10 kHz). Engine frame: z up, bottom disk at z = 0; the trace uses the paper's frame.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/scenario/time_step.h"
#include "engine/system/system.h"

namespace gravsweep {

struct ProjectileSpec {
  double diameter_m = 0.10;   ///< paper: 10 cm
  double mass_kg = 1.0;       ///< paper: 1 kg
  std::uint8_t material = 2;  ///< kProjectileMaterial
  /// Exactly one of the two: speed when the projectile first touches a grain (it starts
  /// start_gap_m above the highest grain under its footprint, with the velocity that free fall
  /// turns into this speed at the touch), or the height of the bottom above the mean surface for
  /// a release from rest. Either way a start that would overlap a grain is refused.
  std::optional<double> impact_speed_m_s;
  std::optional<double> drop_height_m;
  double start_gap_m = 0.005;     ///< impact-speed mode: gap between the projectile's bottom
                                  ///< and the first grain it would touch, at release
  double lateral_offset_x_m = 0;  ///< start offset from the container axis (already drawn)
  double lateral_offset_y_m = 0;
  double vertical_offset_m = 0;  ///< added to the start height (already drawn)
};

struct DropStop {
  double speed_m_s = 1e-3;     ///< paper: projectile speed < 0.1 cm/s after contact
  double hold_time_s = 0.005;  ///< the speed must stay below for this long (guards
                               ///< against stopping at the turning point of a bounce)
  double max_time_s = 1.0;     ///< cap on simulated time after release
};

/// The projectile's record during a drop, a column per quantity and a value per output sample
/// (paper frame: z positive down from the bed surface, velocity positive down, acceleration
/// positive up so that free fall reads -g). DropRun::sample appends each sample here once, and
/// the trace record (results::TraceData) takes the columns over by move: the values the engine
/// writes are the trace's own, never copied into another form.
struct DropSamples {
  std::vector<double> t_s;      ///< time since release
  std::vector<double> depth_m;  ///< depth of the projectile's lowest point below the mean surface
  std::vector<double> velocity_down_m_s;
  std::vector<double> accel_up_m_s2;           ///< mean over the preceding sample interval (dv/dt), so the
                                               ///< 10 kHz record is not aliased by the us-scale contact force
  std::vector<double> omega_rad_s;             ///< T x 3: projectile's angular velocity (engine frame)
  std::vector<double> position_m;              ///< T x 3: projectile centre (engine frame)
  std::vector<std::int32_t> contacts;          ///< particles and walls touching the projectile
  std::vector<double> grain_kinetic_energy_J;  ///< translational + rotational kinetic energy of the grains

  [[nodiscard]] std::size_t size() const { return t_s.size(); }
  [[nodiscard]] bool empty() const { return t_s.empty(); }
  /// Every column holds size() samples (the (T, 3) ones 3 size() values).
  [[nodiscard]] bool consistent() const;
  /// Room for n samples in every column.
  void reserve(std::size_t n);
  /// Every column cut or extended (with zeros) to n samples.
  void resize(std::size_t n);
};

struct DropResult {
  DropSamples samples;
  double surface_height_m = 0;      ///< engine z of the mean bed surface (depth 0)
  double release_height_m = 0;      ///< engine z of the projectile's bottom at release
  double release_speed_m_s = 0;     ///< downward speed at release
  double first_touch_height_m = 0;  ///< engine z of the projectile's bottom where it would first
                                    ///< touch a grain falling straight down (mean surface if none)
  std::optional<double> first_contact_s;
  bool stopped = false;          ///< stop criterion met (false: the time cap ended the run)
  std::optional<double> rest_s;  ///< start of the hold window that met the stop criterion
  long long steps = 0;
  ParticleIndex projectile = 0;  ///< its index at the end (grains removed before it shift it down)
  /// Grains that went over the container's rim and were removed (remove_spilled_grains): low-gravity
  /// ejecta; 0 at 1 g in the paper's beds.
  std::size_t grains_spilled = 0;
};

/// Removes the grains that go over the rim of a container wall (a cylinder of finite height):
/// centred above its top (where the wall no longer acts on them) and beyond its radius less their
/// own, moving outward. Nothing brings
/// them back (the paper's Chrono runs have no domain: such grains fly on), so they are taken out
/// rather than ending a low-gravity drop with "left the container" when they cross the domain's
/// side. Contact histories of the other particles are kept; `projectile` follows the renumbering.
/// Returns how many were removed (checked once per output sample by drop_projectile).
std::size_t remove_spilled_grains(System& sys, ParticleIndex& projectile);

/// The grain a sphere of radius_m falling straight down along (x_m, y_m) touches first, and the
/// engine z of the sphere's bottom at that moment; nothing when no grain lies under it.
struct FirstTouch {
  double bottom_height_m = 0;
  ParticleIndex grain = 0;
};
std::optional<FirstTouch> first_touch_bottom(const System& sys, double x_m, double y_m, double radius_m);

/// progress(fraction of the time cap, detail); may throw to abort the run.
using DropProgress = std::function<void(double, const std::string&)>;

/// Grain snapshots during a drop: `write(sys, projectile, t_s)` is called at release,
/// every interval_s of simulated time (rounded to whole samples, at least one) and at the end.
/// Off when interval_s <= 0 or `write` is empty. `write` may throw to abort the run.
struct DropSnapshots {
  double interval_s = 0;
  std::function<void(const System&, ParticleIndex projectile, double t_since_release_s)> write;
};

/// Everything the drop's loop keeps between two samples besides the System (whose dynamic state
/// System::save_state gives): with both, drop_projectile continues a drop where it was, bit for bit.
struct DropLoopState {
  DropResult result;             ///< samples so far, release facts, first contact, spilled grains,
                                 ///< the projectile's index
  long long samples_done = 0;    ///< index k of the last sample taken (0: the release sample only)
  long long below_stop = 0;      ///< consecutive samples after contact below the stop speed
  long long last_snapshot = -1;  ///< sample index of the last grain snapshot (-1: none yet)
  double release_time_s = 0;     ///< System time at release: t = 0 of the samples
  long long release_step = 0;    ///< System step count at release
};

/// A drop saved between two samples: the System's state and the loop's.
struct DropState {
  SystemState system;
  DropLoopState loop;
};

/// Checkpoints of a drop. After each sample that does not end the drop, `due()` is asked; when it
/// answers true, `save(sys, loop)` is called between two samples (the caller stores
/// sys.save_state() and `loop`); it may throw to end the run (after saving on a stop request).
/// With `resume`, drop_projectile continues that drop instead of releasing the projectile: `sys`
/// must hold the configuration and the walls of the saved drop (its particles are replaced; a
/// state that does not fit is refused with std::invalid_argument before anything runs).
struct DropCheckpoints {
  std::function<bool()> due;
  std::function<void(const System&, const DropLoopState&)> save;
  const DropState* resume = nullptr;
};

/// Adds the projectile to the bed held by `sys` (grains + container walls), releases it and runs
/// to the stop criterion or the time cap. `surface_height_m` is the bed's mean surface (engine z).
/// Snapshots of a resumed drop are those from the resume on (the earlier ones were the earlier
/// run's); its samples are all of them. time_step on: the step is chosen before each sample
/// interval (AdaptiveStep, a whole number of steps per sample).
DropResult drop_projectile(System& sys, double surface_height_m, const ProjectileSpec& projectile, const DropStop& stop,
                           double sample_rate_hz, const DropProgress& progress = {},
                           const DropSnapshots& snapshots = {}, const DropCheckpoints& checkpoints = {},
                           const AdaptiveStep& time_step = {});

/// Kinetic energy (translational + rotational) of the free grains.
double grain_kinetic_energy_J(const System& sys);

}  // namespace gravsweep
