// A bed's preparation saved between two intervals and continued in a fresh System
// (engine/scenario/bed_prepare.cpp, BedCheckpoints): interrupted once in each of its five stages
// (the pour settling under a lid, the flattened surface's relaxation, the gravity ramp, the
// quench at the adaptive step, the free relaxation), it ends in the state of an uninterrupted
// preparation, bit for bit.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>

#include "engine/scenario/bed.h"
#include "physics_helpers.h"

using namespace gravsweep;

namespace {

/// Thrown by the test's save hook after storing the state: the run ends there.
struct Stopped : std::runtime_error {
  Stopped() : std::runtime_error("stopped after a checkpoint") {}
};

SystemConfig cup_config() {
  SystemConfig cfg = chrono_table1_config(0.09);
  cfg.dt_s = 1e-5;
  cfg.threads = 1;
  return cfg;
}

/// An 8 cm cup (4 cm fill, a few hundred grains) poured under a lid at 9.81 m/s2, flattened, its
/// surface relaxed, ramped to 0.1 m/s2 under a quench that goes on at the adaptive step, then
/// relaxed free at the adaptive step: every stage of prepare_bed runs.
BedSpec cup_spec() {
  BedSpec spec;
  spec.container.diameter_m = 0.08;
  spec.fill_height_m = 0.04;
  spec.seed = 11;
  spec.lid = true;
  spec.settle.max_time_s = 0.12;
  spec.settle.rms_speed_m_s = 1e-5;
  spec.settle.max_speed_m_s = 1e-4;
  spec.surface_relax_s = 0.02;
  spec.relax_gravity_m_s2 = Vec3(0, 0, -0.1);
  spec.gravity_ramp_s = 0.05;
  spec.quench_interval_s = 5e-4;
  spec.quench_time_s = 0.05;
  spec.relax_time_s = 0.05;
  spec.time_step.steps_per_contact = 50;
  spec.time_step.dt_max_s = 1e-4;
  return spec;
}

/// Saves (in memory) and stops once in each stage, at the stage's `at` interval.
struct StopInEachStage {
  std::map<BedStage, long long> at{{BedStage::settle, 30},
                                   {BedStage::surface_relax, 10},
                                   {BedStage::ramp, 20},
                                   {BedStage::quench, 40},
                                   {BedStage::relax, 10}};
  std::set<BedStage> done;
  BedState saved;
  BedCheckpoints hooks() {
    BedCheckpoints h;
    h.due = [] { return true; };
    h.save = [this](const System& sys, const BedLoopState& loop) {
      if (done.count(loop.stage) > 0 || loop.cursor.intervals != at.at(loop.stage)) return;
      done.insert(loop.stage);
      saved = BedState{sys.save_state(), loop};
      throw Stopped();
    };
    return h;
  }
};

}  // namespace

TEST(BedCheckpoint, InterruptedInEachStageTheBedIsTheUninterruptedOne) {
  const BedSpec spec = cup_spec();
  System reference(cup_config());
  const BedReport want = prepare_bed(reference, spec);

  StopInEachStage stops;
  std::optional<BedReport> got;
  std::unique_ptr<System> sys;
  int runs = 0;
  for (; runs < 10 && !got; ++runs) {
    sys = std::make_unique<System>(cup_config());  // a fresh system each time, as a new attempt has
    BedCheckpoints h = stops.hooks();
    if (runs > 0) h.resume = &stops.saved;
    try {
      got = prepare_bed(*sys, spec, {}, h);
    } catch (const Stopped&) {
      EXPECT_EQ(sys->time_s(), stops.saved.system.time_s);
    }
  }
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(runs, 6) << "five interruptions, one in each stage, then the end";
  EXPECT_EQ(stops.done.size(), 5u);
  EXPECT_EQ(sys->particles.position_m, reference.particles.position_m);
  EXPECT_EQ(sys->particles.velocity_m_s, reference.particles.velocity_m_s);
  EXPECT_EQ(sys->particles.omega_rad_s, reference.particles.omega_rad_s);
  EXPECT_EQ(sys->time_s(), reference.time_s());
  EXPECT_EQ(sys->step_count(), reference.step_count());
  EXPECT_EQ(sys->config().gravity_m_s2, reference.config().gravity_m_s2);
  EXPECT_EQ(sys->config().dt_s, reference.config().dt_s) << "the bed's step comes back after the adaptive phases";
  EXPECT_EQ(sys->walls.size(), reference.walls.size()) << "the lid is off";
  EXPECT_EQ(got->grains_placed, want.grains_placed);
  EXPECT_EQ(got->grains_kept, want.grains_kept);
  EXPECT_EQ(got->settle_time_s, want.settle_time_s);
  EXPECT_EQ(got->relax_time_s, want.relax_time_s);
  EXPECT_EQ(got->quench_time_s, want.quench_time_s);
  EXPECT_EQ(got->surface_relax_s, want.surface_relax_s);
  EXPECT_EQ(got->settle_end, want.settle_end);
  EXPECT_EQ(got->relax_end, want.relax_end);
  EXPECT_EQ(got->surface_height_m, want.surface_height_m);
  EXPECT_EQ(got->rms_speed_m_s, want.rms_speed_m_s);
}

// A saved state that does not fit the system it is restored into (fewer particle arrays than
// grains) is refused before anything runs, with std::invalid_argument.
TEST(BedCheckpoint, AStateThatDoesNotFitIsRefused) {
  const BedSpec spec = cup_spec();
  StopInEachStage stops;
  System first(cup_config());
  EXPECT_THROW(prepare_bed(first, spec, {}, stops.hooks()), Stopped);
  BedState broken = stops.saved;
  broken.system.particles.radius_m.pop_back();
  System second(cup_config());
  BedCheckpoints h;
  h.resume = &broken;
  EXPECT_THROW(prepare_bed(second, spec, {}, h), std::invalid_argument);
}
