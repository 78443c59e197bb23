// Collision models on measurements: the term registry, fits, held-out errors, the paper's
// Table 3, and finding the missing effect on the dev campaign and on synthetic campaigns.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <tuple>
#include <vector>
#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "spec/json_schema.h"
#include "results/model/cross_validation.h"
#include "results/model/discover.h"
#include "results/model/fit.h"
#include "results/model/model_spec.h"
#include "results/model/predict.h"
#include "results/model/residual_axes.h"
#include "results/model/table3.h"
#include "results/model/synth.h"
#include "results_helpers.h"

using namespace gravsweep::results;
using gravsweep::testing::TempDir;

namespace {

const Campaign& dev() {
  static const Campaign c = load_campaign(gravsweep::testing::dev_campaign());
  return c;
}

const AxisResidual& axis(const std::vector<AxisResidual>& a, const std::string& name) {
  for (const auto& x : a)
    if (x.axis == name) return x;
  throw std::runtime_error("no axis " + name);
}

bool is_depth_friction(const std::string& t) { return t == "depth_friction" || t == "gravity_depth_friction"; }

/// A small campaign: 3 gravity levels x 6 speeds x 2 repeats = 36 trials.
SynthOptions small_synth(unsigned seed) {
  SynthOptions o;
  o.impact_speed_m_s = {0.15, 0.35, 0.55, 0.75, 0.95, 1.15};
  o.repeats = 2;
  o.seed = seed;
  return o;
}

}  // namespace

TEST(Terms, RegistryHasTheLibraryAndRejectsUnknownNames) {
  for (const char* n : {"base", "scaled_base", "depth_friction", "gravity_depth_friction", "viscous_drag",
                        "immersion_drag", "bottom_stiffening", "cohesion"})
    EXPECT_EQ(find_term(n).name, n);
  EXPECT_THROW(find_term("warp_drive"), gravsweep::ConfigError);
  const auto s = parse_model("base+depth_friction:shared");
  ASSERT_EQ(s.terms.size(), 2u);
  EXPECT_FALSE(s.terms[1].per_gravity);
  EXPECT_EQ(s.name(), "base+depth_friction:shared");
}

TEST(Terms, ModelSpecFileErrorsNameTheJsonPointer) {
  TempDir d;
  const auto f = (d.path / "spec.json").string();
  std::ofstream(f) << R"({"terms": [{"name": "base"}, {"name": "depth_friction", "shared": "yes"}]})";
  try {
    parse_model(f);
    FAIL();
  } catch (const gravsweep::spec::SpecError& e) {  // checked by schemas/model.schema.json (exit 2)
    EXPECT_NE(std::string(e.what()).find("/terms/1/shared"), std::string::npos) << e.what();
  }
  std::ofstream(f) << R"({"terms": [{"name": "base"}, {"name": "depth_friction", "shared": true}]})";
  EXPECT_EQ(parse_model(f).name(), "base+depth_friction:shared");
}

TEST(Terms, ANewTermIsAFeatureFunctionAndFitsLikeTheOthers) {
  // What a term file provides (ARCHITECTURE.md, "Collision-model terms"): a TermInfo with named
  // parameters and a feature function. Here a quadratic depth friction k2 z^2, built in the test.
  TermInfo q;
  q.name = "depth_friction_sq";
  q.params = {"k2_N_m2"};
  q.per_gravity = true;
  q.features = [](const TermContext& c, double* out) { out[0] = c.z_m * c.z_m; };
  q.typical = [](double g, double m, double) { return std::vector<double>{2.0e3 * m * g}; };
  ModelSpec truth = parse_model("base");
  truth.terms.push_back({&q, true, 1.0});
  TempDir d;
  SynthOptions o = small_synth(3);
  o.gravity_m_s2 = {9.81, 1.2};
  write_synthetic_campaign(d.str(), truth, o);
  const Campaign c = load_campaign(d.str());
  ASSERT_GE(c.trials.size(), 20u);
  const FittedModel with = fit_model(truth, c);
  // k2 recovered at 1 g within 25 % (bed spread, fluctuations and the contact ramp remain).
  EXPECT_EQ(with.column_names[4], "depth_friction_sq.k2_N_m2@g=9.81");
  EXPECT_NEAR(with.coef(4), 2.0e3 * 9.81, 0.25 * 2.0e3 * 9.81);
  const auto h0 = summarize(c, cross_validate(parse_model("base"), c, 4, 1));
  const auto h1 = summarize(c, cross_validate(truth, c, 4, 1));
  EXPECT_LT(h1.zstop_rel_pct, h0.zstop_rel_pct);
}

