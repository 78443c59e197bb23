// The committed reproduction dataset (data/reproduction/, REPRODUCTION.md): `model
// table3` and `model rank` on it must keep giving the values REPRODUCTION.md states, so that a
// change to processing or fitting that moves them fails here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "engine/scenario/bed.h"
#include "results/model/table3.h"
#include "results/io/bed_file.h"
#include "results/io/csv.h"
#include "results/measurements/campaign.h"
#include "results_helpers.h"
#include "tests/common/temp_dir.h"

namespace {

std::string dataset(const char* part) {
  return (std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "reproduction" / part).string();
}

/// The row of gravity level `g_m_s2` of `model table3 <inputs> --format csv`, by column name (a
/// note or a nan reads as NaN).
std::map<std::string, double> table3_row(const std::string& inputs, double g_m_s2 = 9.81) {
  const auto r = gravsweep::testing::run_gravsweep("model table3 " + inputs + " --format csv", false);
  EXPECT_EQ(r.code, 0) << r.out;
  std::istringstream in(r.out);
  gravsweep::results::CsvReader csv(in);
  std::vector<std::string> names, fields;
  int line = 0;
  if (!csv.next(names, line)) return {};
  while (csv.next(fields, line)) {
    std::map<std::string, double> out;
    for (std::size_t i = 0; i < names.size() && i < fields.size(); ++i) {
      char* end = nullptr;
      const double v = std::strtod(fields[i].c_str(), &end);
      out[names[i]] = end && *end == '\0' && !fields[i].empty() ? v : NAN;
    }
    if (std::abs(out["gravity_m_s2"] - g_m_s2) <= 1e-6 * g_m_s2) return out;
  }
  return {};
}

/// The rows of a committed results CSV (the project's RFC 4180 reader: notes hold commas), by
/// column name.
std::vector<std::map<std::string, std::string>> csv_rows(const std::string& file) {
  std::ifstream in(std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "reproduction" / file);
  EXPECT_TRUE(in.good()) << file;
  gravsweep::results::CsvReader csv(in);
  std::vector<std::string> names, fields;
  int line = 0;
  std::vector<std::map<std::string, std::string>> rows;
  if (!csv.next(names, line)) return rows;
  while (csv.next(fields, line)) {
    EXPECT_EQ(fields.size(), names.size()) << file << ":" << line;
    std::map<std::string, std::string> r;
    for (std::size_t i = 0; i < names.size() && i < fields.size(); ++i) r[names[i]] = fields[i];
    rows.push_back(r);
  }
  return rows;
}

}  // namespace

// Chrono set at 1 g, part 1: 21 drops whose three repeats hit the same three sites at every speed
// (site_draw "seed"), rerun from a clean build (REPRODUCTION.md). Ours: f0 15.0 +/- 3.3, 1/d1
// 46.5 +/- 4.6, alpha 0.383. Evidence for the site effect, not the row we quote: 1/d1 lies 16.6
// 1/m above part 1b's (a site per drop), more than three of part 1's standard errors.
TEST(Reproduction, ChronoOneGSharedSitesRowAsStated) {
  const auto row = table3_row("'" + dataset("chrono_1g") + "'");
  ASSERT_EQ(row.count("f0_N"), 1u);
  EXPECT_EQ(row.at("trials"), 21);
  EXPECT_NEAR(row.at("gravity_m_s2"), 9.81, 1e-9);
  EXPECT_NEAR(row.at("f0_N"), 15.0, 0.1);
  EXPECT_NEAR(row.at("inv_d1_1_m"), 46.5, 0.1);
  EXPECT_NEAR(row.at("alpha"), 0.375, 0.002);  // zstop from the collision start (0.383 from the surface)
  const auto sites = table3_row("'" + dataset("chrono_1g_sites") + "'");
  EXPECT_GT(row.at("inv_d1_1_m") - sites.at("inv_d1_1_m"), 3 * row.at("inv_d1_se_1_m"))
      << "the shared sites move 1/d1 by more than three standard errors";
}

// Part 1 again with a site per drop (part1b, REPRODUCTION.md "Definitions and criteria"): the
// sites part 1 shared move 1/d1 by 16.6 1/m; with independent sites f0 and alpha stay inside the
// paper's uncertainties and 1/d1 lies 1.3 combined standard errors below the paper's 38 +/- 5.
TEST(Reproduction, ChronoOneGTable3RowWithASitePerDrop) {
  const auto row = table3_row("'" + dataset("chrono_1g_sites") + "'");
  ASSERT_EQ(row.count("f0_N"), 1u);
  EXPECT_EQ(row.at("trials"), 21);
  EXPECT_NEAR(row.at("f0_N"), 20.5, 0.1);
  EXPECT_NEAR(row.at("inv_d1_1_m"), 29.9, 0.1);
  EXPECT_NEAR(row.at("alpha"), 0.381, 0.002);  // zstop from the collision start (0.384 from the surface)
  EXPECT_NEAR(row.at("f0_boot_se_N"), 1.7, 0.1);
  EXPECT_NEAR(row.at("inv_d1_boot_se_1_m"), 3.7, 0.1);
  EXPECT_NEAR(row.at("f0_N"), 19, 3);
  EXPECT_NEAR(row.at("alpha"), 0.39, 0.03);
  EXPECT_LT(std::abs(row.at("inv_d1_1_m") - 38) / std::hypot(row.at("inv_d1_se_1_m"), 5.0), 1.5);
}

