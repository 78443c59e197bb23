// Measurement import: the laboratory format, bad rows and traces reported by file, line and
// column without stopping the others, and storage in a real SQLite file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "results/measurements/campaign.h"
#include "results/model/fit.h"
#include "results/model/model_spec.h"
#include "results/model/synth.h"
#include "results/processing/metric_fields.h"
#include "results_helpers.h"
#include "db/database.h"

using namespace gravsweep;
using namespace gravsweep::results;
using gravsweep::testing::TempDir;

namespace {

SynthOptions small() {
  SynthOptions o;
  o.gravity_m_s2 = {9.81, 1.2};
  o.impact_speed_m_s = {0.3, 0.8};
  o.repeats = 2;
  o.seed = 5;
  return o;
}

std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// `text` as one RFC 4180 field: in double quotes, each quote doubled.
std::string csv_quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

/// The synthetic campaign of `model` on the small design, written to d/c and read from there.
Campaign synthetic_campaign(const TempDir& d, const std::string& model) {
  write_synthetic_campaign((d.path / "c").string(), parse_model(model), small());
  return load_campaign((d.path / "c").string());
}

/// `c` stored into a new SQLite file d/lab.db (every trial, checked); returns the file's path.
std::string stored_in_sqlite(const TempDir& d, const Campaign& c) {
  const std::string dbfile = (d.path / "lab.db").string();
  db::Database db(dbfile);
  EXPECT_EQ(store_campaign(db, c), static_cast<int>(c.trials.size()));
  return dbfile;
}

}  // namespace

TEST(Campaign, ReadsSyntheticCampaignAndRecoversImpactSpeed) {
  TempDir d;
  const int n = write_synthetic_campaign(d.str(), parse_model("base"), small());
  ASSERT_EQ(n, 8);
  const Campaign c = load_campaign(d.str());
  EXPECT_TRUE(c.issues.empty()) << c.issues.front().to_string();
  ASSERT_EQ(c.trials.size(), 8u);
  EXPECT_EQ(c.gravity_levels(), (std::vector<double>{9.81, 1.2}));
  for (const auto& t : c.trials) {
    EXPECT_GT(t.processed.metrics.zstop_m, 0.0);
    EXPECT_GT(t.processed.metrics.tstop_s, 0.0);
    EXPECT_GT(t.fit_end, t.fit_begin);
  }
}

TEST(Campaign, BadRowsAndTracesAreReportedByFileLineColumnAndDoNotStopOthers) {
  TempDir d;
  write_synthetic_campaign(d.str(), parse_model("base"), small());
  const auto csv = d.path / "trials.csv";
  std::string text = read_all(csv);
  // Line 3 (second trial): an unparseable gravity (column 3).
  auto line_start = [&](int line) {
    std::size_t p = 0;
    for (int i = 1; i < line; ++i) p = text.find('\n', p) + 1;
    return p;
  };
  {
    const std::size_t p = line_start(3);
    const std::size_t c1 = text.find(',', p), c2 = text.find(',', c1 + 1), c3 = text.find(',', c2 + 1);
    text.replace(c2 + 1, c3 - c2 - 1, "nine");
  }
  std::ofstream(csv) << text;
  // Trace of the fourth trial: a non-increasing time on its line 5.
  {
    const auto tp = d.path / "traces" / "S004.csv";
    std::string tr = read_all(tp);
    std::size_t p = 0;
    for (int i = 1; i < 5; ++i) p = tr.find('\n', p) + 1;
    tr.replace(p, tr.find(',', p) - p, "0.000000");
    std::ofstream(tp) << tr;
  }
  // Trace of the sixth trial: cut during the collision.
  {
    const auto tp = d.path / "traces" / "S006.csv";
    std::string tr = read_all(tp);
    std::size_t p = 0;
    for (int i = 0; i < 50; ++i) p = tr.find('\n', p) + 1;
    std::ofstream(tp) << tr.substr(0, p);
  }
  const Campaign c = load_campaign(d.str());
  EXPECT_EQ(c.trials.size(), 5u);
  ASSERT_EQ(c.issues.size(), 3u);
  EXPECT_EQ(c.issues[0].file, "trials.csv");
  EXPECT_EQ(c.issues[0].line, 3);
  EXPECT_EQ(c.issues[0].column, 3);
  EXPECT_NE(c.issues[0].message.find("gravity_m_s2"), std::string::npos);
  EXPECT_NE(c.issues[0].message.find("expected a finite number"), std::string::npos);
  EXPECT_EQ(c.issues[1].file, "traces/S004.csv");
  EXPECT_EQ(c.issues[1].line, 5);
  EXPECT_EQ(c.issues[1].column, 1);
  EXPECT_NE(c.issues[1].message.find("time must increase"), std::string::npos);
  EXPECT_EQ(c.issues[2].file, "traces/S006.csv");
  EXPECT_NE(c.issues[2].message.find("shorter than the collision"), std::string::npos) << c.issues[2].message;
}