// A fit whose result is not finite (a trial of mass 1e308 read without the import's range check)
// throws, naming the parameters and the trial responsible, instead of returning NaN parameters.
TEST(Fit, ANonFiniteFitFailsNamingTheTrial) {
  TempDir d;
  SynthOptions o = small_synth(5);
  o.gravity_m_s2 = {9.81};
  write_synthetic_campaign(d.str(), parse_model("base"), o);
  Campaign c = load_campaign(d.str());
  ASSERT_GE(c.trials.size(), 6u);
  EXPECT_TRUE(fit_model(parse_model("base"), c).coef.allFinite());
  c.trials[2].info.projectile_mass_kg = 1e308;
  try {
    (void)fit_model(parse_model("base"), c);
    FAIL() << "a non-finite fit returned";
  } catch (const gravsweep::NumericalFailure& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("not finite"), std::string::npos) << m;
    EXPECT_NE(m.find(c.trials[2].info.trial_id), std::string::npos) << m;
    EXPECT_NE(m.find("base.f0_N"), std::string::npos) << m;
  }
}

TEST(Table3, PaperMethodGivesParametersWithUncertainties) {
  GRAVSWEEP_REQUIRE_DEV_CAMPAIGN();
  const auto rows = table3(dev());
  ASSERT_EQ(rows.size(), 3u);
  for (const auto& r : rows) {
    EXPECT_EQ(r.trials, 24);
    EXPECT_GT(r.f0_se_N, 0);
    EXPECT_GT(r.inv_d1_se_1_m, 0);
    EXPECT_GT(r.alpha_se, 0);
    // The bootstrap over drops: the order of the least-squares errors when every drop has
    // its own scatter (the dev campaign's trials are independent), reproducible (fixed seed).
    EXPECT_GT(r.f0_boot_se_N, 0.3 * r.f0_se_N);
    EXPECT_LT(r.f0_boot_se_N, 3 * r.f0_se_N);
    EXPECT_GT(r.inv_d1_boot_se_1_m, 0.3 * r.inv_d1_se_1_m);
    EXPECT_LT(r.inv_d1_boot_se_1_m, 3 * r.inv_d1_se_1_m);
  }
  EXPECT_EQ(table3(dev())[0].f0_boot_se_N, rows[0].f0_boot_se_N);
  // 1 g: f0 near the truth's 1.6 m g = 15.7 N and 1/d1 near 25 1/m, within 3 standard errors.
  EXPECT_NEAR(rows[0].f0_N, 15.7, 3 * rows[0].f0_se_N + 2);
  EXPECT_NEAR(rows[0].inv_d1_1_m, 25, 3 * rows[0].inv_d1_se_1_m);
  // Eqs. 3-4 at the Table 3 row of the paper's experiment: f0 = 25 N, 1/d1 = 25 1/m, 1 kg, 1 m/s.
  Table3Row paper;
  paper.g_m_s2 = 9.81;
  paper.f0_N = 25;
  paper.inv_d1_1_m = 25;
  const Prediction p = predict_paper(paper, 1.0, 1.0);
  EXPECT_NEAR(p.zstop_m, 0.02 * std::log(1 + 1.0 / (0.04 * 15.19)), 1e-9);
  EXPECT_NEAR(p.apeak_m_s2, 25 + 25 - 9.81, 1e-12);
}

TEST(Fit, TraceFitRecoversTheHiddenDepthFrictionOnTheDevCampaign) {
  GRAVSWEEP_REQUIRE_DEV_CAMPAIGN();
  const FittedModel m = fit_model(parse_model("base+depth_friction"), dev());
  // Truth (ANSWER.md): k = f0/lambda = 1.6 m g / 3 cm per gravity level.
  for (int gi = 0; gi < 3; ++gi) {
    const double g = m.gravity_levels[static_cast<std::size_t>(gi)];
    const double k = m.coef(6 + gi), se = std::sqrt(m.cov(6 + gi, 6 + gi));
    EXPECT_NEAR(k, 1.6 * g / 0.03, std::max(4 * se, 0.2 * 1.6 * g / 0.03)) << "g = " << g;
    EXPECT_GT(se, 0);
  }
}