// Beyond the paper: the Poncelet law misses a depth-dependent friction in our DEM data at 1 g (the
// drops of part 1), depth_friction or equally gravity_depth_friction (one level cannot tell k z
// from kappa g z); with zstop from the collision start a generated form beyond the named library,
// a depth term that saturates within 2.5 mm of contact, predicts zstop and tstop better held out
// and is named beside them.
TEST(Reproduction, ModelRankNamesDepthFrictionOnTheChronoOneGDrops) {
  const auto r = gravsweep::testing::run_gravsweep("model rank '" + dataset("chrono_1g") + "'", true);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("Verdict: partly explained by depth_friction"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("or equally well gravity_depth_friction"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("better on 20 of 21 trials"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("a generated form fits it: c * z^1*exp(-z/0.0025)"), std::string::npos) << r.out;
}

// Chrono set at 0.1 m/s2 (part 2: 21 drops on a bed at rest, a site per drop; REPRODUCTION.md).
// Paper Table 3: f0 0.2 +/- 2 N, 1/d1 39 +/- 5 1/m, alpha 0.28 +/- 0.02, processed as the paper
// processes its Chrono drops (a 500 Hz filter at every gravity: --time-scale fixed). Ours, to the
// printed digits: f0 3.6 +/- 4.1 (bootstrap 2.4), 1/d1 55.6 +/- 6.4 (12), alpha 0.307 +/- 0.006
// (0.311 with zstop from the surface), below 1 g's as the paper found. In the drop's own scales (a
// 50.5 Hz filter at 0.1 m/s2) the apeak fit pins f0 and 1/d1: 2.32 +/- 0.8 N and 20.6 +/- 1.2 1/m.
// Tight: a change of the data or the fit that moves f0 by 0.1 N fails.
TEST(Reproduction, ChronoLowGTable3RowOnABedAtRest) {
  const std::string both = "'" + dataset("chrono_1g_sites") + "' '" + dataset("chrono_0.1g") + "'";
  const auto low = table3_row(both + " --time-scale fixed", 0.1), one = table3_row(both, 9.81);
  ASSERT_EQ(low.count("inv_d1_1_m"), 1u);
  EXPECT_EQ(low.at("trials"), 21) << "seven speeds, three repeats";
  EXPECT_NEAR(low.at("f0_N"), 3.6, 0.05);
  EXPECT_NEAR(low.at("f0_se_N"), 4.1, 0.05);
  EXPECT_NEAR(low.at("inv_d1_1_m"), 55.6, 0.05);
  EXPECT_NEAR(low.at("inv_d1_boot_se_1_m"), 12, 0.5);
  EXPECT_NEAR(low.at("alpha"), 0.307, 0.0005);
  const auto own = table3_row(both, 0.1);
  EXPECT_NEAR(own.at("f0_N"), 2.32, 0.05);
  EXPECT_NEAR(own.at("f0_se_N"), 0.8, 0.05);
  EXPECT_NEAR(own.at("inv_d1_1_m"), 20.6, 0.05);
  EXPECT_NEAR(own.at("alpha"), 0.307, 0.0005);
  EXPECT_LT(std::abs(low.at("f0_N") - 0.2), std::hypot(low.at("f0_se_N"), 2.0)) << "inside the paper's 0.2 +/- 2 N";
  const double d1_off = std::abs(low.at("inv_d1_1_m") - 39) / std::hypot(low.at("inv_d1_boot_se_1_m"), 5.0);
  EXPECT_GT(d1_off, 1.0) << "outside one combined uncertainty of the paper's 1/d1, as stated";
  EXPECT_LT(d1_off, 1.5) << "and within 1.5 of them (bootstrap error)";
  EXPECT_LT(low.at("alpha"), one.at("alpha")) << "the paper: alpha lower at 0.1 m/s2 than at 1 g";
}

// Eq. 4 at 0.1 m/s2 (REPRODUCTION.md), the traces processed as the paper does (500 Hz at every
// gravity, --time-scale fixed): fitted to the traces, the Poncelet law pins f0 at 1.6 m g
// (the apeak fit cannot: 3.6 +/- 4.1 N) and then over-predicts the duration, as the paper found,
// where Table 3's f0 under-predicts it; held out, both miss tstop.
TEST(Reproduction, EquationFourAtLowGravityFollowsTheFittedF0) {
  gravsweep::test::TempDir tmp;
  const auto r = gravsweep::testing::run_gravsweep("model fit '" + dataset("chrono_0.1g") +
                                                       "' --model base --time-scale fixed --format csv --plot '" +
                                                       (tmp.path / "error_falls.png").string() + "'",
                                                   false);
  ASSERT_EQ(r.code, 0) << r.out;
  std::istringstream in(r.out);
  std::string line;
  double f0_N = NAN, inv_d1_1_m = NAN;
  while (std::getline(in, line)) {
    if (line.rfind("base.f0_N@g=0.1,", 0) == 0) f0_N = std::stod(line.substr(line.find(',') + 1));
    if (line.rfind("base.inv_d1_1_m@g=0.1,", 0) == 0) inv_d1_1_m = std::stod(line.substr(line.find(',') + 1));
  }
  EXPECT_NEAR(f0_N, 0.1565, 0.001) << r.out;
  EXPECT_NEAR(inv_d1_1_m, 22.9, 0.1) << r.out;
  // Eq. 4 (Sunday et al. 2021): tstop = atan(vc sqrt(m / (d1 (f0 - m g)))) / sqrt((f0/m - g) / d1).
  constexpr double kMass_kg = 1.0, kG_m_s2 = 0.1, kTable3F0_N = 3.6, kTable3InvD1_1_m = 55.6;
  const auto eq4_s = [&](double vc_m_s, double f0, double inv_d1) {
    const double d1 = 1 / inv_d1, net_N = f0 - kMass_kg * kG_m_s2;
    return std::atan(vc_m_s * std::sqrt(kMass_kg / (d1 * net_N))) / std::sqrt((f0 / kMass_kg - kG_m_s2) / d1);
  };
  for (const auto& row : csv_rows("results_part2_chrono_lowg.csv")) {
    const double vc = std::stod(row.at("vc_m_s")), tstop = std::stod(row.at("tstop_s"));
    EXPECT_LT(eq4_s(vc, kTable3F0_N, kTable3InvD1_1_m), 0.15 * tstop) << "Table 3's f0 under-predicts, vc " << vc;
    if (vc >= 0.2) {
      EXPECT_GT(eq4_s(vc, f0_N, inv_d1_1_m), 1.3 * tstop) << "the traces' f0 over-predicts, vc " << vc;
    }
  }
}

// pkdgrav set at 1 g (part 5: 7 drops from the axis on a bed at rest, the rolling and twisting
// sliders held at their limit; REPRODUCTION.md). Paper Table 3: f0 21 +/- 4 N, 1/d1 35 +/- 7 1/m,
// alpha 0.40 +/- 0.03. Ours: f0 15.1 +/- 0.4 N (1.5 combined uncertainties below), 1/d1 77.6 +/- 0.5
// 1/m (not reproduced: 6 above), alpha 0.474 +/- 0.010 (2.3 above). Before the fix (latched sliders,
// a bed that never came to rest): f0 21.2, 1/d1 42.7, alpha 0.536.
TEST(Reproduction, PkdgravTable3RowAsStated) {
  const auto row = table3_row("'" + dataset("pkdgrav_1g") + "'");
  ASSERT_EQ(row.count("f0_N"), 1u);
  EXPECT_EQ(row.at("trials"), 7);
  EXPECT_NEAR(row.at("f0_N"), 15.1, 0.5);
  EXPECT_NEAR(row.at("inv_d1_1_m"), 77.6, 1.0);
  EXPECT_NEAR(row.at("alpha"), 0.474, 0.01);
  const double f0_combined = std::hypot(4.0, row.at("f0_se_N"));
  EXPECT_GT(21 - row.at("f0_N"), f0_combined) << "below the paper's f0 by more than one combined uncertainty";
  EXPECT_LT(21 - row.at("f0_N"), 2 * f0_combined) << "and by less than two";
  EXPECT_GT(row.at("inv_d1_1_m") - 35, 5 * std::hypot(7.0, row.at("inv_d1_se_1_m"))) << "1/d1 not reproduced";
  const double alpha_combined = std::hypot(0.03, row.at("alpha_se"));
  EXPECT_GT(row.at("alpha") - 0.40, 2 * alpha_combined) << "alpha above the paper's, as stated";
  EXPECT_LT(row.at("alpha") - 0.40, 3 * alpha_combined);
}

// Part 5b (REPRODUCTION.md, check 5): part 5's drops on the same bed with a 7.7x stiffer spring at
// the paper's 0.5 us step. With the bed at rest the spring matters: the fast drops stop shallower,
// alpha falls from 0.474 to 0.437 (1.1 combined uncertainties above the paper's 0.40) and f0 is
// 16.3 +/- 1.2 N (1.1 below 21 +/- 4); 1/d1 is 59 +/- 1.7 1/m, still 3.3 above 35 +/- 7.
TEST(Reproduction, AStifferPkdgravSpringBringsAlphaAndF0WithinTheirUncertainties) {
  const auto stiff = table3_row("'" + dataset("pkdgrav_stiff_1g") + "'");
  const auto soft = table3_row("'" + dataset("pkdgrav_1g") + "'");
  ASSERT_EQ(stiff.count("alpha"), 1u);
  ASSERT_EQ(soft.count("alpha"), 1u);
  EXPECT_EQ(stiff.at("trials"), 7);
  EXPECT_NEAR(stiff.at("f0_N"), 16.3, 0.5);
  EXPECT_NEAR(stiff.at("inv_d1_1_m"), 59.0, 1.0);
  EXPECT_NEAR(stiff.at("alpha"), 0.437, 0.01);
  EXPECT_GT(soft.at("alpha") - stiff.at("alpha"), 0.03) << "k_N moves alpha once the bed is at rest";
  EXPECT_LT(std::abs(stiff.at("alpha") - 0.40), 1.5 * std::hypot(0.03, stiff.at("alpha_se")));
  EXPECT_LT(std::abs(stiff.at("f0_N") - 21), 1.5 * std::hypot(4.0, stiff.at("f0_se_N")));
  EXPECT_GT(stiff.at("inv_d1_1_m") - 35, 3 * std::hypot(7.0, stiff.at("inv_d1_se_1_m"))) << "1/d1 not reproduced";
}

// Beyond the paper (REPRODUCTION.md): a depth-dependent resistance is what the Poncelet law misses
// at 1 g (part 1b). At 0.1 m/s2 (part 2, mostly above Fr 1.5) the paper's 500 Hz processing finds
// nothing missing; in the drop's own scales (50.5 Hz) the residuals rise with depth, which no named
// term explains alone and a depth-weighted drag c z v^0.5 fits; on both levels together the depth
// friction that does not follow g is named, then a drag linear in the speed.
TEST(Reproduction, ModelRankFindsADepthResistanceAtBothLevels) {
  const auto one = gravsweep::testing::run_gravsweep("model rank '" + dataset("chrono_1g_sites") + "'", true);
  ASSERT_EQ(one.code, 0) << one.out;
  EXPECT_NE(one.out.find("Verdict: missing effect: gravity_depth_friction"), std::string::npos) << one.out;
  EXPECT_NE(one.out.find("or equally well depth_friction"), std::string::npos) << one.out;
  const auto paper =
      gravsweep::testing::run_gravsweep("model rank '" + dataset("chrono_0.1g") + "' --time-scale fixed", true);
  ASSERT_EQ(paper.code, 0) << paper.out;
  EXPECT_NE(paper.out.find("Verdict: no missing effect found"), std::string::npos) << paper.out;
  const auto low = gravsweep::testing::run_gravsweep("model rank '" + dataset("chrono_0.1g") + "'", true);
  ASSERT_EQ(low.code, 0) << low.out;
  EXPECT_NE(low.out.find("Verdict: structure left that no named term explains, along depth_m"), std::string::npos)
      << low.out;
  EXPECT_NE(low.out.find("a generated form fits it: c * z^1*v^0.5 "), std::string::npos) << low.out;
  const auto both = gravsweep::testing::run_gravsweep(
      "model rank '" + dataset("chrono_1g_sites") + "' '" + dataset("chrono_0.1g") + "'", true);
  ASSERT_EQ(both.code, 0) << both.out;
  EXPECT_NE(both.out.find("Verdict: missing effect: depth_friction"), std::string::npos) << both.out;
  EXPECT_NE(both.out.find("better on 35 of 42 trials"), std::string::npos) << both.out;
  EXPECT_NE(both.out.find("; then viscous_drag (drag linear in speed"), std::string::npos) << both.out;
}

// Several inputs are read as one campaign (one exported dataset per gravity level): the trials of
// both are counted once each, each input is described, and reading one twice is refused.
TEST(Reproduction, ModelVerbsReadSeveralDatasetsAsOneCampaign) {
  const std::string both = "'" + dataset("chrono_1g_sites") + "' '" + dataset("chrono_0.1g") + "'";
  const auto r = gravsweep::testing::run_gravsweep("model table3 " + both + " --format csv", true);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("reading " + dataset("chrono_1g_sites")), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("reading " + dataset("chrono_0.1g")), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("9.81,"), std::string::npos) << r.out;  // a row per gravity level
  EXPECT_NE(r.out.find("0.1,"), std::string::npos) << r.out;
  // A level with too few trials or speeds is listed, not fitted: one speed cannot separate f0 from
  // 1/d1 (a partial 0.1 m/s2 level of 0.05 m/s drops printed 1/d1 = -1.5e5 1/m before).
  const auto few = gravsweep::testing::run_gravsweep(
      "model table3 " + both + " --where 'impact_speed_m_s>0.5' --where 'impact_speed_m_s<0.7' --format csv", true);
  ASSERT_EQ(few.code, 0) << few.out;
  EXPECT_NE(few.out.find("not fitted: Eq. 2 needs >= 3 trials over a vc range"), std::string::npos) << few.out;
  const auto twice = gravsweep::testing::run_gravsweep(
      "model table3 '" + dataset("chrono_1g") + "' '" + dataset("chrono_1g") + "'", true);
  EXPECT_EQ(twice.code, 2) << twice.out;
  EXPECT_NE(twice.out.find("is also in an earlier input"), std::string::npos) << twice.out;
}

// `report` reads several inputs too: Figs. 9 and 10 of both gravity levels in one report (the
// trials behind them are those of both datasets).
TEST(Reproduction, ReportDrawsBothGravityLevelsFromTwoDatasets) {
  gravsweep::test::TempDir out;
  const std::string both = "'" + dataset("chrono_1g_sites") + "' '" + dataset("chrono_0.1g") + "'";
  const auto r = gravsweep::testing::run_gravsweep("report " + both + " --out '" + out.path.string() + "'", true);
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* f : {"fig9_metrics_vs_vc.png", "fig10_zstop_vs_H.png", "index.html"})
    EXPECT_TRUE(std::filesystem::exists(out.path / f)) << f;
  std::ifstream trials(out.path / "trials.csv");
  std::string header, line;
  std::getline(trials, header);
  int rows = 0;
  while (std::getline(trials, line)) ++rows;
  const auto count = [](const std::string& d) {
    std::ifstream f(std::filesystem::path(d) / "trials.csv");
    std::string l;
    int n = -1;
    while (std::getline(f, l)) ++n;
    return n;
  };
  EXPECT_EQ(rows, count(dataset("chrono_1g_sites")) + count(dataset("chrono_0.1g"))) << header;
}

