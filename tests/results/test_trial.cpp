// The one trial record (results/measurements/trial.h), its readers (lab CSV, DEM trace.h5) and the
// one processing entry (process_trial), on real files: field table and JSON, the gravity-level
// rule, RFC 4180 CSV with a BOM, trace paths kept inside the campaign folder, declared sample rate
// against the timestamps, gaps, bias removal from the source, DEM and lab agreeing.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "poncelet.h"
#include "results/io/trace_file.h"
#include "results/measurements/campaign.h"
#include "results/io/csv.h"
#include "results/io/table.h"
#include "results_helpers.h"

using namespace gravsweep::results;
using gravsweep::testing::Poncelet;
using gravsweep::testing::TempDir;
namespace fs = std::filesystem;

namespace {

constexpr const char* kHeader =
    "trial_id,trace_file,gravity_m_s2,impact_velocity_m_s,fill_height_m,projectile_mass_kg,"
    "projectile_diameter_m,grain_diameter_m,bulk_density_kg_m3,sample_rate_hz";

/// A lab record of a Poncelet collision: free fall from t = 0, contact at t_contact, rest after.
/// `with_zv` adds the optional position_m/velocity_m_s columns.
void write_lab_trace(const fs::path& p, const Poncelet& k, double fs_hz, double bias_m_s2, bool with_zv,
                     double t_contact = 0.0213457) {
  fs::create_directories(p.parent_path());
  std::ofstream f(p);
  f << (with_zv ? "t_s,accel_m_s2,position_m,velocity_m_s\n" : "t_s,accel_m_s2\n");
  const double T = t_contact + k.tstop() + 0.08;
  for (int i = 0; i / fs_hz < T; ++i) {
    const double t = i / fs_hz;
    f << t << "," << k.accel_up(t - t_contact) + bias_m_s2;
    if (with_zv) {
      double v, z;
      k.state(t - t_contact, v, z);
      f << "," << z << "," << v;
    }
    f << "\n";
  }
}

/// The same collision as a DEM trace.h5 (no sensor: v and z exact, bias 0).
void write_dem_trace(const fs::path& p, const Poncelet& k, double fs_hz, const std::string& scenario_json,
                     double t_contact = 0.0213457) {
  TraceData d;
  const double T = t_contact + k.tstop() + 0.08;
  for (int i = 0; i / fs_hz < T; ++i) {
    const double t = i / fs_hz;
    double v, z;
    k.state(t - t_contact, v, z);
    d.raw.t_s.push_back(t);
    d.raw.depth_m.push_back(z);
    d.raw.velocity_down_m_s.push_back(v);
    d.raw.accel_up_m_s2.push_back(k.accel_up(t - t_contact));
    for (int c = 0; c < 3; ++c) {
      d.omega_rad_s.push_back(0.0);
      d.position_m.push_back(c == 2 ? 0.2 - z : 0.0);
    }
    d.contacts.push_back(t >= t_contact ? 5 : 0);
    d.grain_kinetic_energy_J.push_back(0.0);
  }
  d.info.sample_rate_hz = fs_hz;
  d.dt_s = 1e-5;
  d.info.gravity_m_s2 = k.g;
  d.info.fill_height_m = 0.1;
  d.release_height_m = 0.15;
  d.release_speed_m_s = k.v0 - k.g * t_contact;
  d.info.projectile_diameter_m = 0.1;
  d.info.projectile_mass_kg = k.m;
  d.info.grain_diameter_m = 0.01;
  d.stopped = true;
  d.scenario_json = scenario_json;
  d.bed_key_json = "{}";
  d.metrics_json = "{\"vc_m_s\": " + std::to_string(k.v0) + "}";
  d.info.code_version = "test";
  fs::create_directories(p.parent_path());
  write_trace(p, d);
}

std::string row(const std::string& id, const std::string& trace, double g = 9.81, double v0 = 0.8, double rate = 1400) {
  std::ostringstream s;
  s << id << "," << trace << "," << g << "," << v0 << ",0.1,1.0,0.1,0.01,1450," << rate;
  return s.str();
}

void write_text(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

bool has_issue(const Campaign& c, const std::string& where, const std::string& what) {
  for (const auto& is : c.issues)
    if (is.to_string().find(where) != std::string::npos && is.message.find(what) != std::string::npos) return true;
  return false;
}

std::string issues_of(const Campaign& c) {
  std::string s;
  for (const auto& is : c.issues) s += is.to_string() + "\n";
  return s;
}

}  // namespace

TEST(TrialRecord, OneFieldTableGivesCsvSqlAndJsonNamesAndRoundTrips) {
  std::set<std::string> keys;
  for (const auto& f : trial_fields()) {
    EXPECT_TRUE(keys.insert(f.key).second) << "field listed twice: " << f.key;
    EXPECT_TRUE((f.number != nullptr) != (f.text != nullptr)) << f.key;
  }
  // The required columns of docs/formats/measurements.md section 2.1, no more, no less.
  std::set<std::string> required;
  for (const auto& f : trial_fields())
    if (f.csv_required) required.insert(f.key);
  EXPECT_EQ(required, (std::set<std::string>{"trial_id", "trace_file", "gravity_m_s2", "impact_speed_m_s",
                                             "fill_height_m", "projectile_mass_kg", "projectile_diameter_m",
                                             "grain_diameter_m", "bulk_density_kg_m3", "sample_rate_hz"}));
  Trial t;
  t.trial_id = "J1";
  t.source = TraceSource::dem;
  t.gravity_m_s2 = 1.62;
  t.filter_cutoff_hz = 250;
  t.job_id = "abc";
  t.attributes["operator"] = "x";
  const nlohmann::json j = t;
  EXPECT_EQ(j.at("source"), "dem");
  EXPECT_EQ(j.at("gravity_m_s2"), 1.62);
  const Trial back = j.get<Trial>();
  EXPECT_EQ(back.source, TraceSource::dem);
  EXPECT_EQ(back.filter_cutoff_hz, 250);
  EXPECT_EQ(back.job_id, "abc");
  EXPECT_EQ(back.attributes.at("operator"), "x");
  // MetricOptions come from the trial.
  const MetricOptions o = metric_options(back);
  EXPECT_EQ(o.cutoff_hz, 250);
  EXPECT_EQ(o.gravity_m_s2, 1.62);
}

TEST(TrialRecord, OneGravityLevelRule) {
  EXPECT_TRUE(same_gravity_level(1.62, 1.6200000001));
  EXPECT_FALSE(same_gravity_level(1.62, 1.63));
  EXPECT_EQ(gravity_levels_of({1.62, 9.81, 1.6200000001, 0.1}), (std::vector<double>{9.81, 1.62, 0.1}));
}

TEST(Csv, Rfc4180QuotingAndAByteOrderMark) {
  std::istringstream in(
      "\xEF\xBB\xBF"
      "a,b,c\r\n\"9.81\",\"x, y\",\"say \"\"hi\"\"\"\r\n\r\n 1 ,\"two\nlines\",3\n");
  CsvReader r(in);
  std::vector<std::string> f;
  int line = 0;
  ASSERT_TRUE(r.next(f, line));
  EXPECT_EQ(f, (std::vector<std::string>{"a", "b", "c"}));
  ASSERT_TRUE(r.next(f, line));
  EXPECT_EQ(line, 2);
  EXPECT_EQ(f, (std::vector<std::string>{"9.81", "x, y", "say \"hi\""}));
  ASSERT_TRUE(r.next(f, line));
  EXPECT_EQ(line, 4);
  EXPECT_EQ(f, (std::vector<std::string>{"1", "two\nlines", "3"}));
  EXPECT_FALSE(r.next(f, line));
  std::istringstream bad("a,\"open\n");
  CsvReader rb(bad);
  EXPECT_THROW(rb.next(f, line), CsvSyntaxError);
  EXPECT_EQ(csv_field("x, \"y\""), "\"x, \"\"y\"\"\"");
}

// The verbs' table writer (results/io/table.h) writes CSV that the reader reads back: a comma
// or a quote in a value does not shift the columns (it wrote them bare before).
TEST(Csv, TableWriterQuotesCommasAndQuotesAndReadsBack) {
  Table t({"trial_id", "note"});
  t.add({"T1", "rebound, then rest"});
  t.add({"T \"2\"", "plain"});
  std::istringstream in(t.render("csv"));
  CsvReader r(in);
  std::vector<std::string> f;
  int line = 0;
  ASSERT_TRUE(r.next(f, line));
  EXPECT_EQ(f, (std::vector<std::string>{"trial_id", "note"}));
  ASSERT_TRUE(r.next(f, line));
  EXPECT_EQ(f, (std::vector<std::string>{"T1", "rebound, then rest"}));
  ASSERT_TRUE(r.next(f, line));
  EXPECT_EQ(f, (std::vector<std::string>{"T \"2\"", "plain"}));
  EXPECT_FALSE(r.next(f, line));
}

TEST(LabCampaign, TrialsCsvWithBomAndQuotedNumbersIsRead) {
  TempDir d;
  Poncelet k;
  write_lab_trace(d.path / "traces/A.csv", k, 1400, 0.0, false);
  write_text(d.path / "trials.csv", std::string("\xEF\xBB\xBF") + kHeader + "\r\n" +
                                        "\"A\",\"traces/A.csv\",\"9.81\",\"0.8\",\"0.1\",\"1.0\",\"0.1\",\"0.01\","
                                        "\"1450\",\"1400\"\r\n");
  const Campaign c = load_campaign(d.str());
  ASSERT_EQ(c.trials.size(), 1u) << issues_of(c);
  EXPECT_EQ(c.trials[0].info.gravity_m_s2, 9.81);
  EXPECT_NEAR(c.trials[0].processed.metrics.apeak_m_s2, k.apeak(), 0.03 * k.apeak());
}

// The impact speed has one name, impact_speed_m_s; the laboratory format's impact_velocity_m_s
// (and files gravsweep wrote before) are read as it, in a trials.csv header and as a JSON key.
TEST(LabCampaign, TheLabFormatsImpactVelocityColumnIsReadAsTheImpactSpeed) {
  TempDir d;
  Poncelet k;
  write_lab_trace(d.path / "old/traces/A.csv", k, 1400, 0.0, false);
  write_lab_trace(d.path / "new/traces/A.csv", k, 1400, 0.0, false);
  std::string renamed = kHeader;
  renamed.replace(renamed.find("impact_velocity_m_s"), std::string("impact_velocity_m_s").size(), "impact_speed_m_s");
  write_text(d.path / "old/trials.csv", std::string(kHeader) + "\n" + row("A", "traces/A.csv", 9.81, 0.8) + "\n");
  write_text(d.path / "new/trials.csv", renamed + "\n" + row("A", "traces/A.csv", 9.81, 0.8) + "\n");
  const Campaign a = load_campaign((d.path / "old").string()), b = load_campaign((d.path / "new").string());
  ASSERT_EQ(a.trials.size(), 1u) << issues_of(a);
  ASSERT_EQ(b.trials.size(), 1u) << issues_of(b);
  EXPECT_EQ(a.trials[0].info.impact_speed_m_s, 0.8);
  EXPECT_EQ(b.trials[0].info.impact_speed_m_s, 0.8);
  EXPECT_TRUE(a.trials[0].info.attributes.empty()) << "the older name is the field, not an extra column";
  EXPECT_EQ(nlohmann::json(a.trials[0].info).count("impact_velocity_m_s"), 0u) << "nothing is written under it";
  const Trial from_old_json = nlohmann::json{{"trial_id", "J"}, {"impact_velocity_m_s", 0.5}}.get<Trial>();
  EXPECT_EQ(from_old_json.impact_speed_m_s, 0.5);
  // Both names in one header: refused, naming both (never one kept as an attribute beside the other).
  write_text(d.path / "both/trials.csv", renamed + ",impact_velocity_m_s\n" + row("A", "traces/A.csv") + ",0.7\n");
  try {
    load_campaign((d.path / "both").string());
    FAIL() << "a header with both names was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'impact_velocity_m_s' and 'impact_speed_m_s'"), std::string::npos)
        << e.what();
  }
}