TEST(Discovery, DevCampaignBaselineFailsWithDepthAndDepthFrictionWins) {
  GRAVSWEEP_REQUIRE_DEV_CAMPAIGN();
  const Discovery d = discover(dev(), parse_model("base"));
  // Where it fails: of the state axes the residual varies most with depth, growing with it (the
  // model misses a resistance that grows with depth), consistently across trials.
  const auto& z = axis(d.residual_before, "depth_m");
  for (const char* other : {"speed_m_s", "time_since_contact_s"})
    EXPECT_GT(z.eta2, axis(d.residual_before, other).eta2);
  EXPECT_GT(z.bin_mean_r_over_g.back(), z.bin_mean_r_over_g.front() + 0.5);
  EXPECT_GT(z.trials_positive, 2 * z.trials_negative);
  EXPECT_LT(z.slope_sign_trials_p, 1e-4);
  // Which effect: depth friction first and significant, counted over 72 trials.
  ASSERT_FALSE(d.rounds.empty());
  const Candidate& first = d.rounds.front().front();
  EXPECT_TRUE(is_depth_friction(first.term)) << first.term;
  EXPECT_TRUE(first.significant);
  EXPECT_EQ(first.trials, 72);
  EXPECT_LT(first.p_value, 1e-6);
  ASSERT_FALSE(d.added.empty());
  EXPECT_TRUE(is_depth_friction(d.added.front()));
  EXPECT_NE(d.verdict.find("missing effect"), std::string::npos) << d.verdict;
  EXPECT_EQ(d.verdict.find("structure left"), std::string::npos) << d.verdict;
  // At one gravity level a depth friction k z and its gravity-scaled form kappa g z are one law: the
  // held-out trials cannot tell them apart, and the verdict names both. bottom_stiffening is
  // significant too, but fits worse in most trials: it is not named.
  ASSERT_EQ(d.equivalent.size(), d.added.size());
  const std::string other = d.added.front() == "depth_friction" ? "gravity_depth_friction" : "depth_friction";
  EXPECT_NE(std::find(d.equivalent.front().begin(), d.equivalent.front().end(), other), d.equivalent.front().end());
  EXPECT_NE(d.verdict.find(", or equally well " + other), std::string::npos) << d.verdict;
  EXPECT_NE(d.verdict.find("(the held-out trials cannot tell"), std::string::npos) << d.verdict;
  EXPECT_EQ(d.verdict.find("bottom_stiffening"), std::string::npos) << d.verdict;
}

TEST(Discovery, AddingDepthFrictionCutsHeldOutZstopAndTstopErrors) {
  GRAVSWEEP_REQUIRE_DEV_CAMPAIGN();
  const auto base = summarize(dev(), cross_validate(parse_model("base"), dev(), 6, 1));
  const auto after = summarize(dev(), cross_validate(parse_model("base+depth_friction"), dev(), 6, 1));
  const auto paper = summarize(dev(), cross_validate_paper(dev(), 6, 1));
  EXPECT_LT(after.zstop_rms_mm, 0.7 * base.zstop_rms_mm);
  EXPECT_LT(after.tstop_rms_ms, 0.7 * base.tstop_rms_ms);
  EXPECT_LT(after.trace_rms_m_s2, base.trace_rms_m_s2);
  EXPECT_LT(after.zstop_rms_mm, paper.zstop_rms_mm);
  EXPECT_LT(after.tstop_rms_ms, paper.tstop_rms_ms);
}

class HiddenTerm : public ::testing::TestWithParam<std::tuple<std::string, unsigned>> {};

