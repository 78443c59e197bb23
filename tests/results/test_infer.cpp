// What one impact says about the ground (results/model/infer.h, `gravsweep model infer`): on
// synthetic single drops of a known truth (constants drawn from the prior, metrics from the law
// with log-normal noise of the law's form error) the 95 % intervals cover the truth; a stopping
// depth alone at a high Froude number constrains the drag and not the quasi-static constant, and
// the verb says so instead of printing a number.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "results/model/infer.h"
#include "results/model/law.h"
#include "results/model/model.h"
#include "results_helpers.h"

namespace gravsweep::results {
namespace {

constexpr double kZstopPct = 5.0, kTstopPct = 8.0, kApeakPct = 20.0;

/// A law with known constants (phi, 1/d1, kappa of Sunday et al. 2022's scaled law at about the
/// sweep's values) and a flat form error, fitted over 0.001-9.81 m/s2 and Fr 0.2-10.
SavedLaw known_law() {
  SavedLaw s;
  s.model = "scaled_base+gravity_depth_friction";
  s.constants = {"scaled_base.phi", "scaled_base.inv_d1_1_m", "gravity_depth_friction.kappa_kg_m"};
  s.values = {0.7, 14.5, 31.6};
  s.covariance.assign(3, std::vector<double>(3, 0.0));
  for (double fr : {0.2, 1.0, 10.0}) s.form_error.push_back({fr, 10, kZstopPct, kTstopPct, kApeakPct});
  s.form_error_source = "synthetic";
  s.gravity_m_s2 = {0.001, 9.81};
  s.froude = {0.2, 10.0};
  s.diameter_m = {0.1, 0.1};
  s.mass_kg = {1.0, 1.0};
  s.grain_diameter_m = {0.01, 0.01};
  s.trials = 30;
  s.levels = 3;
  return s;
}

Prediction truth_prediction(const SavedLaw& law, const std::vector<double>& truth, const LawCase& c) {
  FittedModel m = law_model(law);
  for (std::size_t i = 0; i < truth.size(); ++i) m.coef[static_cast<Eigen::Index>(i)] = truth[i];
  return predict(m, law_case_context(law, c));
}

TEST(Infer, SyntheticDropsOfAKnownTruthAreCoveredByTheirIntervals) {
  const SavedLaw law = known_law();
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01;
  int covered = 0, intervals = 0, cases = 0;
  const std::vector<std::pair<double, double>> design = {{9.81, 0.5}, {9.81, 2.0}, {0.1, 1.0},
                                                         {0.1, 5.0},  {0.01, 0.5}, {0.01, 8.0}};
  for (int rep = 0; rep < 2; ++rep)
    for (const auto& [g, fr] : design) {
      std::vector<double> truth;
      for (double v : law.values) truth.push_back(v * std::exp(std::log(kInferPriorWidth) * n01(rng)));
      const LawCase c{g, fr * std::sqrt(g * 0.1), 0.1, 1.0};
      const Prediction p = truth_prediction(law, truth, c);
      ASSERT_TRUE(p.stopped);
      InferMeasurement m;
      m.zstop_m = p.zstop_m * std::exp(kZstopPct / 100 * n01(rng));
      m.tstop_s = p.tstop_s * std::exp(kTstopPct / 100 * n01(rng));
      m.apeak_m_s2 = p.apeak_m_s2 * std::exp(kApeakPct / 100 * n01(rng));
      InferOptions o;
      o.samples = 1000;
      o.seed = static_cast<unsigned>(10 * rep + cases);
      const Inference r = infer_ground(law, c, m, o);
      ++cases;
      for (std::size_t i = 0; i < truth.size(); ++i) {
        const auto& k = r.constants[i];
        if (!k.constrained) continue;
        ++intervals;
        const bool in = truth[i] >= k.lo && truth[i] <= k.hi;
        covered += in ? 1 : 0;
        if (!in)
          std::printf("g %.3g Fr %.2g: %s truth %.4g outside %.4g-%.4g\n", g, fr, k.name.c_str(), truth[i], k.lo, k.hi);
      }
    }
  std::printf("%d of %d constrained intervals cover the truth (%d drops)\n", covered, intervals, cases);
  ASSERT_GE(intervals, cases) << "at least one constant per drop is constrained by its three metrics";
  EXPECT_GE(covered, 0.9 * intervals);
}

TEST(Infer, ADepthAloneAtHighFroudeNumberConstrainsTheDragAndNotTheQuasiStaticConstant) {
  const SavedLaw law = known_law();
  const LawCase c{0.01, 8.0 * std::sqrt(0.01 * 0.1), 0.1, 1.0};
  InferMeasurement m;
  m.zstop_m = truth_prediction(law, law.values, c).zstop_m * 0.9;
  InferOptions o;
  o.samples = 1000;
  const Inference r = infer_ground(law, c, m, o);
  ASSERT_EQ(r.constants.size(), 3u);
  EXPECT_FALSE(r.constants[0].constrained) << "phi: shrink " << r.constants[0].shrink;
  EXPECT_TRUE(r.constants[1].constrained) << "1/d1: shrink " << r.constants[1].shrink;
  EXPECT_GT(r.constants[1].median, law.values[1]) << "a shallower stop asks for more drag";
  EXPECT_FALSE(r.constants[2].constrained) << "kappa: shrink " << r.constants[2].shrink;
  // The posterior reproduces the measurement.
  EXPECT_LT(r.metrics[0].lo, m.zstop_m);
  EXPECT_GT(r.metrics[0].hi, m.zstop_m);
}

TEST(Infer, TheVerbSaysWhatOneImpactCannotConstrainAndRefusesFarOutsideTheRanges) {
  gravsweep::testing::TempDir d;
  const std::string file = d.str() + "/law.json";
  write_law(file, known_law());
  const std::string law = " --law '" + file + "'";
  const double v = 8.0 * std::sqrt(0.01 * 0.1);
  auto r = gravsweep::testing::run_gravsweep(
      "model infer" + law + " --gravity 0.01 --speed " + std::to_string(v) + " --zstop 0.08 --samples 600", true);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("scaled_base.phi"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("no: one impact does not constrain it"), std::string::npos) << r.out;
  r = gravsweep::testing::run_gravsweep("model infer" + law + " --gravity 1e-7 --speed 0.001 --zstop 0.08", true);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("refused"), std::string::npos) << r.out;
  r = gravsweep::testing::run_gravsweep("model infer" + law + " --gravity 0.01 --speed 0.2", true);
  EXPECT_EQ(r.code, 2) << "no --zstop: a usage error: " << r.out;
  EXPECT_NE(r.out.find("--zstop"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace gravsweep::results