TEST(LabCampaign, TracePathsOutsideTheCampaignFolderAreRefusedWithTheRow) {
  TempDir d;
  Poncelet k;
  const fs::path camp = d.path / "camp";
  write_lab_trace(d.path / "outside/X.csv", k, 1400, 0.0, false);  // a valid trace, but outside
  write_lab_trace(camp / "traces/ok.csv", k, 1400, 0.0, false);
  fs::create_directories(camp / "traces");
  fs::create_symlink(d.path / "outside/X.csv", camp / "traces/link.csv");
  fs::create_directory_symlink(d.path / "outside", camp / "traces/dirlink");
  write_text(camp / "trials.csv", std::string(kHeader) + "\n" + row("T1", "../outside/X.csv") + "\n" +
                                      row("T2", "traces/../../outside/X.csv") + "\n" + row("T3", "/etc/passwd") + "\n" +
                                      row("T4", "traces/link.csv") + "\n" + row("T5", "traces/dirlink/X.csv") + "\n" +
                                      row("T6", "traces/ok.csv") + "\n");
  const Campaign c = load_campaign(camp.string());
  ASSERT_EQ(c.trials.size(), 1u) << issues_of(c);
  EXPECT_EQ(c.trials[0].info.trial_id, "T6");
  for (int line = 2; line <= 6; ++line)
    EXPECT_TRUE(has_issue(c, "trials.csv:" + std::to_string(line) + ":2", "inside the campaign folder"))
        << "line " << line << "\n"
        << issues_of(c);
}