TEST_P(HiddenTerm, IsRankedFirstOnASyntheticCampaign) {
  const auto& [term, seed] = GetParam();
  TempDir d;
  SynthOptions o = small_synth(seed);
  if (term == "bottom_stiffening") o.fill_height_m = {0.05, 0.06, 0.08};  // shallow beds, cycled
  write_synthetic_campaign(d.str(), parse_model("base+" + term), o);
  const Campaign c = load_campaign(d.str());
  ASSERT_GE(c.trials.size(), 30u);
  const Discovery disc = discover(c, parse_model("base"), 6, 0.01, 0.03, 1);
  const Candidate& first = disc.rounds.front().front();
  if (term == "depth_friction") {
    EXPECT_TRUE(is_depth_friction(first.term)) << first.term;
  } else {
    EXPECT_EQ(first.term, term) << disc.verdict;
  }
  // The strong effects are also significant at this size (36 trials); the viscous drag, nearly
  // a mix of the baseline's constant and v^2 over a trajectory, only ranks first.
  if (term != "viscous_drag") {
    EXPECT_TRUE(first.significant) << "p = " << first.p_value;
  }
}

INSTANTIATE_TEST_SUITE_P(
    FourHiddenTermsThreeSeeds, HiddenTerm,
    ::testing::Combine(::testing::Values("depth_friction", "immersion_drag", "bottom_stiffening", "viscous_drag"),
                       ::testing::Values(11u, 12u, 13u)),
    [](const auto& info) { return std::get<0>(info.param) + "_seed" + std::to_string(std::get<1>(info.param)); });

TEST(Discovery, NothingHiddenNothingReportedIn19Of20Seeds) {
  int reported = 0;
  std::string log;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    TempDir d;
    SynthOptions o;  // full size: 72 trials, as the dev campaign
    o.seed = 100 + seed;
    write_synthetic_campaign(d.str(), parse_model("base"), o);
    const Campaign c = load_campaign(d.str());
    const Discovery disc = discover(c, parse_model("base"), 6, 0.01, 0.03, 1);
    if (!disc.added.empty() || disc.structure_left) {
      ++reported;
      log += "seed " + std::to_string(o.seed) + ": " + disc.verdict + "\n";
    }
  }
  EXPECT_LE(reported, 1) << log;
}

TEST(Terms, SchemaListsExactlyTheRegisteredTerms) {
  std::ifstream in(std::string(GRAVSWEEP_SOURCE_DIR) + "/schemas/model.schema.json");
  const auto j = nlohmann::json::parse(in);
  const auto names =
      j["properties"]["terms"]["items"]["properties"]["name"]["oneOf"][0]["enum"].get<std::vector<std::string>>();
  std::vector<std::string> reg;
  for (const auto& t : term_registry()) reg.push_back(t.name);
  EXPECT_EQ(names, reg);
}

TEST(Discovery, StructureNoCandidateExplainsIsReportedWithWhereItLies) {
  // Hidden: a resistance that grows with time since contact, not with depth or speed (a creep or
  // compaction effect outside the library). No candidate should explain it fully.
  TermInfo creep;
  creep.name = "creep";
  creep.params = {"c_N"};
  creep.per_gravity = true;
  creep.features = [](const TermContext& c, double* out) {
    out[0] = std::sin(2 * 3.14159265 * c.t_since_contact_s / 0.04);
  };
  creep.typical = [](double g, double m, double) { return std::vector<double>{1.0 * m * g}; };
  ModelSpec truth = parse_model("base");
  truth.terms.push_back({&creep, true, 1.0});
  TempDir d;
  SynthOptions o = small_synth(21);
  o.gravity_m_s2 = {9.81};
  o.impact_speed_m_s = {0.5, 0.7, 0.9, 1.1};
  o.repeats = 4;
  o.fill_height_m = {0.2};
  write_synthetic_campaign(d.str(), truth, o);
  const Campaign c = load_campaign(d.str());
  const Discovery disc = discover(c, parse_model("base"));
  // Humble: a named term may take part of it, but the verdict says what is left.
  EXPECT_TRUE(disc.verdict.find("structure left that no named term explains") != std::string::npos ||
              disc.verdict.find("partly explained by") != std::string::npos)
      << disc.verdict;
  EXPECT_NE(disc.verdict.find("structure left along time_since_contact_s"), std::string::npos) << disc.verdict;
  EXPECT_EQ(disc.verdict.find("missing effect"), std::string::npos) << disc.verdict;
  EXPECT_NE(disc.verdict.find("time_since_contact_s"), std::string::npos) << disc.verdict;
}

