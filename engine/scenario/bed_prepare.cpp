// prepare_bed: the stages of a bed's preparation (Sunday et al. 2021 Sect. 2.2) in order, each a
// resumable loop (StageCursor), with checkpoints between intervals (BedCheckpoints).
#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "engine/core/error.h"
#include "engine/scenario/bed.h"

namespace gravsweep {

namespace {

void check_bed_spec(const System& sys, const BedSpec& spec) {
  if (!(spec.fill_height_m > 0)) throw ConfigError("bed: fill_height_m must be > 0");
  if (!(spec.grains.diameter_m > 0)) throw ConfigError("bed: grain diameter_m must be > 0");
  if (!(spec.grains.diameter_spread_m >= 0 && spec.grains.diameter_spread_m < 0.5 * spec.grains.diameter_m))
    throw ConfigError("bed: grain diameter_spread_m must be in [0, diameter/2)");
  if (!(spec.container.diameter_m > 4 * spec.grains.diameter_m))
    throw ConfigError("bed: container diameter_m must exceed 4 grain diameters");
  check_adaptive_step(spec.time_step, sys.config().dt_s, "bed");
}

/// Places the grains and builds the container (with its lid when asked): the state before the
/// first stage. Returns the wall height.
double fill_container(System& sys, const BedSpec& spec, const BedProgress& progress, BedReport& rep) {
  if (progress) progress(BedPhase::fill, 0.0, "placing grains");
  rep.grains_placed = place_grains(sys, spec);
  double top = 0;
  for (std::size_t i = 0; i < sys.particles.size(); ++i)
    top = std::max(top, sys.particles.position_m[i].z() + sys.particles.radius_m[i]);
  const double wall_h =
      spec.container.wall_height_m > 0 ? spec.container.wall_height_m : std::max(top, spec.fill_height_m) + 0.1;
  add_container_walls(sys, spec.container, wall_h, spec.wall_material);
  if (spec.lid) add_lid(sys, spec.container, wall_h, spec.wall_material);
  sys.invalidate();
  if (progress) progress(BedPhase::fill, 1.0, fmt::format("{} grains", rep.grains_placed));
  return wall_h;
}

/// Puts a saved preparation back into `sys` (made with the saved bed's configuration): the walls
/// of its stage (the lid while the pour settles), then the dynamic state.
void restore_bed(System& sys, const BedSpec& spec, const BedState& saved) {
  if (!(saved.loop.wall_height_m > 0))
    throw std::invalid_argument(
        fmt::format("bed state cannot be restored: wall height {} m", saved.loop.wall_height_m));
  sys.walls.clear();
  add_container_walls(sys, spec.container, saved.loop.wall_height_m, spec.wall_material);
  if (spec.lid && saved.loop.stage == BedStage::settle)
    add_lid(sys, spec.container, saved.loop.wall_height_m, spec.wall_material);
  sys.restore_state(saved.system);
}

/// Deletes the grains whose centre lies above the fill height.
void flatten(System& sys, const BedSpec& spec, const BedProgress& progress) {
  std::vector<bool> remove(sys.particles.size(), false);
  for (std::size_t i = 0; i < sys.particles.size(); ++i)
    remove[i] = sys.particles.size_class[i] == SizeClass::grain && sys.particles.position_m[i].z() > spec.fill_height_m;
  sys.remove_particles(remove);
  if (progress) progress(BedPhase::flatten, 1.0, fmt::format("{} grains kept", sys.particles.size()));
}

/// The surface height and bulk density of the finished bed.
void measure_bed(const System& sys, const BedSpec& spec, BedReport& rep) {
  rep.settled = rep.settle_end == SettleEnd::criteria && rep.relax_end == SettleEnd::criteria;
  rep.grains_kept = sys.particles.size();
  rep.surface_height_m = surface_height(sys, 0.5 * spec.container.diameter_m);
  double mass = 0;
  for (double m : sys.particles.mass_kg) mass += m;
  const double R = 0.5 * spec.container.diameter_m;
  rep.bulk_density_kg_m3 = rep.surface_height_m > 0 ? mass / (kPi * R * R * rep.surface_height_m) : 0;
}

}  // namespace

BedReport prepare_bed(System& sys, const BedSpec& spec, const BedProgress& progress, const BedCheckpoints& ckpt) {
  check_bed_spec(sys, spec);
  BedLoopState st;
  if (ckpt.resume != nullptr) {
    restore_bed(sys, spec, *ckpt.resume);
    st = ckpt.resume->loop;
  } else {
    st.wall_height_m = fill_container(sys, spec, progress, st.report);
  }
  BedReport& rep = st.report;
  const IntervalHook hook = [&](const StageCursor&) {
    if (ckpt.due && ckpt.save && ckpt.due()) ckpt.save(sys, st);
  };
  const auto enter = [&](BedStage next) {
    st.stage = next;
    st.cursor = StageCursor{0, sys.time_s()};
  };
  const bool quenched = spec.quench_interval_s > 0 && spec.quench_time_s > 0;
  // The adaptive step (when on) applies at the drop's gravity only: after a ramp, or throughout a
  // bed poured at the drop's gravity with pour_time_step.
  const AdaptiveStep relax_step = spec.relax_gravity_m_s2 || spec.pour_time_step ? spec.time_step : AdaptiveStep{};
  if (st.stage == BedStage::settle) {  // settle under gravity (with the lid, when asked)
    const AdaptiveStep pour_step = spec.pour_time_step ? spec.time_step : AdaptiveStep{};
    rep.settle_end = settle(sys, spec.settle, 0.0, progress, BedPhase::settle, &rep.rms_speed_m_s, &rep.max_speed_m_s,
                            pour_step, &st.cursor, hook);
    rep.settle_time_s = sys.time_s() - st.cursor.start_s;
    remove_lid(sys);
    flatten(sys, spec, progress);
    enter(BedStage::surface_relax);
  }
  if (st.stage == BedStage::surface_relax) {  // the flattened surface at the settling gravity
    if (spec.surface_relax_s > 0) {
      run_for(sys, spec.surface_relax_s, spec.settle.check_interval_s, progress, &st.cursor, hook);
      rep.surface_relax_s = spec.surface_relax_s;
    }
    enter(BedStage::ramp);
  }
  if (st.stage == BedStage::ramp) {  // to the drop's gravity, geometrically, the contacts unloading gradually
    if (spec.relax_gravity_m_s2)
      ramp_gravity(sys, *spec.relax_gravity_m_s2, spec.gravity_ramp_s, spec.settle.check_interval_s, progress, quenched,
                   &st.cursor, hook);
    enter(BedStage::quench);
  }
  if (st.stage == BedStage::quench) {
    if (quenched) {
      quench(sys, spec.quench_time_s, spec.quench_interval_s, progress, relax_step, &st.cursor, hook);
      rep.quench_time_s = spec.quench_time_s;
    }
    enter(BedStage::relax);
  }
  rep.relax_end = settle(sys, spec.settle, spec.relax_time_s, progress, BedPhase::relax, &rep.rms_speed_m_s,
                         &rep.max_speed_m_s, relax_step, &st.cursor, hook);
  rep.relax_time_s = sys.time_s() - st.cursor.start_s;
  measure_bed(sys, spec, rep);
  return rep;
}

}  // namespace gravsweep