TEST(LabCampaign, DeclaredSampleRateIsCheckedAgainstTheTimestamps) {
  TempDir d;
  Poncelet k;
  write_lab_trace(d.path / "traces/A.csv", k, 1400, 0.0, false);
  write_text(d.path / "trials.csv", std::string(kHeader) + "\n" + row("A", "traces/A.csv", 9.81, 0.8, 14000) + "\n");
  const Campaign c = load_campaign(d.str());
  EXPECT_TRUE(c.trials.empty());
  EXPECT_TRUE(has_issue(c, "trials.csv:2:10", "declared 14000 Hz")) << issues_of(c);
}

TEST(LabCampaign, AGapInsideTheRecordIsRefusedWithItsLine) {
  TempDir d;
  Poncelet k;
  write_lab_trace(d.path / "traces/A.csv", k, 1400, 0.0, false);
  // Drop 20 samples inside the collision (lines 40..59 of the file).
  std::ifstream in(d.path / "traces/A.csv");
  std::string text, l;
  int n = 0;
  while (std::getline(in, l))
    if (++n < 40 || n >= 60) text += l + "\n";
  write_text(d.path / "traces/A.csv", text);
  write_text(d.path / "trials.csv", std::string(kHeader) + "\n" + row("A", "traces/A.csv") + "\n");
  const Campaign c = load_campaign(d.str());
  EXPECT_TRUE(c.trials.empty());
  EXPECT_TRUE(has_issue(c, "traces/A.csv:40:1", "gap")) << issues_of(c);
  EXPECT_TRUE(has_issue(c, "traces/A.csv:40:1", "20 samples missing")) << issues_of(c);
}

