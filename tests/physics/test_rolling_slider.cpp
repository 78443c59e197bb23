// The rolling and twisting sliders of the pkdgrav / Zhang model (engine/rolling/rolling_zhang.h)
// never do net positive work: a slider can give back at most the energy its spring holds at the
// limit. The limit falls with |F_N|; a spring loaded to the limit and then left beyond a lower one
// must not keep pushing at that limit while the motion unloading it goes on.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/rolling/rolling_zhang.h"

using namespace gravsweep;

namespace {

constexpr double kRadius_m = 0.005;
constexpr double kDt_s = 2e-6;
constexpr double kSpin_rad_s = 5.0;  ///< spin of the grain about the contact's normal or tangent

/// A grain on a floor (body 2 a wall, normal +z), Table 1 pkdgrav springs, no damping (e_t = 1,
/// and the normal dashpot set to 0 so that only the springs and sliders act).
struct FloorContact {
  ContactGeometry g{};
  PairCoefficients pc{};
  ContactOptions options{};
  ContactHistory h{};
  FrameHistory fh{};
  FloorContact() {
    g.n = Vec3::UnitZ();
    g.r1_m = kRadius_m;
    g.distance_m = kRadius_m;
    g.wall = true;
    g.w2 = Vec3::Zero();
    pc.mu_static = 1.0;
    pc.mu_rolling = 1.05;
    pc.mu_twisting = 1.3;
    pc.shape_beta = 0.05;
  }
  /// One step at normal force fn_N with the grain spinning at w1_rad_s; returns the torque on the grain.
  Vec3 step(double fn_N, const Vec3& w1_rad_s) {
    g.w1 = w1_rad_s;
    ContactForce out;
    out.kn_N_m = 7.48e5;
    out.kt_N_m = 213714;
    out.normal_force_N = fn_N;
    out.lever1_m = kRadius_m;
    RollingZhang::apply(g, pc, options, h, fh, kDt_s, out);
    return out.torque_1;
  }
  /// Loads the spring along the grain's spin `axis` (unit) to the limit at normal force fn_N,
  /// then lowers the force to fn_N / 4 and turns the spin around (the motion that unloads the
  /// spring) for `turn_rad`; returns the work the torque did on the grain during that second part.
  double work_after_the_limit_fell(double fn_N, const Vec3& axis, double turn_rad) {
    for (int s = 0; s < 20000; ++s) step(fn_N, -kSpin_rad_s * axis);  // 0.2 rad: far past the limit
    double work_J = 0;
    const Vec3 w1 = kSpin_rad_s * axis;
    for (double turned = 0; turned < turn_rad; turned += kSpin_rad_s * kDt_s)
      work_J += step(0.25 * fn_N, w1).dot(w1) * kDt_s;
    return work_J;
  }
};

/// Energy of a spring of stiffness k held at the torque limit M: M^2 / (2 k).
double energy_at_limit_J(double limit_N_m, double k_N_m_rad) { return 0.5 * limit_N_m * limit_N_m / k_N_m_rad; }

}  // namespace

// Twisting about the floor's normal (k_Q = 2 k_T (beta Rbar)^2, M_Q <= mu_t mu_s beta Rbar |F_N|):
// after the limit falls to a quarter, turning back by 1 rad releases at most the spring's energy
// at the new limit. Undoing the increment alone kept the spring at 4x the new limit and the torque
// pushing along the spin for the whole turn (about 10^4 times that energy).
TEST(ZhangSlider, TwistingSpringGivesBackNoMoreThanItHolds) {
  FloorContact c;
  const double fn_N = 0.05;
  const double bR = c.pc.shape_beta * kRadius_m;
  const double kQ = 2 * 213714 * bR * bR;
  const double limit = 0.25 * fn_N * c.pc.mu_twisting * c.pc.mu_static * bR;
  const double work_J = c.work_after_the_limit_fell(fn_N, Vec3::UnitZ(), 1.0);
  EXPECT_LE(work_J, 1.01 * energy_at_limit_J(limit, kQ)) << "the twisting slider did positive work";
  EXPECT_LE(std::abs(kQ * c.fh.twist_rad), limit * (1 + 1e-12)) << "the spring stays within its limit";
}

// The same for the rolling spring (k_R = k_N (beta Rbar)^2, M_R <= mu_r beta Rbar |F_N|), rolling
// about a tangent of the floor.
TEST(ZhangSlider, RollingSpringGivesBackNoMoreThanItHolds) {
  FloorContact c;
  const double fn_N = 0.05;
  const double bR = c.pc.shape_beta * kRadius_m;
  const double kR = 7.48e5 * bR * bR;
  const double limit = 0.25 * fn_N * c.pc.mu_rolling * bR;
  const double work_J = c.work_after_the_limit_fell(fn_N, Vec3::UnitX(), 1.0);
  EXPECT_LE(work_J, 1.01 * energy_at_limit_J(limit, kR)) << "the rolling slider did positive work";
  EXPECT_LE(kR * c.fh.roll_rad.norm(), limit * (1 + 1e-12)) << "the spring stays within its limit";
}
