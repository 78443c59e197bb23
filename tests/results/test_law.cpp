// A law kept in a file and applied to new cases (results/model/law.h, `model fit --save`,
// `model predict`): the file's round trip and its checks, the range flags (refused at 1e-7 m/s2
// and at D = 1 m, flagged just outside), and the coverage of the 95 % intervals: each gravity
// level of the committed sweep predicted by the law saved from the other levels.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "results/measurements/campaign.h"
#include "results/model/law.h"
#include "results/model/model_spec.h"
#include "results/model/predict.h"
#include "results/model/synth.h"
#include "results_helpers.h"

namespace gravsweep::results {
namespace {

using gravsweep::testing::TempDir;

/// Three levels, speeds by Froude number 0.3-3, two repeats; the law saved with 50 resamples.
SavedLaw synth_law(const TempDir& d) {
  SynthOptions o;
  o.gravity_m_s2 = {9.81, 0.1, 0.01};
  o.froude = {0.3, 1.0, 3.0};
  o.repeats = 2;
  write_synthetic_campaign(d.str(), parse_model("scaled_base+gravity_depth_friction"), o);
  return make_saved_law(parse_model("scaled_base+gravity_depth_friction"), load_campaign(d.str()), 50);
}

std::string message_of(const std::filesystem::path& p) {
  try {
    read_law(p);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Law, TheFileHoldsTheLawAndItsPredictionsExactly) {
  TempDir d;
  const SavedLaw law = synth_law(d);
  EXPECT_EQ(law.levels, 3);
  EXPECT_EQ(law.form_error_source, "leave one gravity level out");
  EXPECT_EQ(law.form_error.size(), 3u);
  EXPECT_GE(law.bootstrap.size(), 45u);
  const auto file = d.path / "law.json";
  write_law(file, law);
  const SavedLaw back = read_law(file);
  EXPECT_EQ(back.values, law.values);
  EXPECT_EQ(back.covariance, law.covariance);
  EXPECT_EQ(back.bootstrap, law.bootstrap);
  EXPECT_EQ(back.model, law.model);
  // The bed it was fitted on (synth.h's defaults), kept for the user to compare with their ground.
  EXPECT_DOUBLE_EQ(law.bulk_density_kg_m3.lo, 1450);
  EXPECT_DOUBLE_EQ(law.bulk_density_kg_m3.hi, 1450);
  EXPECT_DOUBLE_EQ(law.fill_height_m.lo, 0.21);
  EXPECT_DOUBLE_EQ(law.fill_height_m.hi, 0.21);
  EXPECT_EQ(back.bulk_density_kg_m3.lo, law.bulk_density_kg_m3.lo);
  EXPECT_EQ(back.bulk_density_kg_m3.hi, law.bulk_density_kg_m3.hi);
  EXPECT_EQ(back.fill_height_m.lo, law.fill_height_m.lo);
  EXPECT_EQ(back.fill_height_m.hi, law.fill_height_m.hi);
  // A version-1 file written before the bed was recorded still loads, with no bed range.
  nlohmann::json j;
  std::ifstream(file) >> j;
  j["ranges"].erase("bulk_density_kg_m3");
  j["ranges"].erase("fill_height_m");
  std::ofstream(d.path / "old.json") << j.dump();
  const SavedLaw old = read_law(d.path / "old.json");
  EXPECT_TRUE(std::isnan(old.bulk_density_kg_m3.lo));
  EXPECT_TRUE(std::isnan(old.fill_height_m.hi));
  EXPECT_EQ(old.values, law.values);
  const LawCase c{0.1, 0.3, 0.1, 1.0};
  const LawPrediction a = predict_case(law, c), b = predict_case(back, c);
  EXPECT_EQ(a.zstop_m, b.zstop_m);
  EXPECT_EQ(a.zstop_hi_m, b.zstop_hi_m);
  EXPECT_EQ(a.range, LawRangeFlag::inside) << a.note;
  EXPECT_LT(a.zstop_lo_m, a.zstop_m);
  EXPECT_GT(a.zstop_hi_m, a.zstop_m);
  EXPECT_GT(a.tstop_hi_s, a.tstop_s);
  // The prediction is the law integrated: the saved law's model gives the same depth.
  TermContext ctx;
  ctx.g_m_s2 = 0.1, ctx.v_m_s = ctx.vc_m_s = 0.3, ctx.diameter_m = 0.1, ctx.mass_kg = 1.0, ctx.fill_height_m = 1e3;
  EXPECT_DOUBLE_EQ(predict(law_model(law), ctx).zstop_m, a.zstop_m);
}

TEST(Law, FarBeyondTheFittedRangesACaseIsRefusedJustOutsideItIsFlagged) {
  TempDir d;
  const SavedLaw law = synth_law(d);
  const double v_fr1 = [](double g) { return std::sqrt(g * 0.1); }(1e-7);
  EXPECT_EQ(predict_case(law, {1e-7, v_fr1, 0.1, 1.0}).range, LawRangeFlag::refused);
  const LawPrediction big = predict_case(law, {0.1, 0.3, 1.0, 1.0});
  // D = 1 m is refused by the diameter alone (10 times the fitted 0.1 m); its Fr 0.95 is inside.
  EXPECT_EQ(big.range, LawRangeFlag::refused) << big.note;
  EXPECT_NE(big.note.find("diameter"), std::string::npos) << big.note;
  EXPECT_EQ(big.note.find("Froude"), std::string::npos) << big.note;
  EXPECT_TRUE(std::isnan(big.zstop_m));
  const LawPrediction below = predict_case(law, {0.005, std::sqrt(0.005 * 0.1), 0.1, 1.0});
  EXPECT_EQ(below.range, LawRangeFlag::extrapolated) << below.note;
  EXPECT_NE(below.note.find("gravity"), std::string::npos) << below.note;
  EXPECT_TRUE(std::isfinite(below.zstop_m));
  const LawPrediction wider = predict_case(law, {0.1, std::sqrt(0.1 * 0.15), 0.15, 1.0});
  EXPECT_EQ(wider.range, LawRangeFlag::extrapolated) << wider.note;
  EXPECT_NE(wider.note.find("diameter"), std::string::npos) << wider.note;
}

TEST(Law, ABadFileIsRefusedNamingTheFileAndTheField) {
  TempDir d;
  const SavedLaw law = synth_law(d);
  const auto file = d.path / "law.json";
  write_law(file, law);
  nlohmann::json j;
  std::ifstream(file) >> j;
  const auto write = [&](const nlohmann::json& x) { std::ofstream(file) << x.dump(); };
  auto v = j;
  v["format_version"] = 99;
  write(v);
  EXPECT_NE(message_of(file).find(file.string() + ": /format_version"), std::string::npos) << message_of(file);
  v = j;
  v["values"][1] = "x";
  write(v);
  EXPECT_NE(message_of(file).find("/values/1"), std::string::npos) << message_of(file);
  v = j;
  v["constants"].erase(v["constants"].size() - 1);
  write(v);
  EXPECT_NE(message_of(file).find("/constants"), std::string::npos) << message_of(file);
  v = j;
  v["model"] = "base";
  write(v);
  EXPECT_NE(message_of(file).find("/model"), std::string::npos) << message_of(file);
  std::ofstream(file) << "{ not json";
  EXPECT_NE(message_of(file).find("not JSON"), std::string::npos) << message_of(file);
  EXPECT_THROW(make_saved_law(parse_model("base"), load_campaign(d.str()), 20), std::invalid_argument);
}

// Each level of the committed sweep (50 drops, five levels) predicted by the law
// (scaled_base+gravity_depth_friction+immersion_drag:shared) saved from the other four: at least 90 %
// of the held-out drops fall inside their 95 % intervals of zstop and of tstop.
TEST(Law, HeldOutLevelsOfTheSweepFallInsideTheirIntervals) {
  const auto root = std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "gravity_sweep";
  std::vector<Campaign> parts;
  for (const char* level : {"g9.81", "g1.62", "g0.1", "g0.1_axis", "g0.01", "g0.01_axis", "g0.001", "g0.001_axis"})
    parts.push_back(load_campaign((root / level).string()));
  Campaign all = parts.front();
  for (std::size_t i = 1; i < parts.size(); ++i)
    for (auto& t : parts[i].trials) all.trials.push_back(t);
  const ModelSpec law = parse_model("scaled_base+gravity_depth_friction+immersion_drag:shared");
  int drops = 0, z_in = 0, t_in = 0;
  std::map<long, std::array<int, 3>> by_froude;  // 10 Fr rounded -> drops, zstop inside, tstop inside
  for (double g : all.gravity_levels()) {
    Campaign others = all, held = all;
    std::erase_if(others.trials, [g](const MeasuredTrial& t) { return same_gravity_level(t.info.gravity_m_s2, g); });
    std::erase_if(held.trials, [g](const MeasuredTrial& t) { return !same_gravity_level(t.info.gravity_m_s2, g); });
    const SavedLaw s = make_saved_law(law, others, 100);
    int level_z = 0, level_t = 0;
    for (const auto& t : held.trials) {
      const auto& m = t.processed.metrics;
      const LawPrediction p =
          predict_case(s, {t.info.gravity_m_s2, m.vc_m_s, t.info.projectile_diameter_m, t.info.projectile_mass_kg});
      ++drops;
      const int zi = m.zstop_m >= p.zstop_lo_m && m.zstop_m <= p.zstop_hi_m ? 1 : 0;
      const int ti = m.tstop_s >= p.tstop_lo_s && m.tstop_s <= p.tstop_hi_s ? 1 : 0;
      level_z += zi, level_t += ti;
      auto& f = by_froude[std::lround(10 * p.froude)];
      f[0] += 1, f[1] += zi, f[2] += ti;
    }
    std::printf("held out %g m/s2: zstop inside %d of %zu, tstop inside %d of %zu\n", g, level_z, held.trials.size(),
                level_t, held.trials.size());
    z_in += level_z, t_in += level_t;
  }
  for (const auto& [fr10, f] : by_froude)
    std::printf("Fr %.1f: zstop inside %d of %d, tstop inside %d of %d\n", fr10 / 10.0, f[1], f[0], f[2], f[0]);
  std::printf("all levels: zstop inside %d of %d, tstop %d of %d\n", z_in, drops, t_in, drops);
  EXPECT_EQ(drops, 50);
  EXPECT_GE(z_in, 0.9 * drops);
  EXPECT_GE(t_in, 0.9 * drops);
}

}  // namespace gravsweep::results

namespace gravsweep::results {

// The verbs: `model fit --save` writes the law, `model predict` prints the cases with their
// intervals and flags, exits 2 on a refused case (0 with --extrapolate) and on a bad law file.
TEST(Law, TheVerbsSaveAndPredictWithExitCodesScriptsCanTrust) {
  TempDir d;
  SynthOptions o;
  o.gravity_m_s2 = {9.81, 0.1, 0.01};
  o.froude = {0.3, 1.0, 3.0};
  o.repeats = 2;
  write_synthetic_campaign(d.str(), parse_model("scaled_base+gravity_depth_friction"), o);
  const std::string law = (d.path / "law.json").string();
  auto r = gravsweep::testing::run_gravsweep("model fit '" + d.str() +
                                                 "' --model scaled_base+gravity_depth_friction --baseline "
                                                 "scaled_base --no-plot --resamples 30 --save '" +
                                                 law + "'",
                                             true);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("wrote " + law), std::string::npos) << r.out;
  r = gravsweep::testing::run_gravsweep("model predict --law '" + law + "' --gravity 0.1 --speed 0.3 --format csv",
                                        false);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.rfind("gravity_m_s2,speed_m_s,diameter_m,mass_kg,impact_froude,zstop_m,zstop_lo_m,zstop_hi_m,", 0),
            0u)
      << r.out;
  EXPECT_NE(r.out.find(",inside,"), std::string::npos) << r.out;
  {  // csv at full precision: the depth read back (column 6, zstop_m) is the one the law gives
    std::istringstream row(r.out.substr(r.out.find('\n') + 1));
    std::string zstop;
    for (int k = 0; k < 6; ++k) std::getline(row, zstop, ',');
    EXPECT_EQ(std::stod(zstop), predict_case(read_law(law), {0.1, 0.3, 0.1, 1.0}).zstop_m) << r.out;
  }
  r = gravsweep::testing::run_gravsweep("model predict --law '" + law + "' --gravity 1e-7 --speed 0.0001", true);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("refused"), std::string::npos) << r.out;
  r = gravsweep::testing::run_gravsweep("model predict --law '" + law + "' --gravity 0.1 --speed 0.3 --diameter 1",
                                        true);
  EXPECT_EQ(r.code, 2) << r.out;  // D = 1 m: ten times the fitted 0.1 m
  EXPECT_NE(r.out.find("projectile diameter (m) 1 outside the fitted 0.1-0.1"), std::string::npos) << r.out;
  r = gravsweep::testing::run_gravsweep(
      "model predict --law '" + law + "' --gravity 1e-7 --speed 0.0001 --extrapolate --format csv", false);
  EXPECT_EQ(r.code, 0) << r.out;
  std::ofstream(d.path / "bad.json") << "{\"format\": \"something else\"}";
  r = gravsweep::testing::run_gravsweep(
      "model predict --law '" + (d.path / "bad.json").string() + "' --gravity 0.1 --speed 0.3", true);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("bad.json: /format"), std::string::npos) << r.out;
}

}  // namespace gravsweep::results