namespace {

std::string file_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

// The committed figures and tables (docs/reproduction/figures.txt, drawn by `deploy/reproduce.sh
// figures`) come from the committed data: every line runs again here, and the points behind each
// figure (its --data CSV) and each table's text must match the committed files. A dataset that
// moves without its figures being drawn again fails here.
TEST(Reproduction, TheCommittedFiguresMatchTheCommittedData) {
  namespace fs = std::filesystem;
  const fs::path root(GRAVSWEEP_SOURCE_DIR), figs = root / "docs" / "reproduction";
  std::ifstream manifest(figs / "figures.txt");
  ASSERT_TRUE(manifest.good()) << figs / "figures.txt";
  gravsweep::test::TempDir tmp;
  fs::current_path(root);  // the manifest's paths are relative to the repository root
  std::string line;
  int outputs = 0;
  while (std::getline(manifest, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto colon = line.find(": ");
    ASSERT_NE(colon, std::string::npos) << line;
    const std::string file = line.substr(0, colon), args = line.substr(colon + 2);
    const bool figure = fs::path(file).extension() == ".png";
    const std::string compared = figure ? fs::path(file).stem().string() + ".csv" : file;
    std::string fresh;
    if (figure) {
      const fs::path png = tmp.path / file, data = tmp.path / compared;
      const auto r = gravsweep::testing::run_gravsweep(
          args + " --out '" + png.string() + "' --data '" + data.string() + "'", true);
      ASSERT_EQ(r.code, 0) << line << "\n" << r.out;
      EXPECT_TRUE(fs::exists(figs / file)) << file << " is not committed";
      fresh = file_text(data);
    } else {
      const auto r = gravsweep::testing::run_gravsweep(args, true);
      ASSERT_EQ(r.code, 0) << line << "\n" << r.out;
      fresh = r.out;
    }
    EXPECT_EQ(fresh, file_text(figs / compared))
        << "docs/reproduction/" << compared << " no longer matches the committed data: run deploy/reproduce.sh figures";
    ++outputs;
  }
  EXPECT_GE(outputs, 9);
  // A results CSV without the column asked for is refused, naming the file and the column.
  const auto bad = gravsweep::testing::run_gravsweep(
      "plot results --from data/reproduction/results_part4_rolling_friction.csv --x mu_rolling --y zstop_mm --out '" +
          (tmp.path / "x.png").string() + "'",
      true);
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("results_part4_rolling_friction.csv: no column 'zstop_mm' in its header"), std::string::npos)
      << bad.out;
}

namespace {

// Each drop of an exported dataset with the swept values of its results row and the metrics its
// trace gives through the processing code (load_campaign): what the Fig. 6 and dt tests check.
struct RecomputedDrop {
  std::map<std::string, std::string> swept;  ///< the dataset's results.csv row
  gravsweep::results::Metrics metrics;       ///< from the exported trace
};
std::vector<RecomputedDrop> recomputed(const char* part) {
  const auto campaign = gravsweep::results::load_campaign(dataset(part));
  EXPECT_TRUE(campaign.issues.empty()) << part;
  std::vector<RecomputedDrop> out;
  for (const auto& row : csv_rows(std::string(part) + "/results.csv"))
    for (const auto& t : campaign.trials)
      if (t.info.trial_id == row.at("job_id")) out.push_back({row, t.processed.metrics});
  return out;
}

}  // namespace

// Fig. 3 (part 3, REPRODUCTION.md), recomputed from the committed traces: the projectile reaches
// the floor and rebounds at fills <= 4 cm (every 2 cm drop, at least one at 4 cm), none rebounds from
// 6 cm on; from 10 cm the depth is flat to within 7 % of its mean (3.76 cm from the collision
// start; 3.5 cm from the mean surface), and the 6-8 cm fills stop 8-20 % deeper than that (ours
// steps down between 8 and 10 cm where the paper's is constant).
TEST(Reproduction, FillHeightTrendsAsStated) {
  const auto drops = recomputed("fill_height");
  ASSERT_EQ(drops.size(), 14u);
  int rebounds_at_4cm = 0;
  std::vector<double> plateau, shallow;
  for (const auto& d : drops) {
    const double fill = std::stod(d.swept.at("fill_height_m"));
    const auto& m = d.metrics;
    EXPECT_NEAR(m.vc_m_s, 1.0, 0.03) << "the paper's Fig. 3 speed";
    std::printf("fill %.2f m: zstop %.4f m, tstop %.4f s, rebound %d\n", fill, m.zstop_m, m.tstop_s, m.rebound);
    if (fill < 0.03) {
      EXPECT_TRUE(m.rebound) << "fill " << fill;
      EXPECT_LT(m.zstop_m, fill) << "through a 2 cm layer onto the floor";
    } else if (fill < 0.05) {
      rebounds_at_4cm += m.rebound;
    } else {
      EXPECT_FALSE(m.rebound) << "fill " << fill;
    }
    if (fill > 0.05 && fill < 0.09) shallow.push_back(m.zstop_m);
    if (fill >= 0.1 - 1e-9) plateau.push_back(m.zstop_m);
  }
  EXPECT_GE(rebounds_at_4cm, 1);
  ASSERT_EQ(plateau.size(), 6u);
  ASSERT_EQ(shallow.size(), 4u);
  const auto mean_of = [](const std::vector<double>& v) {
    double m = 0;
    for (double x : v) m += x / static_cast<double>(v.size());
    return m;
  };
  const double mean = mean_of(plateau);
  EXPECT_NEAR(mean, 0.0376, 0.001);
  for (double z : plateau) EXPECT_NEAR(z, mean, 0.07 * mean);
  EXPECT_GT(mean_of(shallow), 1.08 * mean);
  EXPECT_LT(mean_of(shallow), 1.20 * mean);
}

// Fig. 6 (part 4, REPRODUCTION.md): at 1 m/s and 1 g with mu_t = 0, zstop falls as mu_r grows to
// ~0.13 and is flat from 0.13 to 0.25 (the paper: "flat"; ours within 10 %, the bed-to-bed scatter
// of one drop per bed); inside the paper's axes, 2.5-5 cm. Recomputed from the committed traces
// (one bed per mu_r).
TEST(Reproduction, RollingFrictionDepthFallsThenFlattensAsFig6) {
  const auto drops = recomputed("rolling_friction");
  ASSERT_EQ(drops.size(), 6u);
  std::map<double, double> zstop_by_mur;
  for (const auto& d : drops) {
    EXPECT_NEAR(d.metrics.vc_m_s, 1.0, 0.03) << "the paper's Fig. 6 speed";
    zstop_by_mur[std::stod(d.swept.at("mu_rolling"))] = d.metrics.zstop_m;
  }
  ASSERT_EQ(zstop_by_mur.size(), 6u);
  double previous = 1.0;
  for (const auto& [mur, z] : zstop_by_mur) {
    EXPECT_GT(z, 0.025) << mur;
    EXPECT_LT(z, 0.05) << mur;
    if (mur > 0.13 + 1e-9) continue;
    EXPECT_LT(z, previous) << "mu_r " << mur << ": deeper than at the smaller mu_r";
    previous = z;
  }
  const double z0 = zstop_by_mur.at(0.0), z13 = zstop_by_mur.at(0.13);
  EXPECT_LT(z13, 0.8 * z0) << "falls by more than 20 % from mu_r 0 to 0.13";
  for (double mur : {0.2, 0.25}) EXPECT_NEAR(zstop_by_mur.at(mur), z13, 0.1 * z13) << "flat from 0.13 on: mu_r " << mur;
}

// dt check (Fig. 4, REPRODUCTION.md): the same bed and start at 5 and 1 us, zstop recomputed from
// the committed traces of both: within 2 %, or within the scatter of part 1b's three repeats at
// that speed where it is larger (0.35 m/s: 5.2 %), at each of the three speeds.
TEST(Reproduction, DtCheckMovesZstopByLessThanTwoPercentOrTheRepeatScatter) {
  const auto drops = recomputed("dt_check");
  ASSERT_EQ(drops.size(), 6u);
  std::map<double, std::map<double, double>> zstop;  // speed -> dt -> zstop
  for (const auto& d : drops)
    zstop[std::stod(d.swept.at("impact_speed_m_s"))][std::stod(d.swept.at("dt_s"))] = d.metrics.zstop_m;
  ASSERT_EQ(zstop.size(), 3u);
  const auto repeats = csv_rows("results_part1b_chrono_1g_sites.csv");
  for (const auto& [v, by_dt] : zstop) {
    ASSERT_EQ(by_dt.size(), 2u) << v;
    double lo = 1, hi = 0, sum = 0;
    int n = 0;
    for (const auto& r : repeats)
      if (std::abs(std::stod(r.at("impact_speed_m_s")) - v) < 1e-9) {
        const double z = std::stod(r.at("zstop_m"));
        lo = std::min(lo, z), hi = std::max(hi, z), sum += z, ++n;
      }
    ASSERT_EQ(n, 3) << v;
    const double scatter = (hi - lo) / (sum / n), rel = by_dt.at(1e-6) / by_dt.at(5e-6) - 1.0;
    EXPECT_LT(std::abs(rel), std::max(0.02, scatter))
        << v << " m/s: zstop " << by_dt.at(5e-6) << " m at 5 us, " << by_dt.at(1e-6) << " at 1 us";
  }
}

namespace {

/// Packing fraction of a bed's core (axis distance < 12 cm, 2-8 cm above the floor; Table 1's bulk
/// densities: 0.585-0.597 for pkdgrav, 0.57-0.585 for Chrono), by the engine's own measure.
double core_packing_fraction(const gravsweep::Particles& grains) {
  return gravsweep::core_packing_fraction(grains, 0.12, 0.02, 0.08);
}

/// The grains of a committed bed file.
gravsweep::Particles grains_of(const std::filesystem::path& bed) {
  gravsweep::Particles grains;
  gravsweep::results::read_bed(bed, grains);
  return grains;
}

/// Grains faster than `speed_m_s`, and how many of them lie in the bottom two layers (centre below
/// 1.5 diameters; a close-packed second layer sits at 1.32).
std::pair<int, int> fast_grains(const gravsweep::Particles& g, double speed_m_s) {
  int fast = 0, at_floor = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const gravsweep::Vec3& v = g.velocity_m_s[i];
    if (std::hypot(v[0], v[1], v[2]) <= speed_m_s) continue;
    ++fast;
    if (g.position_m[i].z() < 3 * g.radius_m[i]) ++at_floor;
  }
  return {fast, at_floor};
}

}  // namespace

