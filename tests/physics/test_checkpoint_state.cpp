// System::save_state / restore_state (engine/system/system_state.h): a run saved after k steps and
// continued in a fresh System must reach, after N steps in all, bit for bit the state of a run that
// never stopped (same thread count). Covered: the laws with frame histories (hooke, zhang) and
// without, the three integrators (leapfrog_kdk and velocity Verlet start a step from the saved
// forces), saves just before and after neighbour-list rebuilds, a save right after particles were
// removed, and 1 and 2 threads (the saved work prefix decides the thread split, hence the rounding).
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>
#include <tuple>

#include "physics_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;

namespace {

constexpr int kSteps = 2400;                   ///< N: the whole run
constexpr double kLatticeSpacingFactor = 2.1;  ///< grain spacing / radius
constexpr double kMixingSpeed_m_s = 1.0;       ///< random velocities: contacts open and close, the list is rebuilt
constexpr double kBox_m = 0.06;                ///< side of the square box around the lattice

struct RunSetup {
  std::string law, rolling, integrator;
  int threads;
};

SystemConfig config_of(const RunSetup& s) {
  SystemConfig c = two_material_config(s.law, 0.7, 0.3, s.rolling);
  for (auto& m : c.materials) {
    m.mu_rolling = 0.05;
    m.mu_twisting = 0.05;
  }
  c.integrator = s.integrator;
  c.gravity_m_s2 = Vec3(0, 0, -9.81);
  c.threads = s.threads;
  c.parallel_min_particles = 1;  // the small system runs on s.threads threads
  return c;
}

/// The walls of a box (floor and four sides) around a 5 x 5 x 4 lattice of grains with random
/// velocities and spins. The walls are what restore_state() expects the fresh System to have.
void add_walls(System& s) {
  s.walls.push_back(Wall::plane("floor", Vec3::Zero(), Vec3::UnitZ(), 1));
  s.walls.push_back(Wall::plane("x0", Vec3::Zero(), Vec3::UnitX(), 1));
  s.walls.push_back(Wall::plane("x1", Vec3(kBox_m, 0, 0), -Vec3::UnitX(), 1));
  s.walls.push_back(Wall::plane("y0", Vec3::Zero(), Vec3::UnitY(), 1));
  s.walls.push_back(Wall::plane("y1", Vec3(0, kBox_m, 0), -Vec3::UnitY(), 1));
}

void fill(System& s) {
  add_walls(s);
  const double r = kBeadRadius_m, m = bead_mass_kg(), a = kLatticeSpacingFactor * r;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 5; ++x) {
        const ParticleIndex i =
            s.particles.add(Vec3(1.5 * r + x * a, 1.5 * r + y * a, 1.05 * r + z * a), r, m, 0, SizeClass::grain);
        s.particles.set_velocity(i, Vec3(u(rng), u(rng), u(rng)) * kMixingSpeed_m_s,
                                 Vec3(u(rng), u(rng), u(rng)) * 50.0);
      }
}

void expect_same_state(const System& a, const System& b) {
  ASSERT_EQ(a.particles.size(), b.particles.size());
  EXPECT_EQ(a.step_count(), b.step_count());
  EXPECT_EQ(a.time_s(), b.time_s());
  for (std::size_t i = 0; i < a.particles.size(); ++i) {
    ASSERT_EQ(a.particles.position_m[i], b.particles.position_m[i]) << "particle " << i;
    ASSERT_EQ(a.particles.velocity_m_s[i], b.particles.velocity_m_s[i]) << "particle " << i;
    ASSERT_EQ(a.particles.omega_rad_s[i], b.particles.omega_rad_s[i]) << "particle " << i;
  }
  EXPECT_EQ(a.neighbor_list().builds(), b.neighbor_list().builds());
}