TEST(Campaign, MissingRequiredColumnIsAnErrorNamingIt) {
  TempDir d;
  std::ofstream(d.path / "trials.csv") << "trial_id,trace_file,gravity_m_s2\nA,traces/A.csv,9.81\n";
  try {
    load_campaign(d.str());
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'impact_speed_m_s' (or 'impact_velocity_m_s')"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("trials.csv:1"), std::string::npos) << e.what();
  }
}

TEST(Campaign, StoresTrialsSamplesAndMetricsInSqlite) {
  TempDir d;
  const Campaign c = synthetic_campaign(d, "base");
  const std::string dbfile = (d.path / "lab.db").string();
  {
    db::Database db(dbfile);
    EXPECT_EQ(store_campaign(db, c), 8);
    EXPECT_EQ(store_campaign(db, c), 8);  // re-import replaces, no duplicates
  }
  db::Database db(dbfile);
  db::Statement q(db, "SELECT COUNT(*), SUM(zstop_m > 0) FROM trial_metrics");
  ASSERT_TRUE(q.step());
  EXPECT_EQ(q.get_int(0), 8);
  EXPECT_EQ(q.get_int(1), 8);
  std::size_t samples = 0;
  for (const auto& t : c.trials) samples += t.processed.t_s.size();
  db::Statement s(db, "SELECT COUNT(*) FROM trial_samples");
  ASSERT_TRUE(s.step());
  EXPECT_EQ(static_cast<std::size_t>(s.get_int(0)), samples);
  db::Statement g(db, "SELECT gravity_m_s2 FROM trials WHERE trial_id = 'S001'");
  ASSERT_TRUE(g.step());
  EXPECT_DOUBLE_EQ(g.get_double(0), 9.81);
}

TEST(Campaign, ReadBackFromSqliteFitsExactlyAsFromTheFolder) {
  TempDir d;
  const Campaign c = synthetic_campaign(d, "base+depth_friction");
  const std::string dbfile = stored_in_sqlite(d, c);
  const Campaign back = load_campaign_any(dbfile);
  ASSERT_EQ(back.trials.size(), c.trials.size());
  for (std::size_t i = 0; i < c.trials.size(); ++i) {
    EXPECT_EQ(back.trials[i].info.trial_id, c.trials[i].info.trial_id);
    EXPECT_EQ(back.trials[i].fit_begin, c.trials[i].fit_begin);
    EXPECT_EQ(back.trials[i].fit_end, c.trials[i].fit_end);
    // Every metric of the one table, the depths at the end and the note included.
    EXPECT_EQ(nlohmann::json(back.trials[i].processed.metrics), nlohmann::json(c.trials[i].processed.metrics));
  }
  const auto spec = parse_model("base+depth_friction");
  const auto a = fit_model(spec, c), b = fit_model(spec, back);
  for (Eigen::Index j = 0; j < a.coef.size(); ++j) EXPECT_NEAR(b.coef(j), a.coef(j), 1e-9 * std::abs(a.coef(j)));
}

// A lab record too short for its drop-scaled filter is processed in the paper's fixed scales; a
// record processed beside it (the model's record that predicts its apeak as measured) must be
// processed in those scales too, whether the trial was processed now or read back from SQLite.
TEST(Campaign, ATrialProcessedInTheFixedScalesIsProcessedAgainInThem) {
  TempDir d;
  SynthOptions o;
  o.gravity_m_s2 = {0.1};  // records sized in seconds: 10-30 ms of free fall, 0.1 s of rest
  o.repeats = 1;
  o.seed = 5;
  ASSERT_EQ(write_synthetic_campaign(d.str(), parse_model("base"), o), 8);
  const Campaign c = load_campaign(d.str(), kPaperCutoff_hz, {"froude", ""});
  const Campaign back = load_campaign_any(stored_in_sqlite(d, c));
  ASSERT_EQ(back.trials.size(), c.trials.size());
  int fell_back = 0;
  for (std::size_t i = 0; i < c.trials.size(); ++i) {
    const MeasuredTrial& t = c.trials[i];
    const MetricOptions& applied = t.options;
    const Metrics again = process_trace(t.raw, applied).metrics;
    EXPECT_EQ(again.apeak_m_s2, t.processed.metrics.apeak_m_s2) << t.info.trial_id;
    EXPECT_EQ(again.tstop_s, t.processed.metrics.tstop_s) << t.info.trial_id;
    EXPECT_EQ(applied.cutoff_hz, t.processed.metrics.cutoff_hz) << t.info.trial_id;
    EXPECT_EQ(back.trials[i].options.cutoff_hz, applied.cutoff_hz) << t.info.trial_id;
    EXPECT_EQ(back.trials[i].options.end_hold_s, applied.end_hold_s) << t.info.trial_id;
    EXPECT_EQ(back.trials[i].options.gravity_m_s2, applied.gravity_m_s2) << t.info.trial_id;
    if (t.processed.metrics.note.find("fixed scales") == std::string::npos) continue;
    ++fell_back;
    EXPECT_EQ(applied.cutoff_hz, kPaperCutoff_hz) << t.info.trial_id;
    EXPECT_LT(metric_options(t.info).cutoff_hz, 0.2 * kPaperCutoff_hz) << t.info.trial_id;  // asked: 50 Hz
  }
  EXPECT_GE(fell_back, 3);
}