TEST(OneEntry, ALabRecordWithPositionAndVelocityColumnsStillGetsItsBiasRemoved) {
  TempDir d;
  Poncelet k;
  const double bias = 0.05 * 9.81;
  write_lab_trace(d.path / "traces/A.csv", k, 1400, bias, true);
  write_text(d.path / "trials.csv", std::string(kHeader) + "\n" + row("A", "traces/A.csv") + "\n");
  const Campaign c = load_campaign(d.str());
  ASSERT_EQ(c.trials.size(), 1u) << issues_of(c);
  EXPECT_EQ(c.trials[0].info.source, TraceSource::lab);
  EXPECT_NEAR(c.trials[0].processed.bias_m_s2, bias, 0.05 * bias);
}

TEST(OneEntry, ADemTrialAndALabTrialWithTheSameKinematicsGiveTheSameMetrics) {
  TempDir d;
  Poncelet k;
  write_lab_trace(d.path / "lab/traces/A.csv", k, 10000, 0.0, false);
  write_text(d.path / "lab/trials.csv",
             std::string(kHeader) + "\n" + row("A", "traces/A.csv", 9.81, 0.8, 10000) + "\n");
  const Campaign lab = load_campaign((d.path / "lab").string());
  write_dem_trace(d.path / "dem/trace.h5", k, 10000, R"({"output": {"filter_cutoff_hz": 500}})");
  const Campaign dem = load_dem_campaign("dem", {{"D", "", d.path / "dem/trace.h5"}});
  ASSERT_EQ(lab.trials.size(), 1u) << issues_of(lab);
  ASSERT_EQ(dem.trials.size(), 1u) << issues_of(dem);
  EXPECT_EQ(dem.trials[0].info.source, TraceSource::dem);
  EXPECT_EQ(dem.trials[0].processed.bias_m_s2, 0.0);
  const Metrics& a = lab.trials[0].processed.metrics;
  const Metrics& b = dem.trials[0].processed.metrics;
  EXPECT_NEAR(a.apeak_m_s2, b.apeak_m_s2, 0.02 * a.apeak_m_s2);
  EXPECT_NEAR(a.zstop_m, b.zstop_m, 0.02 * a.zstop_m);
  EXPECT_NEAR(a.tstop_s, b.tstop_s, 0.02 * a.tstop_s);
  EXPECT_NEAR(b.zstop_m, k.zstop(), 0.02 * k.zstop());
}

