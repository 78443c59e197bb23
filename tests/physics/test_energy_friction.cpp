// Energy conservation, sliding friction and rolling resistance against closed-form theory.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "physics_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;

namespace {

/// A bead resting on (or above) a horizontal plane at z = 0, gravity 9.81 m/s2 down.
std::unique_ptr<System> bead_on_floor(SystemConfig cfg, double height_m) {
  cfg.gravity_m_s2 = Vec3(0, 0, -9.81);
  auto s = std::make_unique<System>(std::move(cfg));
  s->particles.add(Vec3(0, 0, kBeadRadius_m + height_m), kBeadRadius_m, bead_mass_kg(), 0, SizeClass::grain);
  s->walls.push_back(Wall::plane("floor", Vec3::Zero(), Vec3::UnitZ(), 1));
  s->initialize();
  return s;
}

}  // namespace

class EnergyTest : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

// e = 1 and mu = 0: total energy (kinetic + gravitational) between contacts stays within 1e-4 of
// its initial value over 10 bounces, for every integrator.
TEST_P(EnergyTest, ConservedOverTenCollisions) {
  const auto [law, integrator] = GetParam();
  auto cfg = two_material_config(law, 1.0, 0.0);
  cfg.integrator = integrator;
  auto sp = bead_on_floor(cfg, 0.02);
  System& s = *sp;
  const double e0 = s.kinetic_energy_J() + s.potential_energy_J();
  const double scale = bead_mass_kg() * 9.81 * 0.02;  // energy relative to the floor
  int collisions = 0;
  bool in_contact = false;
  double worst = 0;
  while (collisions < 10 && s.time_s() < 3.0) {
    s.step();
    const bool touching = s.stats().wall_contacts > 0;
    if (touching && !in_contact) ++collisions;
    in_contact = touching;
    if (!touching) worst = std::max(worst, std::abs(s.kinetic_energy_J() + s.potential_energy_J() - e0) / scale);
  }
  EXPECT_EQ(collisions, 10);
  EXPECT_LT(worst, 1e-4) << law << " + " << integrator;
}

INSTANTIATE_TEST_SUITE_P(Integrators, EnergyTest,
                         ::testing::Values(std::make_tuple("hertz", "semi_implicit_euler"),
                                           std::make_tuple("hertz", "velocity_verlet"),
                                           std::make_tuple("hertz", "leapfrog_kdk"),
                                           std::make_tuple("hooke", "leapfrog_kdk"),
                                           std::make_tuple("hooke", "velocity_verlet")));

class SlideToRollTest : public ::testing::TestWithParam<std::string> {};

// A sphere launched sliding without spin ends rolling at 5/7 of its initial speed (within 1 %).
TEST_P(SlideToRollTest, EndsAtFiveSevenths) {
  const std::string law = GetParam();
  auto cfg = two_material_config(law, 0.9, 0.3);
  // pkdgrav with eps_t = 1 (C_T = 0) resets the spring on slip and then applies no force for the
  // step; when one step's spring increment exceeds the Coulomb cap (0.5 m/s here) it never applies
  // any: sliding is frictionless. With eps_t < 1 the slip force is min(mu |F_N|, C_T |u_T|).
  for (auto& m : cfg.materials) m.cor_tangential = 0.5;
  auto sp = bead_on_floor(cfg, 0.0);
  System& s = *sp;
  s.advance(2000);  // let the normal contact come to rest
  const double v0 = 0.5;
  s.particles.velocity_m_s[0] = Vec3(v0, 0, 0);
  s.particles.omega_rad_s[0].setZero();
  // Sliding lasts 2 v0 / (7 mu g) = 0.049 s; run 0.15 s.
  s.advance(static_cast<long long>(0.15 / s.config().dt_s));
  const double v = s.particles.velocity_m_s[0].x();
  const double slip = v - kBeadRadius_m * s.particles.omega_rad_s[0].y();
  EXPECT_NEAR(v / v0, 5.0 / 7.0, 0.01 * 5.0 / 7.0) << law;
  EXPECT_LT(std::abs(slip), 1e-3 * v0) << "still slipping";
}

INSTANTIATE_TEST_SUITE_P(Laws, SlideToRollTest, ::testing::Values("hertz", "hooke"));

namespace {
/// Fits dv/dt of the rolling bead between 80 % and 20 % of its initial speed.
double rolling_deceleration(System& s, double v0) {
  s.particles.velocity_m_s[0] = Vec3(v0, 0, 0);
  s.particles.omega_rad_s[0] = Vec3(0, v0 / kBeadRadius_m, 0);
  std::vector<double> t, v;
  while (s.particles.velocity_m_s[0].x() > 0.2 * v0 && s.time_s() < 5.0) {
    s.step();
    const double vx = s.particles.velocity_m_s[0].x();
    if (vx < 0.8 * v0 && s.step_count() % 100 == 0) {
      t.push_back(s.time_s());
      v.push_back(vx);
    }
  }
  // Least-squares slope.
  double mt = 0, mv = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    mt += t[k];
    mv += v[k];
  }
  mt /= static_cast<double>(t.size());
  mv /= static_cast<double>(t.size());
  double stv = 0, stt = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    stv += (t[k] - mt) * (v[k] - mv);
    stt += (t[k] - mt) * (t[k] - mt);
  }
  return -stv / stt;
}
}  // namespace

// Chrono/Sunday rolling torque mu_r F_n R: a rolling sphere decelerates at (5/7) mu_r g (within 5 %).
TEST(RollingFriction, SundayDecelerationMatchesTheory) {
  auto cfg = two_material_config("hertz", 0.9, 0.3, "sunday");
  for (auto& m : cfg.materials) m.mu_rolling = 0.09;
  auto sp = bead_on_floor(cfg, 0.0);
  System& s = *sp;
  s.advance(2000);
  const double a = rolling_deceleration(s, 0.2);
  EXPECT_NEAR(a, 5.0 / 7.0 * 0.09 * 9.81, 0.05 * 5.0 / 7.0 * 0.09 * 9.81);
}

// pkdgrav/Zhang rolling slider M_R <= mu_r beta R |F_N|: deceleration (5/7) mu_r beta g (within 5 %).
TEST(RollingFriction, ZhangDecelerationMatchesTheory) {
  auto cfg = two_material_config("hooke", 0.9, 1.0, "zhang");
  for (auto& m : cfg.materials) {
    m.mu_rolling = 1.05;
    m.shape_beta = 0.05;
    m.mu_twisting = 1.3;
  }
  auto sp = bead_on_floor(cfg, 0.0);
  System& s = *sp;
  s.advance(4000);
  const double a = rolling_deceleration(s, 0.2);
  const double expect = 5.0 / 7.0 * 1.05 * 0.05 * 9.81;
  EXPECT_NEAR(a, expect, 0.05 * expect);
}

// Without rolling resistance the sphere keeps rolling (the control for the two tests above).
TEST(RollingFriction, NoneKeepsRolling) {
  auto sp = bead_on_floor(two_material_config("hertz", 0.9, 0.3, "none"), 0.0);
  System& s = *sp;
  s.advance(2000);
  s.particles.velocity_m_s[0] = Vec3(0.2, 0, 0);
  s.particles.omega_rad_s[0] = Vec3(0, 0.2 / kBeadRadius_m, 0);
  s.advance(100000);
  EXPECT_NEAR(s.particles.velocity_m_s[0].x(), 0.2, 1e-3);
}