// Why the first pkdgrav bed gave no reproduction (REPRODUCTION.md, part 5), checked on the committed
// beds: the monodisperse pkdgrav bed packed in order (core packing fraction 0.68, above random close
// packing's 0.64; Table 1 implies 0.58-0.60) where the Chrono bed (0.5 mm spread) is random (0.61),
// and its fastest grains, which keep it from the settling criteria, move at the floor.
TEST(Reproduction, ThePkdgravBedIsOrderedWithItsFastGrainsAtTheFloor) {
  namespace fs = std::filesystem;
  const fs::path beds = fs::path(GRAVSWEEP_SOURCE_DIR) / "data/reproduction/beds";
  const auto pkd = grains_of(beds / "ef2d61bc91083ece4a6c.h5");     // part 5, 9,333 grains
  const auto chrono = grains_of(beds / "bc8dcb3a1b26b1148049.h5");  // Chrono bed, 12 cm (part 3)
  const double phi_pkd = core_packing_fraction(pkd), phi_chrono = core_packing_fraction(chrono);
  const auto [fast_pkd, floor_pkd] = fast_grains(pkd, 1e-2);
  const auto [fast_chrono, floor_chrono] = fast_grains(chrono, 1e-3);
  std::printf(
      "core packing fraction: pkdgrav bed %.3f, Chrono bed %.3f; grains > 1 cm/s in the pkdgrav bed: %d "
      "(%d in the bottom two layers); > 1 mm/s in the Chrono bed: %d\n",
      phi_pkd, phi_chrono, fast_pkd, floor_pkd, fast_chrono);
  EXPECT_GT(phi_pkd, 0.66) << "ordered: above random close packing (0.64)";
  EXPECT_LT(phi_chrono, 0.64) << "random packing";
  EXPECT_GE(fast_pkd, 5);
  EXPECT_EQ(floor_pkd, fast_pkd) << "every fast grain of the pkdgrav bed lies in its bottom two layers";
  EXPECT_EQ(fast_chrono, 0);
}

