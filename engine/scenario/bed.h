// Bed preparation (Sunday et al. 2021 Sect. 2.2): place grains without overlap in a cylindrical
// container, settle them under gravity until the RMS and the largest grain speed fall below the
// criteria, delete the grains above the fill height, and let the surface relax.
// Engine frame: z up, container axis along z through the origin, bottom disk at z = 0.
#pragma once
#include <limits>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "engine/scenario/time_step.h"
#include "engine/system/system.h"
#include "engine/system/system_state.h"

namespace gravsweep {

struct ContainerSpec {
  double diameter_m = 0.315;   ///< inner diameter of the cylinder (paper: 31.5 cm)
  double wall_height_m = 0.0;  ///< 0 = as tall as the initial grain column
};

struct GrainSpec {
  double diameter_m = 0.01;         ///< mean grain diameter (paper: 1 cm)
  double diameter_spread_m = 5e-4;  ///< uniform spread +/- (paper, Chrono: 1 +/- 0.05 cm)
  double density_kg_m3 = 2480.0;
};

struct SettleCriteria {
  double rms_speed_m_s = 1e-5;     ///< paper: RMS grain speed < 1e-3 cm/s
  double max_speed_m_s = 1e-3;     ///< paper: fastest grain < 0.1 cm/s
  double max_time_s = 2.0;         ///< cap on simulated settling time per settling phase
  double check_interval_s = 1e-3;  ///< how often the criteria are evaluated
  /// Rolling-friction speed threshold (Chrono's min_roll_vel) while settling and relaxing. With
  /// Chrono's 1e-4 m/s, a grain whose rest needs rolling resistance rolls freely below 1e-4 m/s and
  /// is braked above it, so such grains creep at ~1e-4 m/s and the RMS speed stays near 5e-5 m/s,
  /// above the paper's 1e-5 m/s criterion. The drop keeps the system's own threshold.
  double min_roll_vel_m_s = 1e-6;
  /// Creep-floor stop (0: off, every phase runs to the criteria or max_time_s). Once the RMS speed
  /// is below max_speed_m_s (the bed quiet as a whole), a phase also ends when the RMS speed has not
  /// set a new low by kPlateauNewLow in this long and is back within that factor of the low (not
  /// in a burst above it): on the paper's bed it falls to a floor of
  /// 2-4e-5 m/s within ~0.4 s and then only creeps, with small avalanches, above the paper's 1e-5
  /// (BENCHMARKS.md), so the rest of the cap buys nothing.
  double plateau_window_s = 0;
};

/// A new low of the RMS speed (creep-floor stop) must be below this fraction of the previous low.
inline constexpr double kPlateauNewLow = 0.9;

/// How a settling phase ended.
enum class SettleEnd { criteria, plateau, time_cap };
const char* to_string(SettleEnd e);

/// The placement lattice's default spacing, in largest grain diameters (BedSpec).
inline constexpr double kLatticeSpacingDiameters = 1.04;

struct BedSpec {
  ContainerSpec container;
  GrainSpec grains;
  double fill_height_m = 0.10;     ///< bed depth after flattening (paper: 10 cm, 21 cm at low g)
  double overfill_factor = 1.15;   ///< grains poured relative to the fill volume
  double packing_fraction = 0.60;  ///< assumed random packing, for the grain count
  /// Spacing of the triangular lattice the grains are placed on before the pour, in largest grain
  /// diameters (the jitter is 45 % of the gap). 1.04 keeps a monodisperse bed's lattice through the
  /// pour: it packs in order (packing fraction 0.68-0.69, above random close packing's 0.64;
  /// REPRODUCTION.md part 5); 1.5 randomises it (0.62).
  double placement_spacing_diameters = kLatticeSpacingDiameters;
  std::uint64_t seed = 1;
  SettleCriteria settle;
  /// Minimum free relaxation after flattening (after the ramp and quench, at the drop's gravity),
  /// even past settle.max_time_s. At low gravity a grain left perched by the ramp rolls off in a few
  /// sqrt(d / g) (1 s at 0.01 m/s2, growing from 2e-5 to 3e-4 m/s before it lands) and the bed is
  /// quiet after: give a low-gravity bed several sqrt(d / g) so that it is not caught mid-roll.
  double relax_time_s = 0.05;
  std::uint8_t grain_material = 0;
  std::uint8_t wall_material = 1;
  /// When set, gravity switches to this value after flattening, before the relaxation (a bed poured
  /// and settled at one gravity, relaxed at the drop's; unset: the system's gravity throughout).
  std::optional<Vec3> relax_gravity_m_s2;
  /// With relax_gravity_m_s2: gravity goes from the settling value to it geometrically over this
  /// time before the relaxation (0: at once). Dropping 9.81 to 0.1 m/s2 at once releases the
  /// contacts' elastic energy into a bed that gravity barely holds: measured 1 cm/s RMS grain speed
  /// still 0.4 s later.
  double gravity_ramp_s = 0.1;
  /// Kinetic-energy quench of a bed relaxed at another gravity (0: off): during the ramp and for
  /// quench_time_s after it, every quench_interval_s, each grain that moves against the force on
  /// it (F.v < 0: past the bottom of its potential well) is stopped, its spin likewise against its
  /// torque. Grains still fall, slide and roll where the forces take them (a rattler lands in its
  /// cage), but the elastic energy the contacts release as gravity falls is taken out instead of
  /// launching grains that a weak gravity barely brings back: the per-grain form of the FIRE
  /// minimiser's velocity reset (Bitzek et al. 2006, PRL 97, 170201), relaxing the packing to its
  /// equilibrium at the new gravity. The relaxation that follows runs free, at least relax_time_s,
  /// and its criteria are measured on free grains.
  double quench_interval_s = 0;
  double quench_time_s = 0;
  /// Time the flattened surface runs at the settling gravity before the ramp (0: none). Flattening
  /// leaves grains perched where the removed layer held them; they roll into their pockets in a few
  /// sqrt(d / g): 0.03 s at 9.81 m/s2, 0.3 s at 0.1 and 3 s at 0.001 m/s2, where a quench, stopping
  /// every grain whose spin runs against its torque, holds them perched for as long as it lasts.
  /// A pocket that holds at one gravity holds at any (rigid grains: gravity scales every force of
  /// a contact network at rest alike), so the surface is let settle where it is cheap.
  double surface_relax_s = 0;
  /// Step of the phases at the drop's gravity after the ramp (the quench and the free relaxation);
  /// off: dt_s throughout. A bed at 0.001 m/s2 relaxes for tens of seconds in which its fastest
  /// grain moves at mm/s: at 5 us that is millions of steps for contacts that last ms.
  AdaptiveStep time_step;
  /// A lid on the container while the grains are poured and settle (removed before flattening): a
  /// disk at the wall's top, facing down. Poured at low gravity, a grain bounced off the pile rises
  /// far (0.3 m from 0.08 m/s at 0.01 m/s2) and may leave the domain (measured: at 0.01 m/s2 a
  /// grain left it after 5.75 s); the lid sends it back. Off: an open container, as the paper's.
  bool lid = false;
  /// With time_step on: the pour and its settling run at the adaptive step too, and so does the
  /// relaxation of a bed poured at the drop's gravity (no ramp). Poured at 0.01 m/s2, grains fall
  /// and settle for tens of seconds at mm/s to cm/s: millions of fixed 5 us steps. Off: the pour
  /// keeps dt_s, as every earlier bed.
  bool pour_time_step = false;
};

/// Phase of bed preparation, for progress reporting.
enum class BedPhase { fill, settle, flatten, relax };
const char* to_string(BedPhase p);

/// progress(phase, fraction in [0, 1], detail)
using BedProgress = std::function<void(BedPhase, double, const std::string&)>;

struct BedReport {
  std::size_t grains_placed = 0;
  std::size_t grains_kept = 0;
  double settle_time_s = 0;
  double relax_time_s = 0;
  double quench_time_s = 0;    ///< time run under the quench after the ramp (0: no quench)
  double surface_relax_s = 0;  ///< time the flattened surface ran at the settling gravity before the ramp
  bool settled = false;        ///< criteria met in both phases (false: the time cap or the creep floor ended one)
  SettleEnd settle_end = SettleEnd::time_cap;  ///< how the settling of the pour ended
  SettleEnd relax_end = SettleEnd::time_cap;   ///< how the relaxation after flattening ended
  double rms_speed_m_s = 0;
  double max_speed_m_s = 0;
  double surface_height_m = 0;  ///< mean height of the top of the grains near the axis
  double bulk_density_kg_m3 = 0;
};

/// Where a resumable loop of the preparation stands (settle, ramp_gravity, quench, the surface
/// relaxation): intervals done since the stage began, when it began, and the settling's creep
/// floor. A loop given a cursor with intervals = 0 starts the stage now; with intervals > 0 it
/// continues it (the System restored to the state saved with the cursor), bit for bit.
struct StageCursor {
  long long intervals = 0;  ///< check (or quench, or ramp) intervals done in the stage
  double start_s = 0;       ///< System time at the stage's start
  double low_m_s = kInf;    ///< settle: lowest RMS grain speed since the bed became quiet
  double low_at_s = 0;      ///< settle: when (since start_s) that low was set
  double from_m_s2 = 0;     ///< ramp_gravity: the magnitude of gravity at the ramp's start
};

/// Called after each interval of a loop that the interval did not end (it may throw to stop the
/// run; the System then holds the state the cursor describes).
using IntervalHook = std::function<void(const StageCursor&)>;

/// The stages of prepare_bed after the placement, in order. Flattening happens between settle and
/// surface_relax (a checkpoint of a later stage holds the flattened bed).
enum class BedStage : std::uint8_t { settle = 0, surface_relax, ramp, quench, relax };

/// Everything prepare_bed keeps between two intervals besides the System (System::save_state):
/// with both, a bed's preparation continues where it was, bit for bit on the same thread count.
struct BedLoopState {
  BedStage stage = BedStage::settle;
  StageCursor cursor;        ///< the running stage's
  double wall_height_m = 0;  ///< the container's wall (walls are rebuilt, not stored)
  BedReport report;          ///< what the finished stages measured
};

/// A bed saved between two intervals of its preparation.
struct BedState {
  SystemState system;
  BedLoopState loop;
};

/// Checkpoints of a bed's preparation (as DropCheckpoints for a drop): after each interval that
/// does not end a stage, `due()` is asked; when it answers true, `save(sys, loop)` stores the state
/// (it may throw to end the run). With `resume`, prepare_bed continues that preparation instead of
/// placing grains: `sys` must hold the configuration it was made with; the container's walls are
/// rebuilt from the saved state, and a state that does not fit is refused with
/// std::invalid_argument before anything runs.
struct BedCheckpoints {
  std::function<bool()> due;
  std::function<void(const System&, const BedLoopState&)> save;
  const BedState* resume = nullptr;
};

/// Adds the container walls (disk bottom at z = 0, cylinder side) to the system.
void add_container_walls(System& sys, const ContainerSpec& c, double height_m, std::uint8_t wall_material);

/// Closes the container with a lid at `height_m` (BedSpec::lid): a disk named kLidWallName facing
/// down; remove_lid takes it off again (no-op without one).
inline constexpr const char* kLidWallName = "lid";
void add_lid(System& sys, const ContainerSpec& c, double height_m, std::uint8_t wall_material);
void remove_lid(System& sys);

/// Places grains without overlap on a jittered lattice filling the container up to the height
/// needed for the grain count; returns the number placed.
std::size_t place_grains(System& sys, const BedSpec& spec);

/// Runs until the grains meet the criteria, reach their creep floor (c.plateau_window_s) or the time
/// cap, after at least min_time_s; returns which ended it. With `step` on, the step is chosen
/// before each check interval (AdaptiveStep) and the system's step is restored at the end.
/// With `cursor`, the phase starts or continues there and `after` is called after each interval.
SettleEnd settle(System& sys, const SettleCriteria& c, double min_time_s, const BedProgress& progress, BedPhase phase,
                 double* rms_out = nullptr, double* max_out = nullptr, const AdaptiveStep& step = {},
                 StageCursor* cursor = nullptr, const IntervalHook& after = {});

/// Takes gravity from its present value to `to_m_s2` geometrically over ramp_s (same direction; in
/// any other case, or with ramp_s = 0, at once), advancing the system meanwhile.
/// With quench, stop_grains after each interval (BedSpec::quench_interval_s).
/// With `cursor`, the ramp starts or continues there and `after` is called after each interval.
void ramp_gravity(System& sys, const Vec3& to_m_s2, double ramp_s, double interval_s, const BedProgress& progress = {},
                  bool quench = false, StageCursor* cursor = nullptr, const IntervalHook& after = {});

/// Stops each free grain moving against its force, and its spin against its torque (BedSpec quench).
void stop_grains(System& sys);

/// Runs time_s, applying stop_grains every interval_s (BedSpec::quench_interval_s). With `step`
/// on, the step is chosen before each interval and the system's step is restored at the end.
/// With `cursor`, the quench starts or continues there and `after` is called after each interval.
void quench(System& sys, double time_s, double interval_s, const BedProgress& progress = {},
            const AdaptiveStep& step = {}, StageCursor* cursor = nullptr, const IntervalHook& after = {});

/// Runs time_s at the system's step in chunks of interval_s (the flattened surface's relaxation at
/// the settling gravity, BedSpec::surface_relax_s); with `cursor`, starts or continues there.
void run_for(System& sys, double time_s, double interval_s, const BedProgress& progress = {},
             StageCursor* cursor = nullptr, const IntervalHook& after = {});

/// The whole preparation: walls, placement, settling, flattening, relaxation; with checkpoints
/// (BedCheckpoints), saved between intervals and continued from a saved state
/// (engine/scenario/bed_prepare.cpp).
BedReport prepare_bed(System& sys, const BedSpec& spec, const BedProgress& progress = {},
                      const BedCheckpoints& checkpoints = {});

/// Height of the bed surface: mean of the highest grain tops in the central region.
double surface_height(const System& sys, double container_radius_m);

/// RMS and maximum speed of the free grains (size class grain).
void grain_speeds(const System& sys, double& rms_m_s, double& max_m_s);

/// How still a bed is, for comparison with the impact it will receive: the speeds of grains that
/// the projectile meets first (their centre within kSurfaceLayerDiameters grain diameters below
/// the mean surface, or above it) and of the bed (RMS and fastest), both within the window.
struct BedRestState {
  double rms_speed_m_s = 0;
  double max_speed_m_s = 0;
  double max_surface_speed_m_s = 0;
  std::size_t surface_grains = 0;
};
inline constexpr double kSurfaceLayerDiameters = 2.0;
/// The part of the bed that counts: grains whose centre lies within radius_m of the vertical line
/// through (x_m, y_m), the impact axis, at the surface and at every depth; by default the whole
/// bed. The creep a ramped-down bed keeps lies at the container wall (GRAVITY.md, 'Where the
/// creeping grains are'): on the 0.1 m/s2 sweep bed the RMS speed within 10 cm of the axis is
/// 4.6e-6 m/s, against 2.6e-5 m/s over the whole bed.
struct SurfaceWindow {
  double x_m = 0, y_m = 0;
  double radius_m = std::numeric_limits<double>::infinity();
};
BedRestState bed_rest_state(const System& sys, double surface_height_m, double grain_diameter_m,
                            const SurfaceWindow& window = {});

/// Packing fraction of the grains in a coaxial cylinder (axis distance < core_radius_m, z_lo_m < z <
/// z_hi_m): each sphere's volume inside the z slab, exactly (layered crystals bias a count of whole
/// spheres by their centres), for spheres centred within core_radius_m. Random packing of equal
/// spheres: 0.55-0.64; close packing: 0.7405. Ignores projectiles (size class).
double core_packing_fraction(const Particles& p, double core_radius_m, double z_lo_m, double z_hi_m);

}  // namespace gravsweep
