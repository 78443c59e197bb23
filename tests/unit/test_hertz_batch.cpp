// The batched (vectorised) hertz + sunday pair kernel against the scalar reference
// (HertzChrono::evaluate then RollingSunday::apply) on random contacts that cover every branch:
// new and old contacts, sticking and Coulomb slip, rolling gate closed and open, rolling and
// spinning speeds below and above the thresholds, unequal radii, a fixed body (infinite mass).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "engine/system/hertz_batch.h"
#include "engine/contact/hertz_chrono.h"
#include "engine/rolling/rolling_none.h"
#include "engine/rolling/rolling_sunday.h"
#include "engine/rolling/rolling_zhang.h"
#include "engine/contact/hooke_pkdgrav.h"
#include "engine/system/force_loop.h"
#include "engine/scenario/paper_params.h"

using namespace gravsweep;

namespace {

struct Case {
  ContactGeometry g;
  ContactHistory h;
};

/// Relative difference of two vectors, scaled by the larger norm (absolute below `floor`).
double rel(const Vec3& a, const Vec3& b, double floor) {
  return (a - b).norm() / std::max({a.norm(), b.norm(), floor});
}

/// How often each branch of the kernel was taken while the batch and the scalar kernel were compared.
struct Branches {
  int slipping = 0, rolling_on = 0, fresh = 0, gated = 0, slow = 0;
};

/// Compares the batched kernel with the scalar one contact by contact (the comparisons assert);
/// returns the branches visited, for the test to check that each one was.
template <class Rolling>
Branches compare(bool rolling) {
  PairCoefficients pc = compose_pair(chrono_table1_config().materials[0], chrono_table1_config().materials[0], nullptr);
  pc.mu_rolling = 0.09;
  pc.mu_twisting = 0.05;
  HertzChrono::prepare(pc);
  ContactOptions opt;
  const double dt = 1e-6;
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
  int slipping = 0, rolling_on = 0, fresh = 0, gated = 0, slow = 0;
  for (int round = 0; round < 40; ++round) {
    HertzBatch batch;
    Case cases[HertzBatch::kSize];
    for (int b = 0; b < HertzBatch::kSize; ++b) {
      Case& cs = cases[b];
      const double r1 = 0.005 * (1 + 0.05 * u(rng)), r2 = (b % 7 == 0 ? 0.05 : 0.005) * (1 + 0.05 * u(rng));
      const double m1 = 2480 * 4.0 / 3 * kPi * r1 * r1 * r1, m2 = 2480 * 4.0 / 3 * kPi * r2 * r2 * r2;
      const Vec3 dir = Vec3(u(rng), u(rng), u(rng)).normalized();
      const double overlap = std::pow(10.0, -7 + 3 * u01(rng));
      const Vec3 d = (r1 + r2 - overlap) * dir;
      const double scale_v = b % 5 == 0 ? 1e-6 : 0.1;  // some below the 1e-4 thresholds
      const Vec3 v1 = scale_v * Vec3(u(rng), u(rng), u(rng)), v2 = scale_v * Vec3(u(rng), u(rng), u(rng));
      const Vec3 w1 = scale_v / r1 * Vec3(u(rng), u(rng), u(rng));
      const Vec3 w2 = scale_v / r2 * Vec3(u(rng), u(rng), u(rng));
      const bool fixed2 = b % 11 == 0;
      const double m_eff = fixed2 ? m1 : m1 * m2 / (m1 + m2);
      ContactHistory& h = cs.h;
      h.active = b % 9 != 0;
      if (h.active) {
        h.shear_m = std::pow(10.0, -9 + 4 * u01(rng)) * Vec3(u(rng), u(rng), u(rng));
        h.gate_s = 1e-5;
        h.duration_s = b % 3 == 0 ? 5e-6 : 2e-5;  // gate closed / open
      }
      ContactGeometry& g = cs.g;
      const double dist = d.norm();
      g.n = d / dist;
      g.overlap_m = r1 + r2 - dist;
      g.distance_m = dist;
      g.r1_m = r1;
      g.r2_m = r2;
      g.R_eff_m = r1 * r2 / (r1 + r2);
      g.m_eff_kg = m_eff;
      g.v1 = v1;
      g.v2 = v2;
      g.w1 = w1;
      g.w2 = w2;
      g.wall = false;
      batch.add(b, 0, 1, d, d.squaredNorm(), r1, r2, m_eff, v1, v2, w1, w2, pc, h);
    }
    if (rolling)
      batch.compute<true>(opt, dt);
    else
      batch.compute<false>(opt, dt);
    for (int b = 0; b < HertzBatch::kSize; ++b) {
      Case& cs = cases[b];
      fresh += !cs.h.active;
      ContactForce out;
      FrameHistory fh;
      HertzChrono::evaluate(cs.g, pc, opt, cs.h, fh, dt, out);
      Rolling::apply(cs.g, pc, opt, cs.h, fh, dt, out);
      const Vec3 f(batch.fx[b], batch.fy[b], batch.fz[b]);
      const Vec3 t1(batch.t1x[b], batch.t1y[b], batch.t1z[b]);
      const Vec3 t2(batch.t2x[b], batch.t2y[b], batch.t2z[b]);
      const Vec3 s(batch.sx[b], batch.sy[b], batch.sz[b]);
      // A torque is a lever r n crossed with a force nearly along n: its rounding error is
      // relative to r |f|, not to the (possibly much smaller) torque itself.
      const double f_scale = out.force_on_2.norm() + 1e-30;
      EXPECT_LT(rel(f, out.force_on_2, 1e-30), 1e-12) << "contact " << b << " round " << round;
      EXPECT_LT(rel(t1, out.torque_1, f_scale * cs.g.r1_m), 1e-12) << "contact " << b;
      EXPECT_LT(rel(t2, out.torque_2, f_scale * cs.g.r2_m), 1e-12) << "contact " << b;
      EXPECT_LT(rel(s, cs.h.shear_m, 1e-30), 1e-12) << "contact " << b;
      EXPECT_EQ(batch.duration[b], cs.h.duration_s) << "contact " << b;
      EXPECT_EQ(batch.gate[b], cs.h.gate_s) << "contact " << b;
      EXPECT_NEAR(batch.overlap[b], cs.g.overlap_m, 1e-15);
      const Vec3 tang = out.force_on_2 - out.force_on_2.dot(cs.g.n) * cs.g.n;
      slipping += tang.norm() >= pc.mu_static * std::abs(out.normal_force_N) * (1 - 1e-9);
      gated += cs.h.duration_s <= cs.h.gate_s;
      rolling_on +=
          cs.h.duration_s > cs.h.gate_s && (out.torque_1 - cs.g.r1_m * cs.g.n.cross(-out.force_on_2)).norm() > 0;
      slow += cs.g.v1.norm() < 1e-5;
    }
  }
  return Branches{slipping, rolling_on, fresh, gated, slow};
}

/// Every branch was visited often (slip, fresh contact, activation gate, slow contact, rolling).
void expect_every_branch(const Branches& b, bool rolling) {
  EXPECT_GT(b.slipping, 50);
  EXPECT_GT(b.fresh, 50);
  EXPECT_GT(b.gated, 50);
  EXPECT_GT(b.slow, 50);
  if (rolling) {
    EXPECT_GT(b.rolling_on, 50);
  }
}

}  // namespace

TEST(HertzBatch, MatchesScalarKernelWithSundayRolling) {
  Branches b;
  EXPECT_NO_FATAL_FAILURE(b = compare<RollingSunday>(true));
  EXPECT_GT(b.rolling_on, 50);  // the rolling branch is what this case adds
  expect_every_branch(b, true);
}

TEST(HertzBatch, MatchesScalarKernelWithoutRolling) {
  Branches b;
  EXPECT_NO_FATAL_FAILURE(b = compare<RollingNone>(false));
  EXPECT_GT(b.slipping, 50);
  expect_every_branch(b, false);
}

TEST(HertzBatch, CoversThePaperModels) {
  EXPECT_TRUE((kHasBatch<HertzChrono, RollingSunday>));
  EXPECT_TRUE((kHasBatch<HertzChrono, RollingNone>));
  EXPECT_FALSE((kHasBatch<HertzChrono, RollingZhang>)) << "the Zhang springs need the scalar kernel";
  EXPECT_FALSE((kHasBatch<HookePkdgrav, RollingSunday>)) << "a law without a Batch";
}
