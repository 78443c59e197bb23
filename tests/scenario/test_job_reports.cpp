// The records a bed job and a drop job report (results/io/job_reports.h): one field table each,
// no key shared with the paper's metrics, and a round trip through JSON (the bed file's `report`).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "results/io/job_reports.h"
#include "results/processing/metric_fields.h"

namespace gravsweep::results {
namespace {

TEST(JobReports, NoDemFigureHasTheKeyOfAMetric) {
  // A shared key would let one record replace the other's value in a drop's results (the DEM's
  // final depth below the surface once replaced the processed final depth from the collision start).
  std::set<std::string> metrics;
  for (const auto& f : metric_fields()) metrics.insert(f.key);
  for (const auto& f : dem_figure_fields()) EXPECT_EQ(metrics.count(f.key), 0u) << f.key;
  EXPECT_TRUE(metrics.count("final_depth_m"));
}

TEST(JobReports, EveryFieldHasOneMemberAndAUnitAndAUniqueKey) {
  const auto check = [](const auto& fields) {
    std::set<std::string> keys;
    for (const auto& f : fields) {
      const int members = !!f.number + !!f.maybe + !!f.count + !!f.flag + !!f.text;
      EXPECT_EQ(members, 1) << f.key;
      EXPECT_TRUE(keys.insert(f.key).second) << f.key << " twice";
      EXPECT_TRUE(f.text || std::string(f.unit) != "") << f.key << " has no unit";
    }
  };
  check(dem_figure_fields());
  check(bed_summary_fields());
}

TEST(JobReports, ABedReportRoundTripsAndAnOlderOneReadsWhatItHas) {
  BedSummary b;
  b.grains_kept = 18220;
  b.settled = true;
  b.settle_end = "criteria";
  b.bulk_density_kg_m3 = 1445.5;
  b.at_rest_for_impacts_above_m_s = std::nullopt;  // an infinite bound is written as null
  b.resumed_at_s = 2.5;
  const BedSummary back = bed_summary_of_json(nlohmann::json::parse(to_json(b).dump()), "test");
  EXPECT_EQ(back.grains_kept, 18220);
  EXPECT_TRUE(back.settled);
  EXPECT_EQ(back.settle_end, "criteria");
  EXPECT_EQ(back.bulk_density_kg_m3, 1445.5);
  EXPECT_FALSE(back.at_rest_for_impacts_above_m_s.has_value());
  EXPECT_EQ(back.resumed_at_s, 2.5);
  EXPECT_TRUE(std::isnan(back.settle_time_s)) << "a NaN is written as null and read back as not recorded";

  // A bed of an older build that did not record the surface's speeds.
  const BedSummary old =
      bed_summary_of_json(nlohmann::json{{"grains_kept", 8595}, {"bulk_density_kg_m3", 1500.0}}, "old");
  EXPECT_EQ(old.grains_kept, 8595);
  EXPECT_TRUE(std::isnan(old.max_surface_speed_m_s));

  try {
    (void)bed_summary_of_json(nlohmann::json{{"grains_kept", "many"}}, "bed x.h5 report");
    FAIL() << "a text count was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bed x.h5 report: /grains_kept is string, expected an integer"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace gravsweep::results