TEST(OneEntry, ACampaignsFilterSettingsReachTheMetrics) {
  TempDir d;
  Poncelet k;
  write_dem_trace(d.path / "a/trace.h5", k, 10000,
                  R"({"output": {"filter_cutoff_hz": 100, "end_threshold_g": 0.3, "end_speed_fraction": 0.2}})");
  const MeasuredTrial t = read_dem_trial({"a", "job1", d.path / "a/trace.h5"});
  EXPECT_EQ(t.info.filter_cutoff_hz, 100);
  EXPECT_EQ(t.info.end_threshold_g, 0.3);
  EXPECT_EQ(t.info.end_speed_fraction, 0.2);
  EXPECT_EQ(t.info.job_id, "job1");
  const Campaign c = load_dem_campaign("c", {{"a", "job1", d.path / "a/trace.h5"}});
  ASSERT_EQ(c.trials.size(), 1u) << issues_of(c);
  MetricOptions o = metric_options(t.info);
  Trace tr = t.raw;
  EXPECT_EQ(o.cutoff_hz, 100);
  const Metrics want = process_trace(tr, o).metrics;
  EXPECT_EQ(c.trials[0].processed.metrics.apeak_m_s2, want.apeak_m_s2);
  o.cutoff_hz = 500;
  o.end_threshold_g = 0.1;
  o.end_speed_fraction = 0.1;
  EXPECT_NE(process_trace(tr, o).metrics.apeak_m_s2, want.apeak_m_s2);  // the settings matter
}

TEST(FromRuns, FindsCampaignTracesAndKeepsThemInsideTheNewCampaignFolder) {
  TempDir d;
  Poncelet k;
  for (double v0 : {0.6, 0.8}) {
    Poncelet q = k;
    q.v0 = v0;
    write_dem_trace(d.path / ("c.files/traces/job" + std::to_string(int(v0 * 10)) + ".a1.h5"), q, 10000,
                    R"({"output": {"filter_cutoff_hz": 500}})");
  }
  std::vector<ImportIssue> issues;
  const std::string out = (d.path / "out").string();
  EXPECT_EQ(write_campaign_from_runs({(d.path / "c.files").string()}, out, issues), 2);
  EXPECT_TRUE(issues.empty());
  EXPECT_TRUE(fs::exists(d.path / "out/traces/job6.h5"));
  const Campaign c = load_campaign(out);
  ASSERT_EQ(c.trials.size(), 2u) << issues_of(c);
  EXPECT_EQ(c.trials[0].info.source, TraceSource::dem);
}

TEST(OneEntry, ADemTrialsFillHeightIsTheTracesMeasuredSurfaceHeight) {
  TempDir d;
  const Poncelet k;
  const fs::path p = d.path / "a/trace.h5";
  write_dem_trace(p, k, 10000, R"({"output": {"filter_cutoff_hz": 500}})");
  TraceData td = read_trace(p);
  td.info.fill_height_m = 0.0937;  // settled below a nominal fill of 0.1 m
  write_trace(p, td);
  EXPECT_DOUBLE_EQ(read_trace(p).info.fill_height_m, 0.0937);
  const MeasuredTrial t = read_dem_trial({"a", "job1", p});
  EXPECT_DOUBLE_EQ(t.info.fill_height_m, 0.0937);
  EXPECT_DOUBLE_EQ(metric_options(t.info).fill_height_m.value_or(0), 0.0937);  // the rebound's floor
}