namespace {

/// Every held-out error of base+term below that of base, with the figures. The
/// metrics named in `within_5pct` need only stay within 5 % of base (an RMS in absolute units that
/// the trials where the term does not matter, or a few fluctuation maxima, dominate; the caller
/// says why); their relative errors must still fall.
void expect_every_error_falls(const Campaign& c, const std::string& term, const std::string& label,
                              const std::set<std::string>& within_5pct = {}) {
  const auto b = summarize(c, cross_validate(parse_model("base"), c, 6, 1));
  const auto a = summarize(c, cross_validate(parse_model("base+" + term), c, 6, 1));
  SCOPED_TRACE(label + ": base -> base+" + term);
  std::cout << label << " base -> base+" << term << ": trace " << b.trace_rel_pct << " -> " << a.trace_rel_pct
            << " % (rms " << b.trace_rms_m_s2 << " -> " << a.trace_rms_m_s2 << "), zstop " << b.zstop_rel_pct << " -> "
            << a.zstop_rel_pct << " %, tstop " << b.tstop_rel_pct << " -> " << a.tstop_rel_pct << " %, apeak "
            << b.apeak_rel_pct << " -> " << a.apeak_rel_pct << " % (rms " << b.apeak_rms_m_s2 << " -> "
            << a.apeak_rms_m_s2 << ")\n";
  auto falls = [&](const char* name, double after, double before) {
    if (within_5pct.count(name))
      EXPECT_LT(after, 1.05 * before) << name;
    else
      EXPECT_LT(after, before) << name;
  };
  falls("trace_rms", a.trace_rms_m_s2, b.trace_rms_m_s2);
  falls("zstop_rms", a.zstop_rms_mm, b.zstop_rms_mm);
  falls("tstop_rms", a.tstop_rms_ms, b.tstop_rms_ms);
  falls("apeak_rms", a.apeak_rms_m_s2, b.apeak_rms_m_s2);
  EXPECT_LT(a.trace_rel_pct, b.trace_rel_pct);
  EXPECT_LT(a.zstop_rel_pct, b.zstop_rel_pct);
  EXPECT_LT(a.tstop_rel_pct, b.tstop_rel_pct);
  EXPECT_LT(a.apeak_rel_pct, b.apeak_rel_pct);
}

}  // namespace

// On the dev campaign the held-out apeak error rose from 22 % to 28 % when depth friction was
// added while the model's apeak was the smooth peak of Eq. 1, the measured one the
// largest value of a record that fluctuates by ~20 % (1.3-2 times the smooth peak), read off the
// 500 Hz filtered record. Predicted as measured (the model's record with the other trials'
// fluctuations laid over it, processed like the trial), every relative error falls (apeak 40 ->
// 21 %). The apeak RMS in m/s2 is set by a few fluctuation maxima of 1 g trials at 1.2 m/s (one
// reads 79 m/s2, its repeats 31 and 46, both models 40): it stays within 5 %.
TEST(HeldOut, EveryErrorFallsWhenDepthFrictionIsAddedOnTheDevCampaign) {
  GRAVSWEEP_REQUIRE_DEV_CAMPAIGN();
  EXPECT_NO_FATAL_FAILURE(expect_every_error_falls(dev(), "depth_friction", "dev", {"apeak_rms"}));
}

class HiddenTermErrors : public ::testing::TestWithParam<std::string> {};

TEST_P(HiddenTermErrors, EveryHeldOutErrorFallsWhenItIsAdded) {
  const std::string term = GetParam();
  TempDir d;
  SynthOptions o = small_synth(21);
  if (term == "bottom_stiffening") o.fill_height_m = {0.05, 0.06, 0.08};  // shallow beds, cycled
  write_synthetic_campaign(d.str(), parse_model("base+" + term), o);
  const Campaign c = load_campaign(d.str());
  ASSERT_EQ(c.trials.size(), 36u);
  // Viscous drag matters at low gravity only; the trace RMS in m/s2 is the 1 g trials'.
  expect_every_error_falls(c, term, "synth",
                           term == "viscous_drag" ? std::set<std::string>{"trace_rms"} : std::set<std::string>{});
}

INSTANTIATE_TEST_SUITE_P(EachNamedTerm, HiddenTermErrors,
                         ::testing::Values("depth_friction", "gravity_depth_friction", "viscous_drag", "immersion_drag",
                                           "bottom_stiffening"));