namespace gravsweep::results {

// The prediction against g: a figure at fixed Froude numbers with the law alone (no --gravity),
// and --plot without a curve is a usage error.
TEST(Law, PredictDrawsTheLawAgainstGravity) {
  gravsweep::testing::TempDir d;
  const std::string law = (std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "examples" / "mission" / "law.json").string();
  const std::string png = d.str() + "/law_g.png";
  auto r = gravsweep::testing::run_gravsweep(
      "model predict --law '" + law + "' --plot-froude 0.5 2 --plot '" + png + "'", true);
  EXPECT_EQ(r.code, 0) << r.out;
  ASSERT_TRUE(std::filesystem::exists(png)) << r.out;
  EXPECT_GT(std::filesystem::file_size(png), 20000u);
  r = gravsweep::testing::run_gravsweep("model predict --law '" + law + "' --plot '" + png + "'", true);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--plot-froude"), std::string::npos) << r.out;
}

// The worked examples of docs/mission.md stay true: each committed output of
// examples/mission/run.sh (the command on its first line, the exit code on its last) is what
// `model predict` and `model infer` print today with the committed law.
TEST(Law, TheWorkedExamplesMatchTheirCommittedOutputs) {
  const auto dir = std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "examples" / "mission";
  int checked = 0;
  for (const char* name : {"lander", "lander_extrapolated", "moon_sampler", "mars_rock", "mars_meteorite",
                           "moon_sampler_infer", "moon_sampler_infer_tstop"}) {
    std::ifstream in(dir / (std::string(name) + ".txt"));
    ASSERT_TRUE(in.good()) << name;
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    ASSERT_GE(lines.size(), 3u) << name;
    const std::string prefix = "$ gravsweep ";
    ASSERT_EQ(lines.front().rfind(prefix, 0), 0u) << lines.front();
    // From the example's folder, where the command names its law.
    const std::string cmd = "cd '" + dir.string() + "' && '" + GRAVSWEEP_BINARY + "' " +
                            lines.front().substr(prefix.size()) + " 2>&1; echo \"(exit $?)\"";
    FILE* p = popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string out;
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), buf.size(), p)) out += buf.data();
    pclose(p);
    std::string want;
    for (std::size_t i = 1; i < lines.size(); ++i) want += lines[i] + "\n";
    EXPECT_EQ(out, want) << name;
    ++checked;
  }
  EXPECT_EQ(checked, 7);
}

}  // namespace gravsweep::results
