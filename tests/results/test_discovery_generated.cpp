// Discovery beyond the named library: generated forms parse and fit like
// named terms; a hidden effect outside the library gets a humble verdict ("partly explained" /
// "structure left"), and the search over the generated family names its form in most seeds; on
// campaigns with nothing hidden the search reports nothing.
#include <gtest/gtest.h>

#include "engine/core/error.h"

#include <algorithm>
#include <iostream>
#include <set>
#include <string>

#include "results/model/generated.h"
#include "results/model/discover.h"
#include "results/model/model_spec.h"
#include "results/model/synth.h"
#include "results_helpers.h"

using namespace gravsweep::results;
using gravsweep::testing::TempDir;

namespace {

/// 2 gravity levels x 8 speeds x 3 repeats = 48 trials of `truth` (a model spec), ranked from base
/// (with 24 trials a hidden form of this size is often not significant: too few trials).
Discovery rank_hidden(const std::string& truth, unsigned seed) {
  TempDir d;
  SynthOptions o;
  o.gravity_m_s2 = {9.81, 1.2};
  o.seed = seed;
  write_synthetic_campaign(d.str(), parse_model(truth), o);
  return discover(load_campaign(d.str()), parse_model("base"));
}

}  // namespace

TEST(GeneratedTerms, FormsHaveOneCanonicalNameAndParseInModelSpecs) {
  EXPECT_EQ(find_term("v^1*z^1").name, "z^1*v^1");
  EXPECT_EQ(&find_term("z^1.0*v^1"), &find_term("z^1*v^1")) << "one term per form";
  EXPECT_EQ(canonical_generated_name("exp(-z/0.010)*v^2"), "v^2*exp(-z/0.01)");
  EXPECT_EQ(canonical_generated_name("depth_friction"), "");
  EXPECT_TRUE(find_term("(1-exp(-z/0.02))").generated);
  EXPECT_FALSE(find_term("depth_friction").generated);
  EXPECT_EQ(generated_words("z^1*(1-exp(-z/0.02))"),
            "depth to the power 1 times a rise with depth saturating over 20 mm");
  // In a model spec: '*' inside a form is not a synth scale; ':shared' and '*2' still apply.
  const auto s = parse_model("base+z^1*v^1:shared*2+(1-exp(-z/0.01))");
  ASSERT_EQ(s.terms.size(), 3u);
  EXPECT_EQ(s.terms[1].term->name, "z^1*v^1");
  EXPECT_FALSE(s.terms[1].per_gravity);
  EXPECT_DOUBLE_EQ(s.terms[1].scale, 2.0);
  EXPECT_EQ(s.terms[2].term->name, "(1-exp(-z/0.01))");
  EXPECT_EQ(s.name(), "base+z^1*v^1:shared+(1-exp(-z/0.01))");
  // Out-of-range numbers name the factor; an unknown name lists the library and the grammar.
  try {
    find_term("z^-1");
    FAIL();
  } catch (const gravsweep::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("'z^-1': a power in [0, 10] expected, found -1"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(find_term("exp(-z/0)"), gravsweep::ConfigError);
  try {
    find_term("warp_drive");
    FAIL();
  } catch (const gravsweep::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("or a generated form such as z^1*v^1"), std::string::npos) << e.what();
  }
}

TEST(GeneratedTerms, TheFamilyIsDistinctAndLeavesTheNamedFormsOut) {
  const auto& f = generated_family();
  EXPECT_EQ(f.size(), 50u);
  EXPECT_EQ(std::set<std::string>(f.begin(), f.end()).size(), f.size()) << "no form twice";
  for (const auto& name : f) {
    EXPECT_EQ(canonical_generated_name(name), name);
    for (const char* named : {"z^0", "z^1", "v^1", "v^2"}) EXPECT_NE(name, named);
  }
  // The typical value of a form: m g at 2 cm and 0.5 m/s (what `synth` hides at scale 1).
  const TermInfo& t = find_term("z^1*v^1");
  TermContext c;
  c.z_m = kGeneratedRefDepth_m;
  c.v_m_s = -kGeneratedRefSpeed_m_s;  // the speed counts, not its sign
  double phi = 0;
  t.features(c, &phi);
  EXPECT_NEAR(phi * t.typical(9.81, 1.0, 0.1)[0], 9.81, 1e-9);
}

TEST(GeneratedSearch, HiddenFormsOutsideTheLibraryAreNamedByTheirFormulaInMostSeeds) {
  // Two forms no named term has: a resistance growing as depth x speed (immersion_drag takes part
  // of it), and a friction growing as depth squared (depth_friction or bottom_stiffening take
  // part). Named "in a seed": the search's form, or one the trials cannot tell apart from it
  // (neighbouring powers often fit these 48 trials equally well; the verdict lists them).
  // Each hidden at a scale the 48 trials can resolve (the term adds 2-3 m g at 2 cm, 0.5 m/s).
  for (const auto& [hidden, scale] : std::vector<std::pair<std::string, std::string>>{{"z^1*v^1", "2"}, {"z^2", "3"}}) {
    int named = 0, humble = 0;
    for (unsigned seed = 1; seed <= 5; ++seed) {
      const Discovery d = rank_hidden("base+" + hidden + "*" + scale, seed);
      const bool is_humble = d.verdict.find("partly explained by") != std::string::npos ||
                             d.verdict.find("structure left that no named term explains") != std::string::npos;
      humble += is_humble;
      EXPECT_EQ(is_humble, d.structure_left) << d.verdict;
      std::set<std::string> forms(d.generated_equivalent.begin(), d.generated_equivalent.end());
      if (!d.generated.empty()) forms.insert(d.generated);
      EXPECT_LE(forms.size(), 20u) << "a form, and those the trials cannot tell apart from it (of 50)";
      if (forms.count(hidden)) {
        ++named;
        EXPECT_NE(d.verdict.find(hidden), std::string::npos) << d.verdict;
        EXPECT_LT(d.errors_with_generated.trace_rel_pct, d.errors_without_generated.trace_rel_pct) << d.verdict;
        EXPECT_LE(d.errors_with_generated.zstop_rel_pct, d.errors_without_generated.zstop_rel_pct) << d.verdict;
        EXPECT_LE(d.errors_with_generated.tstop_rel_pct, d.errors_without_generated.tstop_rel_pct) << d.verdict;
      }
      std::cout << hidden << " seed " << seed << ": " << (d.generated.empty() ? "-" : d.generated) << " ("
                << d.generated_equivalent.size() << " equivalent); " << d.verdict.substr(0, 60) << "\n";
    }
    EXPECT_GE(humble, 3) << hidden << ": a humble verdict in " << humble << " of 5 seeds";
    EXPECT_GE(named, 3) << hidden << ": named in " << named << " of 5 seeds";
  }
}

TEST(GeneratedSearch, NothingHiddenMeansNothingReportedInAtLeast19Of20Seeds) {
  int reported = 0;
  for (unsigned seed = 101; seed <= 120; ++seed) {
    const Discovery d = rank_hidden("base", seed);
    reported += !d.generated.empty() || !d.added.empty();
  }
  EXPECT_LE(reported, 1);
}

TEST(GeneratedSearch, ANamedTermAndAGeneratedFormTheTrialsCannotTellApartAreNamedTogether) {
  // The immersed cross-section's drag, m v^2 (1 - 2z/D)^2 less above z = D/2, and v^2 exp(-z/l)
  // with l = 2 cm differ by at most 0.1 of their size: 48 trials cannot tell them apart, and the
  // verdict names both instead of the named term alone.
  int both = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Discovery d = rank_hidden("base+immersion_drag", seed);
    ASSERT_FALSE(d.added.empty()) << d.verdict;
    EXPECT_EQ(d.added.front(), "immersion_drag") << d.verdict;
    const auto& eq = d.equivalent.front();
    const bool named =
        std::any_of(eq.begin(), eq.end(), [](const std::string& e) { return e.rfind("c * v^2*exp(-z/", 0) == 0; });
    both += named && d.verdict.find(", or equally well c * v^2*exp(-z/") != std::string::npos;
  }
  EXPECT_GE(both, 4) << "named together in " << both << " of 5 seeds";
  // A generated form that fits better than the named winner is not its equal: a depth x speed
  // resistance is partly taken by immersion_drag, and the true form is reported beyond it.
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Discovery d = rank_hidden("base+z^1*v^1*2", seed);
    for (const auto& eq : d.equivalent)
      EXPECT_TRUE(std::find(eq.begin(), eq.end(), "c * z^1*v^1") == eq.end()) << d.verdict;
    EXPECT_EQ(d.verdict.find("or equally well c * z^1*v^1"), std::string::npos) << d.verdict;
  }
}