/// The floor grains of a bed (centre within 1 % of a radius of the floor at z = 0) faster than
/// `speed_m_s`, and the fastest spin about the vertical among them (rad/s).
std::pair<int, double> fast_floor_grains(const gravsweep::Particles& g, double speed_m_s) {
  int fast = 0;
  double spin_z = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const gravsweep::Vec3& v = g.velocity_m_s[i];
    if (g.position_m[i].z() >= 1.01 * g.radius_m[i] || std::hypot(v[0], v[1], v[2]) <= speed_m_s) continue;
    ++fast;
    spin_z = std::max(spin_z, std::abs(g.omega_rad_s[i].z()));
  }
  return {fast, spin_z};
}

// Part 5's bed (1.5 d placement lattice, REPRODUCTION.md) before and after the rolling and twisting
// sliders were held at their limit (docs/physics/contact-laws.md section 2.3). Before (2ea3209e,
// settled 1 s): grains on the floor rolled at over 1 cm/s spinning about the vertical, driven by
// latched springs, and the bed was at rest only for impacts of 0.92 m/s and more. After
// (6d841ee0, the same preparation with Table 1's e_t = 1, settled to the criteria): no grain moves
// at 1 mm/s, the bed is at rest for every part 5 impact (0.2-1.2 m/s) and still random at Table
// 1's density.
TEST(Reproduction, ThePkdgravBedComesToRestOnceItsSlidersAreHeldAtTheLimit) {
  namespace fs = std::filesystem;
  const fs::path beds = fs::path(GRAVSWEEP_SOURCE_DIR) / "data/reproduction/beds";
  const auto latched = grains_of(beds / "2ea3209e0f33f5075120.h5");  // 8,533 grains
  gravsweep::Particles held;
  const auto held_facts = gravsweep::results::read_bed(beds / "6d841ee06ff86eaf48d9.h5", held);  // 8,538 grains
  const auto [fast_before, spin_before] = fast_floor_grains(latched, 1e-2);
  const auto [fast_after, spin_after] = fast_floor_grains(held, 1e-3);
  const auto [fast_anywhere, floor_unused] = fast_grains(held, 1e-3);
  const double phi = core_packing_fraction(held);
  std::printf(
      "latched sliders: %d floor grains > 1 cm/s, spinning about z at up to %.1f rad/s; held at the limit: %d "
      "floor grains (%d grains anywhere) > 1 mm/s; core packing fraction %.3f\n",
      fast_before, spin_before, fast_after, fast_anywhere, phi);
  EXPECT_GE(fast_before, 5);
  EXPECT_GT(spin_before, 5.0) << "the latched twisting springs spun the floor grains about the vertical";
  EXPECT_EQ(fast_anywhere, 0);
  const auto report = nlohmann::json::parse(held_facts.report_json);
  EXPECT_EQ(report.at("settle_end"), "criteria");
  EXPECT_LT(report.at("rms_speed_m_s").get<double>(), 1e-5);
  EXPECT_LT(report.at("at_rest_for_impacts_above_m_s").get<double>(), 0.2) << "part 5's slowest impact";
  EXPECT_GT(phi, 0.58) << "Table 1's pkdgrav bulk density 1.45-1.48 g/cm3: 0.585-0.597";
  EXPECT_LT(phi, 0.60);
}

