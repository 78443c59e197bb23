// The records a bed job and a drop job report (results/io/job_reports.h): one field table each,
// no key shared with the paper's metrics, a drop's figures read from its own record, and a round
// trip through JSON (the bed file's `report`).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

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
      int members = !!f.number + !!f.maybe + !!f.count + !!f.flag;
      if constexpr (requires { f.text; }) members += !!f.text;
      EXPECT_EQ(members, 1) << f.key;
      EXPECT_TRUE(keys.insert(f.key).second) << f.key << " twice";
      EXPECT_TRUE(std::string(f.unit) != "" || std::string(f.sql_type()) == "TEXT") << f.key << " has no unit";
    }
  };
  check(dem_figure_fields());
  check(bed_summary_fields());
}

TEST(JobReports, TheDemFiguresAreReadFromTheDropsOwnRecord) {
  // No record of copies: each figure is read where the drop holds it (the trace, the engine's
  // result, the metrics, the run's facts), the depths and durations computed from them.
  DropRecord d;
  d.trace.raw.t_s = {0.0, 0.1, 0.2};
  d.trace.raw.depth_m = {-0.01, 0.03, 0.02};
  d.trace.dt_s = 1e-5;
  d.trace.info.sample_rate_hz = 10.0;
  d.trace.info.fill_height_m = 0.0625;  // the measured surface; binary fractions: exact differences
  d.trace.release_height_m = 0.078125;
  d.trace.release_speed_m_s = 0.5;
  d.trace.stopped = true;
  d.result.first_touch_height_m = 0.0703125;
  d.result.first_contact_s = 0.05;
  d.result.rest_s = 0.375;
  d.result.steps = 20000;
  d.result.grains_spilled = 3;
  d.bed_grains = 2200;
  d.threads = 2;
  d.checkpoints.written = 1;
  const auto json_of = [&] { return nlohmann::json::parse(record_json(d, dem_figure_fields()).dump()); };
  nlohmann::json j = json_of();
  EXPECT_EQ(j["max_depth_m"], 0.03);
  EXPECT_EQ(j["final_depth_below_surface_m"], 0.02);
  EXPECT_EQ(j["simulated_time_s"], 0.2);
  EXPECT_EQ(j["stopped"], true);
  EXPECT_EQ(j["grains_spilled_over_rim"], 3);
  EXPECT_EQ(j["steps"], 20000);
  EXPECT_EQ(j["grains"], 2200);
  EXPECT_EQ(j["threads"], 2);
  EXPECT_EQ(j["checkpoints_written"], 1);
  EXPECT_EQ(j["first_contact_s"], 0.05);
  EXPECT_EQ(j["rest_time_s"], 0.375);
  EXPECT_TRUE(j["duration_to_rest_s"].is_null()) << "no metrics: no collision start";
  EXPECT_TRUE(j["resumed_at_s"].is_null());
  EXPECT_EQ(j["release_height_above_surface_m"], 0.015625);
  EXPECT_EQ(j["first_touch_height_above_surface_m"], 0.0078125);
  // Measured: the metrics are the ones processing made in the trace record (no copy beside it).
  d.trace.processed.metrics.t_start_s = 0.125;
  EXPECT_EQ(d.metrics(), nullptr);
  d.measured = true;
  EXPECT_EQ(d.metrics(), &d.trace.processed.metrics);
  j = json_of();
  EXPECT_EQ(j["duration_to_rest_s"], 0.25);
  // Every key of the table, once.
  std::vector<std::string> keys;
  const nlohmann::json all = record_json(d, dem_figure_fields());
  for (const auto& [key, value] : all.items()) keys.push_back(key);
  std::vector<std::string> table;
  for (const auto& f : dem_figure_fields()) table.emplace_back(f.key);
  std::sort(table.begin(), table.end());  // nlohmann::json objects iterate by key
  EXPECT_EQ(keys, table);
}

TEST(JobReports, OneFieldTableTypeReadsAMemberOrAGetterAndReadsBackOnlyMembers) {
  // The bed's report (members) and the drop's figures (getters) are rows of one RecordField type,
  // written to JSON by one field_json; only a member can be read back from JSON.
  BedSummary b;
  b.steps = 7;
  const auto& bed = bed_summary_fields();
  const auto steps = std::find_if(bed.begin(), bed.end(), [](const auto& f) { return std::string(f.key) == "steps"; });
  ASSERT_NE(steps, bed.end());
  EXPECT_TRUE(steps->count.member && !steps->count.getter);
  EXPECT_EQ(field_json(b, *steps), 7);
  DropRecord d;
  d.result.steps = 9;
  const auto& dem = dem_figure_fields();
  const auto figure = std::find_if(dem.begin(), dem.end(), [](const auto& f) { return std::string(f.key) == "steps"; });
  ASSERT_NE(figure, dem.end());
  EXPECT_TRUE(figure->count.getter && !figure->count.member);
  EXPECT_EQ(field_json(d, *figure), 9);
  EXPECT_EQ(std::string(figure->sql_type()), "INTEGER");
  EXPECT_THROW(record_of_json(nlohmann::json{{"steps", 9}}, dem, "figures"), std::logic_error);
  EXPECT_EQ(record_of_json(nlohmann::json{{"steps", 9}}, bed, "report").steps, 9);
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
