// Helpers for the tests of the committed gravity sweep (data/gravity_sweep/, GRAVITY.md): the real
// binary's CSV rows, the committed folders, and per-Froude means of a folder's drops.
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "results/io/csv.h"
#include "results/measurements/campaign.h"
#include "results_helpers.h"

namespace gravsweep::testing::sweep {

/// The rows of a CSV table with a header line, each by column name.
inline std::vector<std::map<std::string, std::string>> csv_table_rows(std::istream& in) {
  gravsweep::results::CsvReader csv(in);
  std::vector<std::string> header, cells;
  std::vector<std::map<std::string, std::string>> rows;
  int line = 0;
  if (!csv.next(header, line)) return rows;
  while (csv.next(cells, line)) {
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
    rows.push_back(row);
  }
  return rows;
}

/// The rows of `gravsweep <args> --format csv`, each by column name.
inline std::vector<std::map<std::string, std::string>> csv_rows(const std::string& args, std::string& out) {
  const auto r = gravsweep::testing::run_gravsweep(args + " --format csv", false);
  out = r.out;
  if (r.code != 0) return {};
  std::istringstream in(r.out);
  return csv_table_rows(in);
}

/// One committed folder of the gravity sweep as a quoted command-line argument, with a space before.
inline std::string level_folder(const char* level) {
  return " '" + (std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "gravity_sweep" / level).string() + "'";
}

/// The eight committed folders of the gravity sweep: five levels, 50 drops (GRAVITY.md).
inline std::string sweep_levels() {
  std::string s;
  for (const char* level : {"g9.81", "g1.62", "g0.1", "g0.1_axis", "g0.01", "g0.01_axis", "g0.001", "g0.001_axis"})
    s += level_folder(level);
  return s;
}

/// A committed folder of the gravity sweep (data/gravity_sweep/<folder>).
inline std::string sweep_folder(const char* folder) {
  return (std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "gravity_sweep" / folder).string();
}

/// Mean of a metric (m) of a folder's drops at each design Froude number (rounded to 0.1),
/// processed in the drops' own scales: zstop from the first contact by default, or from the bed's
/// mean surface (Metrics::zstop_surface_m).
inline std::map<double, double> zstop_by_froude(
    const std::vector<const char*>& folders,
    double gravsweep::results::Metrics::*depth = &gravsweep::results::Metrics::zstop_m) {
  using namespace gravsweep::results;
  std::map<double, std::vector<double>> z;
  for (const char* f : folders) {
    Campaign c = load_campaign(sweep_folder(f));
    reprocess_campaign(c, {"froude", ""});
    for (const auto& t : c.trials) {
      const double fr = t.processed.metrics.vc_m_s / std::sqrt(t.info.gravity_m_s2 * t.info.projectile_diameter_m);
      z[std::round(fr * 10) / 10].push_back(t.processed.metrics.*depth);
    }
  }
  std::map<double, double> mean;
  for (const auto& [fr, v] : z) {
    double s = 0;
    for (double x : v) s += x;
    mean[fr] = s / static_cast<double>(v.size());
  }
  return mean;
}

/// The deep bed's eight folders (GRAVITY.md, "Confinement, Fr 2 to 10"): one per export.
inline const std::vector<const char*> kDeepBed{
    "g0.01_deep",           "g0.01_deep_fr10",      "g0.01_deep_fr2_3",     "g0.01_deep_fr10_site2",
    "g0.01_deep_fr2_site3", "g0.01_deep_fr2_site4", "g0.01_deep_fr3_site3", "g0.01_deep_fr3_site4"};

/// A fitted constant of `gravsweep model fit ... --format csv`: {value, standard error}.
inline std::pair<double, double> fitted(const std::vector<std::map<std::string, std::string>>& rows,
                                        const std::string& name) {
  for (const auto& r : rows)
    if (r.count("parameter") && r.at("parameter") == name)
      return {std::stod(r.at("value")), std::stod(r.at("std_error"))};
  ADD_FAILURE() << "no fitted " << name;
  return {0, 1};
}

/// Fits the scaled law on the five levels' 21 cm beds and saves it in `dir` (`model fit --save`,
/// 30 bootstrap resamples); returns the law file's path, for `model predict --law`.
inline std::string fitted_sweep_law(const std::filesystem::path& dir) {
  const std::string law = (dir / "law.json").string();
  std::string out;
  csv_rows("model fit" + sweep_levels() + " --model scaled_base+gravity_depth_friction --resamples 30 --plot '" +
               (dir / "error_falls.png").string() + "' --save '" + law + "'",
           out);
  return law;
}

/// Every drop of a deep-bed folder stops at least 2 D above the floor (the fill height is the
/// floor's depth below the surface). From the wall they stay 1.9 D or more by design: the 26 cm
/// radius less the projectile's 5 cm and a site within two grain diameters of the axis.
inline void expect_two_diameters_above_the_floor(const char* folder) {
  using namespace gravsweep::results;
  Campaign c = load_campaign(sweep_folder(folder));
  reprocess_campaign(c, {"froude", ""});
  ASSERT_FALSE(c.trials.empty()) << folder;
  for (const auto& t : c.trials)
    EXPECT_GE((t.info.fill_height_m - t.processed.metrics.zstop_m) / t.info.projectile_diameter_m, 2.0)
        << folder << " " << t.info.trial_id;
}

}  // namespace gravsweep::testing::sweep