// Every committed drop (a row of any results CSV under data/) comes from a clean build, on a bed
// that is committed beside it (data/<dataset>/beds/<bed job>.h5) and was prepared by a clean
// build; every dataset's provenance.json agrees. A bed of a build with uncommitted changes may be
// kept as evidence (REPRODUCTION.md's bed table) but no committed drop stands on it.
TEST(Reproduction, NoCommittedDropComesFromOrStandsOnABuildWithUncommittedChanges) {
  namespace fs = std::filesystem;
  const fs::path data = fs::path(GRAVSWEEP_SOURCE_DIR) / "data";
  const auto dirty = [](const std::string& version) { return version.find("dirty") != std::string::npos; };
  std::map<std::string, std::string> bed_version;  // bed job id -> code version
  for (const auto& dataset : fs::directory_iterator(data)) {
    if (!fs::is_directory(dataset.path() / "beds")) continue;
    for (const auto& f : fs::directory_iterator(dataset.path() / "beds"))
      if (f.path().extension() == ".h5")
        bed_version[f.path().stem().string()] = gravsweep::results::read_bed(f.path()).code_version;
  }
  ASSERT_GE(bed_version.size(), 20u);
  int drops = 0, provenances = 0;
  for (const auto& f : fs::recursive_directory_iterator(data)) {
    const std::string name = f.path().filename().string();
    if (name == "provenance.json") {
      std::ifstream in(f.path());
      const auto p = nlohmann::json::parse(in);
      for (const char* key : {"drops_by_code_version", "beds_by_code_version"}) {
        const nlohmann::json versions = p.value(key, nlohmann::json::object());
        for (const auto& [version, count] : versions.items())
          EXPECT_FALSE(dirty(version)) << f.path() << " " << key << ": " << version;
      }
      ++provenances;
      continue;
    }
    if (f.path().extension() != ".csv" || name.rfind("results", 0) != 0) continue;
    for (const auto& row : csv_rows(fs::relative(f.path(), data / "reproduction").string())) {
      if (row.count("bed_job_id") == 0 || row.at("bed_job_id").empty()) continue;
      ++drops;
      EXPECT_FALSE(dirty(row.at("code_version"))) << f.path() << ": drop " << row.at("job_id");
      const auto bed = bed_version.find(row.at("bed_job_id"));
      ASSERT_NE(bed, bed_version.end()) << f.path() << ": drop " << row.at("job_id") << " stands on bed "
                                        << row.at("bed_job_id") << ", which is not committed";
      EXPECT_FALSE(dirty(bed->second)) << f.path() << ": drop " << row.at("job_id") << " stands on bed " << bed->first
                                       << " of " << bed->second;
    }
  }
  EXPECT_GE(drops, 100) << "the results tables were read";
  EXPECT_GE(provenances, 8);
}
