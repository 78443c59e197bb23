// Table 2 of Sunday et al. 2021 (REPRODUCTION.md, "Table 2"): the committed angles of repose of the
// pkdgrav set (`gravsweep pile --set pkdgrav`, data/reproduction/results_table2_repose.csv) beside
// the paper's: each within 2 degrees of the paper's, and rising with the shape parameter beta at
// mu_r 1.05 as the paper's does.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "gravity_sweep_helpers.h"

TEST(Reproduction, TheCommittedAnglesOfReposeFollowTableTwo) {
  const auto path = std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "reproduction" / "results_table2_repose.csv";
  std::ifstream in(path);
  ASSERT_TRUE(in) << path;
  std::map<double, double> by_beta;  // mu_r 1.05: beta -> angle (deg)
  int rows = 0;
  for (const auto& r : gravsweep::testing::sweep::csv_table_rows(in)) {
    ++rows;
    const double ours = std::stod(r.at("repose_angle_deg")), paper = std::stod(r.at("paper_table2_deg"));
    EXPECT_LT(std::abs(ours - paper), 2.0) << "mu_r " << r.at("mu_rolling") << ", beta " << r.at("shape_beta");
    EXPECT_EQ(r.at("code_version").find("dirty"), std::string::npos) << "a clean build";
    if (std::abs(std::stod(r.at("mu_rolling")) - 1.05) < 1e-9) by_beta[std::stod(r.at("shape_beta"))] = ours;
  }
  EXPECT_GE(rows, 3);
  ASSERT_GE(by_beta.size(), 2u);
  EXPECT_GT(by_beta.rbegin()->second, by_beta.begin()->second) << "the angle rises with beta";
}