/// Removes every seventh grain at `step` (a spill or a flattening): the save right after it holds
/// a System that must re-initialise at its next step.
void remove_some(System& s) {
  std::vector<bool> drop(s.particles.size(), false);
  for (std::size_t i = 3; i < drop.size(); i += 7) drop[i] = true;
  s.remove_particles(drop);
}

void PrintTo(const RunSetup& s, std::ostream* os) {
  *os << s.law << " + " << s.rolling << ", " << s.integrator << ", " << s.threads << " threads";
}

class CheckpointState : public ::testing::TestWithParam<RunSetup> {};

}  // namespace

// N steps in one go against k steps, save, a fresh System restored, N - k steps; for several k,
// and with grains removed at kSteps / 2 (then saved at once, before any step re-initialises).
TEST_P(CheckpointState, RestoredRunIsBitIdentical) {
  const RunSetup& setup = GetParam();
  System ref(config_of(setup));
  fill(ref);
  long long contacts = 0, wall_contacts = 0;
  for (int s = 0; s < kSteps; ++s) {
    if (s == kSteps / 2) remove_some(ref);
    ref.step();
    contacts += ref.stats().contacts;
    wall_contacts += ref.stats().wall_contacts;
  }
  EXPECT_GT(ref.neighbor_list().builds(), 3);  // the list was rebuilt during the run
  EXPECT_GT(contacts, kSteps) << "grains collide";
  EXPECT_GT(wall_contacts, kSteps) << "grains rest on and hit the walls";
  for (int k : {1, 377, kSteps / 2, 1711}) {
    SCOPED_TRACE("saved after step " + std::to_string(k));
    SystemState saved;
    {
      System first(config_of(setup));
      fill(first);
      for (int s = 0; s < k; ++s) {
        if (s == kSteps / 2) remove_some(first);
        first.step();
      }
      if (k == kSteps / 2) remove_some(first);
      saved = first.save_state();
    }  // the first run is gone: only the state carries over
    System resumed(config_of(setup));
    add_walls(resumed);
    resumed.restore_state(saved);
    for (int s = k; s < kSteps; ++s) {
      if (s == kSteps / 2 && s != k) remove_some(resumed);
      resumed.step();
    }
    EXPECT_NO_FATAL_FAILURE(expect_same_state(ref, resumed));
  }
}

INSTANTIATE_TEST_SUITE_P(LawsIntegratorsThreads, CheckpointState,
                         ::testing::Values(RunSetup{"hertz", "sunday", "semi_implicit_euler", 1},
                                           RunSetup{"hertz", "sunday", "semi_implicit_euler", 2},
                                           RunSetup{"hooke", "zhang", "leapfrog_kdk", 1},
                                           RunSetup{"hooke", "zhang", "leapfrog_kdk", 2},
                                           RunSetup{"hertz", "zhang", "velocity_verlet", 2}),
                         [](const ::testing::TestParamInfo<RunSetup>& info) {
                           return info.param.law + "_" + info.param.rolling + "_" + info.param.integrator + "_" +
                                  std::to_string(info.param.threads) + "threads";
                         });

// A state that does not fit the System it is restored into is refused before anything changes
// hands, with what does not fit: frame histories for a law that keeps none, a wall count.
TEST(CheckpointStateRefused, ByTheLawAndTheWalls) {
  System hooke(config_of({"hooke", "zhang", "leapfrog_kdk", 1}));
  fill(hooke);
  hooke.advance(200);
  const SystemState with_frames = hooke.save_state();
  ASSERT_FALSE(with_frames.pair_frame_history.empty());
  System hertz(config_of({"hertz", "sunday", "semi_implicit_euler", 1}));
  add_walls(hertz);
  try {
    hertz.restore_state(with_frames);
    FAIL() << "restored frame histories into hertz + sunday";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("frame histories"), std::string::npos) << e.what();
  }
  System no_walls(config_of({"hooke", "zhang", "leapfrog_kdk", 1}));
  EXPECT_THROW(no_walls.restore_state(with_frames), std::invalid_argument);
}