// Cohesion (a constant force shared by all levels) is absorbed by the base's f0 per gravity level
// (its term says so): adding it cannot change any held-out error, which is why none can fall.
TEST(HeldOut, HiddenCohesionIsAbsorbedByThePerLevelFrictionSoNoErrorMoves) {
  TempDir d;
  write_synthetic_campaign(d.str(), parse_model("base+cohesion"), small_synth(21));
  const Campaign c = load_campaign(d.str());
  const auto b = summarize(c, cross_validate(parse_model("base"), c, 6, 1));
  const auto a = summarize(c, cross_validate(parse_model("base+cohesion"), c, 6, 1));
  for (const auto& [after, before] : {std::pair{a.trace_rel_pct, b.trace_rel_pct},
                                      {a.zstop_rel_pct, b.zstop_rel_pct},
                                      {a.tstop_rel_pct, b.tstop_rel_pct},
                                      {a.apeak_rel_pct, b.apeak_rel_pct}})
    EXPECT_NEAR(after, before, 0.01 * before);
}

// Two hidden terms at once are both found, in two rounds, over several seeds, and the
// search beyond the named library adds nothing to them (the verdict stays "missing effect"). 72
// trials each (3 levels x 8 speeds x 3 repeats; with 48 the second term is sometimes not significant).
TEST(Discovery, TwoHiddenTermsAreBothFoundInTwoRounds) {
  for (const auto& [first, second, fills] : std::vector<std::tuple<std::string, std::string, std::vector<double>>>{
           {"depth_friction", "viscous_drag", {0.21}}, {"bottom_stiffening", "viscous_drag", {0.05, 0.06, 0.08}}}) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
      TempDir d;
      SynthOptions o;
      o.fill_height_m = fills;
      o.seed = seed;
      write_synthetic_campaign(d.str(), parse_model("base+" + first + "+" + second), o);
      const Discovery disc = discover(load_campaign(d.str()), parse_model("base"));
      ASSERT_EQ(disc.added.size(), 2u) << first << "+" << second << " seed " << seed << ": " << disc.verdict;
      const std::set<std::string> found(disc.added.begin(), disc.added.end());
      EXPECT_TRUE(found.count(first) || (first == "depth_friction" && found.count("gravity_depth_friction")))
          << disc.verdict;
      EXPECT_TRUE(found.count(second)) << disc.verdict;
      EXPECT_EQ(disc.verdict.rfind("missing effect: ", 0), 0u) << disc.verdict;
      EXPECT_TRUE(disc.generated.empty()) << disc.verdict;
    }
  }
}

// The scaled mode: one gravity-scaled law for all levels (scaled_base: phi m g + m v^2/d1) finds a
// resistance whose size does not follow g (a constant 0.5 N cohesion, hidden in a synthetic
// campaign over four gravity levels), which the per-level baseline absorbs into each level's f0.
TEST(Discovery, TheScaledModeNamesAResistanceThatDoesNotFollowGravityThePerLevelOneMissesIt) {
  TempDir d;
  SynthOptions o = small_synth(5);
  o.gravity_m_s2 = {9.81, 1.62, 0.1, 0.01};
  o.repeats = 2;
  write_synthetic_campaign(d.str(), parse_model("base+cohesion"), o);
  const Campaign c = load_campaign(d.str());
  const Discovery scaled = discover(c, parse_model("scaled_base"), 6, 0.01, 0.03, 1, false);
  EXPECT_TRUE(scaled.gravity_scaled);
  ASSERT_EQ(scaled.added.size(), 1u) << scaled.verdict;
  EXPECT_EQ(scaled.added.front(), "cohesion") << scaled.verdict;
  const Discovery per_level = discover(c, parse_model("base"), 6, 0.01, 0.03, 1, false);
  EXPECT_FALSE(per_level.gravity_scaled);
  EXPECT_TRUE(std::find(per_level.added.begin(), per_level.added.end(), "cohesion") == per_level.added.end())
      << per_level.verdict;
  // On a Froude-scaled truth a constant term gains far less: the synthetic lab's contact ramp (1 mm)
  // and force-fluctuation time (1.5 ms) do not scale with g, and a constant picks up part of that.
  TempDir d2;
  write_synthetic_campaign(d2.str(), parse_model("base"), o);
  const Discovery scaled_truth = discover(load_campaign(d2.str()), parse_model("scaled_base"), 6, 0.01, 0.03, 1, false);
  auto gain = [](const Discovery& disc) {
    for (const auto& cd : disc.rounds.front())
      if (cd.term == "cohesion") return cd.mean_rel_improvement;
    return 0.0;
  };
  EXPECT_GT(gain(scaled), 3 * gain(scaled_truth)) << scaled.verdict << " / " << scaled_truth.verdict;
}

