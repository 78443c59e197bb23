// The scaling check of a gravity-scaled law (results/model/scaling.h) on synthetic campaigns over
// four gravity levels (9.81 to 0.01 m/s2, speeds by Froude number 0.3-4, two repeats), five
// seeds each: a hidden drag constant that scales as g^p is reported with p inside its 95 %
// interval, and a Froude-scaled truth is reported as scaling as assumed, each in at least 4 of 5
// seeds. Also the pieces it rests on: one parameter of a term as a term of its own, the g^p
// sharing, and the refusal of a law with per-level terms.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "results/measurements/campaign.h"
#include "results/model/fit.h"
#include "results/model/model_spec.h"
#include "results/model/scaling.h"
#include "results/model/synth.h"
#include "results_helpers.h"

namespace gravsweep::results {
namespace {

using gravsweep::testing::TempDir;

/// Bootstrap resamples in the tests: enough for a 95 % interval of a power (its ends move by a
/// few hundredths between 100 and 1000 resamples on these campaigns).
constexpr int kTestResamples = 100;
constexpr int kSeeds = 5;

/// Four levels over three decades, speeds by Froude number, two repeats: 40 trials.
Campaign four_level_campaign(const std::string& truth, unsigned seed, const TempDir& d) {
  SynthOptions o;
  o.gravity_m_s2 = {9.81, 1.62, 0.1, 0.01};
  o.froude = {0.3, 0.6, 1.0, 2.0, 4.0};
  o.repeats = 2;
  o.seed = seed;
  const std::string dir = (d.path / ("c" + std::to_string(seed))).string();
  write_synthetic_campaign(dir, parse_model(truth), o);
  return load_campaign(dir);
}

const ScalingRow& row_of(const ScalingCheck& r, const std::string& constant) {
  for (const auto& row : r.rows)
    if (row.constant == constant) return row;
  throw std::runtime_error("no row " + constant);
}

void print(const ScalingCheck& r, unsigned seed) {
  for (const auto& row : r.rows)
    std::printf("seed %u: %s p = %.3f [%.3f, %.3f]%s\n", seed, row.constant.c_str(), row.power, row.power_lo,
                row.power_hi, row.differs ? " differs" : "");
  std::printf("seed %u verdict: %s\n", seed, r.verdict.c_str());
}

const std::string kLaw = "scaled_base+gravity_depth_friction";

}  // namespace

TEST(Scaling, OneParameterOfATermIsATermOfItsOwn) {
  const ModelSpec s = parse_model("scaled_base.phi+scaled_base.inv_d1_1_m:g^0.25");
  ASSERT_EQ(s.terms.size(), 2u);
  EXPECT_EQ(s.terms[0].term->params, std::vector<std::string>{"phi"});
  EXPECT_TRUE(s.terms[1].g_scaled());
  EXPECT_DOUBLE_EQ(s.terms[1].g_power, 0.25);
  EXPECT_TRUE(one_law_for_all_levels(s));
  EXPECT_EQ(s.name(), "scaled_base.phi+scaled_base.inv_d1_1_m:g^0.25");
  // The split law is the law: the same force at any state.
  TermContext c;
  c.z_m = 0.02, c.v_m_s = 0.7, c.g_m_s2 = 0.1, c.mass_kg = 1, c.diameter_m = 0.1;
  const FittedModel whole = truth_model(parse_model(kLaw), {9.81, 0.1}, 1, 0.1);
  const FittedModel split = truth_model(split_parameters(parse_model(kLaw)), {9.81, 0.1}, 1, 0.1);
  EXPECT_DOUBLE_EQ(whole.force(c), split.force(c));
  EXPECT_THROW(parse_model("scaled_base.nope"), ConfigError);
  EXPECT_THROW(parse_model("scaled_base:g^x"), std::invalid_argument);
  EXPECT_THROW(parse_model("scaled_base:g^9"), std::invalid_argument);
}

TEST(Scaling, ALawWithPerLevelTermsOrTooFewLevelsIsRefused) {
  TempDir d;
  SynthOptions o;
  o.gravity_m_s2 = {9.81, 0.1};
  o.repeats = 1;
  write_synthetic_campaign((d.path / "two").string(), parse_model("scaled_base"), o);
  const Campaign two = load_campaign((d.path / "two").string());
  EXPECT_THROW(scaling_check(parse_model("scaled_base"), two), std::invalid_argument);
  EXPECT_THROW(scaling_check(parse_model("base"), two), std::invalid_argument);
}

// A drag constant that scales as g^p (p = -0.2, 0.25, 0.45): the check reports 1/d1 as not scaling as
// assumed, with the true p inside its interval, and suggests the law with it carried by g^p.
TEST(Scaling, AHiddenPowerOfGInTheDragIsReportedWithItsPower) {
  TempDir d;
  for (double p : {-0.2, 0.25, 0.45}) {
    const std::string truth =
        "scaled_base.phi+scaled_base.inv_d1_1_m:g^" + std::to_string(p) + "+gravity_depth_friction";
    int found = 0, quiet_others = 0;
    for (unsigned seed = 1; seed <= kSeeds; ++seed) {
      const ScalingCheck r = scaling_check(parse_model(kLaw), four_level_campaign(truth, seed, d), kTestResamples);
      print(r, seed);
      const ScalingRow& drag = row_of(r, "scaled_base.inv_d1_1_m");
      found += drag.differs && drag.power_lo <= p && p <= drag.power_hi ? 1 : 0;
      quiet_others += !row_of(r, "scaled_base.phi").differs && !row_of(r, "gravity_depth_friction").differs ? 1 : 0;
      if (drag.differs) EXPECT_NE(r.suggested_model.find("scaled_base.inv_d1_1_m:g^"), std::string::npos);
    }
    EXPECT_GE(found, kSeeds - 1) << "p = " << p;
    EXPECT_GE(quiet_others, kSeeds - 1) << "p = " << p << ": the other constants scale as assumed";
  }
}

// A Froude-scaled truth (every constant the same at every level): nothing reported.
TEST(Scaling, AFroudeScaledTruthScalesAsAssumed) {
  TempDir d;
  int quiet = 0;
  for (unsigned seed = 1; seed <= kSeeds; ++seed) {
    const ScalingCheck r = scaling_check(parse_model(kLaw), four_level_campaign(kLaw, seed, d), kTestResamples);
    print(r, seed);
    bool any = false;
    for (const auto& row : r.rows) any = any || row.differs;
    quiet += any ? 0 : 1;
    if (!any) EXPECT_TRUE(r.suggested_model.empty());
  }
  EXPECT_GE(quiet, kSeeds - 1);
}

}  // namespace gravsweep::results