// A database imported before the cut-off and the hold applied were recorded (when every trial was
// processed in the paper's fixed scales): its trials are read back with the fixed scales as the
// options they were processed with, not with the drop-scaled ones their facts would give today.
TEST(Campaign, ATrialImportedBeforeItsCutoffWasRecordedHasTheFixedScales) {
  TempDir d;
  SynthOptions o;
  o.gravity_m_s2 = {0.1};
  o.repeats = 1;
  o.seed = 5;
  ASSERT_EQ(write_synthetic_campaign(d.str(), parse_model("base"), o), 8);
  const Campaign c = load_campaign(d.str(), kPaperCutoff_hz, {"froude", ""});
  const std::string dbfile = stored_in_sqlite(d, c);
  int scaled = 0;
  for (const MeasuredTrial& t : load_campaign_any(dbfile).trials) scaled += t.options.cutoff_hz < kPaperCutoff_hz;
  EXPECT_GT(scaled, 0) << "some trials processed in their drop's scales";
  db::Database(dbfile).exec(
      "ALTER TABLE trial_metrics DROP COLUMN cutoff_hz; ALTER TABLE trial_metrics DROP COLUMN end_hold_s");
  const Campaign old = load_campaign_any(dbfile);
  ASSERT_EQ(old.trials.size(), c.trials.size());
  for (const MeasuredTrial& t : old.trials) {
    EXPECT_EQ(t.options.cutoff_hz, t.info.filter_cutoff_hz) << t.info.trial_id;
    EXPECT_EQ(t.options.end_hold_s, kPaperEndHold_s) << t.info.trial_id;
  }
}

// A database imported before a metric had its column: it is read with that metric at its default,
// and storing into it adds the column (no rows lost).
TEST(Campaign, AnOlderMetricsTableGainsTheNewColumnsWhenStoredInto) {
  TempDir d;
  const Campaign c = synthetic_campaign(d, "base");
  const std::string dbfile = stored_in_sqlite(d, c);
  db::Database(dbfile).exec("ALTER TABLE trial_metrics DROP COLUMN depth_at_end_m");
  const Campaign old = load_campaign_any(dbfile);
  ASSERT_EQ(old.trials.size(), c.trials.size());
  EXPECT_EQ(old.trials[0].processed.metrics.depth_at_end_m, 0.0);
  EXPECT_EQ(old.trials[0].processed.metrics.zstop_m, c.trials[0].processed.metrics.zstop_m);
  {
    db::Database db(dbfile);
    EXPECT_EQ(store_campaign(db, c), 8);
  }
  const Campaign back = load_campaign_any(dbfile);
  ASSERT_GT(c.trials[0].processed.metrics.depth_at_end_m, 0.0);
  EXPECT_EQ(back.trials[0].processed.metrics.depth_at_end_m, c.trials[0].processed.metrics.depth_at_end_m);
}

TEST(Campaign, AttributeCellWithQuotesBackslashesAndLineBreaksIsStoredAsValidJson) {
  TempDir d;
  const auto dir = d.path / "c";
  write_synthetic_campaign(dir.string(), parse_model("base"), small());
  // One more trials.csv column, kept as an attribute: a quote (as `"5"" bead"`), backslashes and
  // a line break inside a quoted field.
  const std::string cell = "5\" bead, C:\\lab\\\"wet\" run\nsecond line";
  std::istringstream in(read_all(dir / "trials.csv"));
  std::string csv, line;
  for (bool header = true; std::getline(in, line); header = false) {
    csv += line;
    csv += header ? std::string(",operator_note") : ',' + csv_quoted(cell);
    csv += '\n';
  }
  std::ofstream(dir / "trials.csv") << csv;
  const Campaign c = load_campaign(dir.string());
  ASSERT_TRUE(c.issues.empty()) << c.issues.front().to_string();
  ASSERT_EQ(c.trials.size(), 8u);
  EXPECT_EQ(c.trials.front().info.attributes.at("operator_note"), cell);
  const std::string dbfile = (d.path / "lab.db").string();
  {
    db::Database db(dbfile);
    ASSERT_EQ(store_campaign(db, c), 8);
  }
  db::Database db(dbfile);
  db::Statement q(db, "SELECT trial_id, attributes_json FROM trials ORDER BY trial_id");
  int rows = 0;
  while (q.step()) {
    ++rows;
    const std::string text = q.get_text(1);
    const auto j = nlohmann::json::parse(text, nullptr, false);
    ASSERT_TRUE(j.is_object()) << q.get_text(0) << ": attributes_json is not a JSON object: " << text;
    ASSERT_TRUE(j.contains("operator_note")) << text;
    EXPECT_EQ(j.at("operator_note").get<std::string>(), cell) << text;
  }
  EXPECT_EQ(rows, 8);
  const Campaign back = load_campaign_any(dbfile);
  ASSERT_EQ(back.trials.size(), 8u);
  EXPECT_EQ(back.trials.front().info.attributes.at("operator_note"), cell);
}