// Eq. 1 with R = phi m g + m v^2/d1 integrates to the closed forms tstop = T atan(vc / (g' T)) and
// zstop = d1/2 ln(1 + vc^2 / (g' d1)), g' = (phi - 1) g, T = sqrt(d1 / g'). At 0.001 m/s2 the stop
// comes 11.5 s after contact: the prediction must integrate past the 10 s that suffice at 1 g.
TEST(Predict, ADropAtOneThousandthOfAMetrePerSecondSquaredComesToRestAtTheClosedForm) {
  constexpr double kPhi = 1.6, kInvD1_1_m = 25.0, kG_m_s2 = 0.001, kVc_m_s = 0.03;
  FittedModel m;
  m.spec = parse_model("scaled_base");
  m.gravity_levels = {kG_m_s2};
  m.coef = Eigen::Vector2d(kPhi, kInvD1_1_m);
  TermContext c;
  c.g_m_s2 = kG_m_s2;
  c.vc_m_s = c.v_m_s = kVc_m_s;
  const Prediction p = predict(m, c);
  const double g_net = (kPhi - 1) * kG_m_s2, d1 = 1 / kInvD1_1_m, T = std::sqrt(d1 / g_net);
  const double tstop_s = T * std::atan(kVc_m_s / (g_net * T));
  const double zstop_m = 0.5 * d1 * std::log(1 + kVc_m_s * kVc_m_s / (g_net * d1));
  ASSERT_TRUE(p.stopped);
  EXPECT_GT(tstop_s, 10.0);
  EXPECT_NEAR(p.tstop_s, tstop_s, 1e-4 * tstop_s);
  EXPECT_NEAR(p.zstop_m, zstop_m, 1e-4 * zstop_m);
}

// The scaled mode tries every per-level term in its two gravity-scaled forms too: a depth
// stiffness that does not follow g (k z, 5.2 N/m, beside the gravity-loaded kappa g z) hidden in
// a campaign over four levels is named as such, depth_friction:shared, in at least 4 of 5 seeds,
// and the verdict leads with a term of the truth.
TEST(Discovery, TheScaledModeNamesADepthStiffnessThatDoesNotFollowGravity) {
  int named = 0, led_by_truth = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    TempDir d;
    SynthOptions o = small_synth(seed);
    o.gravity_m_s2 = {9.81, 1.62, 0.1, 0.01};
    write_synthetic_campaign(d.str(), parse_model("scaled_base+gravity_depth_friction+depth_friction:shared*0.01"), o);
    const Discovery disc = discover(load_campaign(d.str()), parse_model("scaled_base"), 6, 0.01, 0.03, 3, false);
    std::printf("seed %u: %s\n", seed, disc.verdict.c_str());
    for (const auto& round : disc.rounds)
      for (std::size_t i = 0; i < round.size() && i < 4; ++i)
        std::printf("  %s %.3f p=%.2g%s\n", round[i].term.c_str(), round[i].mean_rel_improvement, round[i].p_value,
                    round[i].significant ? " *" : "");
    named += std::count(disc.added.begin(), disc.added.end(), "depth_friction:shared") > 0 ? 1 : 0;
    led_by_truth += !disc.added.empty() && (disc.added.front() == "depth_friction:shared" ||
                                            disc.added.front() == "gravity_depth_friction")
                        ? 1
                        : 0;
    if (!disc.added.empty()) EXPECT_EQ(disc.named_model.rfind("scaled_base+", 0), 0u) << disc.named_model;
  }
  EXPECT_GE(named, 4);
  EXPECT_GE(led_by_truth, 4);
}
