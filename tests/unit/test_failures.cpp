// Numerical failure stops the run with a message naming the particle, the step and the cause.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "engine/core/error.h"
#include "engine/scenario/paper_params.h"
#include "engine/system/system.h"

using namespace gravsweep;

namespace {
SystemConfig no_gravity() {
  auto c = chrono_table1_config();
  c.gravity_m_s2 = Vec3::Zero();
  return c;
}
}  // namespace

TEST(Failure, OverlapBeyondHalfRadiusNamesParticlesAndStep) {
  System s(no_gravity());
  s.particles.add(Vec3(0, 0, 0), 0.005, 1.3e-3, 0, SizeClass::grain);
  s.particles.add(Vec3(0, 0, 0.004), 0.005, 1.3e-3, 0, SizeClass::grain);  // 60 % overlap
  try {
    s.step();
    FAIL() << "expected NumericalFailure";
  } catch (const NumericalFailure& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.step(), 0);
    EXPECT_EQ(e.particle(), 0);
    EXPECT_NE(msg.find("particle 0 overlaps particle 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("step 0"), std::string::npos) << msg;
  }
}

TEST(Failure, OverlapWithAWallNamesTheWall) {
  for (const char* law : {"hertz", "hooke"}) {  // the batched and the scalar pair paths share the wall loop
    SystemConfig cfg = no_gravity();
    if (std::string(law) == "hooke") {
      cfg.contact_law = "hooke";
      cfg.rolling_model = "none";
      cfg.integrator = "leapfrog_kdk";
      for (auto& m : cfg.materials) m.kn_N_m = 7.48e5;  // docs/physics/contact-laws.md section 2.4
    }
    System s(cfg);
    s.walls.push_back(Wall::plane("floor", Vec3(0, 0, 0), Vec3(0, 0, 1), 1));
    s.particles.add(Vec3(0.1, 0, 0.01), 0.005, 1.3e-3, 0, SizeClass::grain);  // clear of the floor
    s.particles.add(Vec3(0, 0, 0.002), 0.005, 1.3e-3, 0, SizeClass::grain);   // 60 % into it
    try {
      s.step();
      ADD_FAILURE() << law << ": expected NumericalFailure";
    } catch (const NumericalFailure& e) {
      const std::string msg = e.what();
      EXPECT_EQ(e.particle(), 1) << law;
      EXPECT_NE(msg.find("particle 1 overlaps wall 'floor' by 60 %"), std::string::npos) << law << ": " << msg;
    }
  }
}

TEST(Failure, NaNVelocityIsReported) {
  System s(no_gravity());
  s.particles.add(Vec3(0, 0, 0), 0.005, 1.3e-3, 0, SizeClass::grain);
  s.particles.add(Vec3(0.1, 0, 0), 0.005, 1.3e-3, 0, SizeClass::grain);
  s.advance(3);
  s.particles.velocity_m_s[1].x() = std::numeric_limits<double>::quiet_NaN();
  try {
    s.step();
    FAIL() << "expected NumericalFailure";
  } catch (const NumericalFailure& e) {
    EXPECT_EQ(e.particle(), 1);
    EXPECT_EQ(e.step(), 4);
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
  }
}

// With two threads the end of step runs inside the force loop in blocks handed to whichever thread
// asks first (force_loop.h, FinishQueue): the first bad particle of all blocks is the one reported,
// whichever thread and block found it, and the step's findings do not leak into the next step.
TEST(Failure, FirstBadParticleOfAllThreadSharesIsReported) {
  auto cfg = no_gravity();
  cfg.threads = 2;
  System s(cfg);
  const int n = 1500;  // several blocks of the end-of-step loop
  for (int i = 0; i < n; ++i)
    s.particles.add(Vec3(0.011 * (i % 40), 0.011 * (i / 40), 0), 0.005, 1.3e-3, 0, SizeClass::grain);
  s.advance(2);
  s.particles.velocity_m_s[1300].y() = std::numeric_limits<double>::quiet_NaN();  // a late block
  s.particles.velocity_m_s[700].x() = std::numeric_limits<double>::infinity();    // an earlier block
  try {
    s.step();
    FAIL() << "expected NumericalFailure";
  } catch (const NumericalFailure& e) {
    EXPECT_EQ(e.particle(), 700);
    EXPECT_EQ(e.step(), 3);  // as NaNVelocityIsReported: the step that made the state bad
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
  }
}

TEST(Failure, GrainLeavingTheContainer) {
  auto cfg = no_gravity();
  cfg.domain = Domain{Vec3(-0.1, -0.1, -0.1), Vec3(0.1, 0.1, 0.1)};
  System s(cfg);
  s.particles.add(Vec3(0, 0, 0), 0.005, 1.3e-3, 0, SizeClass::grain);
  s.particles.add(Vec3(0.0995, 0, 0), 0.005, 1.3e-3, 0, SizeClass::grain);
  s.particles.velocity_m_s[1] = Vec3(1.0, 0, 0);
  try {
    s.advance(10000);
    FAIL() << "expected NumericalFailure";
  } catch (const NumericalFailure& e) {
    EXPECT_EQ(e.particle(), 1);
    EXPECT_NE(std::string(e.what()).find("left the container"), std::string::npos) << e.what();
  }
}

TEST(Particles, RemoveKeepsOrderAndHistories) {
  System s(no_gravity());
  for (int i = 0; i < 4; ++i) s.particles.add(Vec3(0.0099 * i, 0, 0), 0.005, 1.3e-3, 0, SizeClass::grain);
  s.step();
  EXPECT_EQ(s.stats().contacts, 3);
  s.remove_particles({false, true, false, false});
  EXPECT_EQ(s.particles.size(), 3u);
  EXPECT_DOUBLE_EQ(s.particles.position_m[1].x(), 0.0099 * 2);
  s.step();
  EXPECT_EQ(s.stats().contacts, 1);  // only the pair (2, 3) still touches
}

// Appending particles (a pour) keeps the histories of the contacts that exist: the tangential
// spring and the contact duration of a touching pair continue instead of restarting.
TEST(Particles, AppendKeepsHistories) {
  System s(no_gravity());
  s.particles.add(Vec3(0, 0, 0), 0.005, 1.3e-3, 0, SizeClass::grain);
  s.particles.add(Vec3(0.0099, 0, 0), 0.005, 1.3e-3, 0, SizeClass::grain);
  s.advance(10);
  auto pair_duration = [&] {
    const auto& l = s.neighbor_list();
    for (auto k = l.offset[0]; k < l.offset[1]; ++k)
      if (l.neighbor[k] == 1) return l.history[k].duration_s;
    return -1.0;
  };
  const double before = pair_duration();
  ASSERT_GT(before, 0.0);
  s.particles.add(Vec3(0.05, 0, 0), 0.005, 1.3e-3, 0, SizeClass::grain);
  s.particles_appended();
  s.step();
  EXPECT_EQ(s.particles.size(), 3u);
  EXPECT_EQ(s.stats().contacts, 1);
  EXPECT_NEAR(pair_duration(), before + s.config().dt_s, 1e-15);
  // invalidate() is the other way: histories are dropped and the contact starts again.
  s.invalidate();
  s.step();
  EXPECT_LT(pair_duration(), before);
}
