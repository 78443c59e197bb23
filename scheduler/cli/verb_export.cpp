// `gravsweep export`: a campaign's finished drops as a measurement campaign on disk
// (docs/formats/measurements.md section 6): trials.csv, traces/<job>.csv at a lower sample rate,
// scenarios/<job>.json, and results.csv (the campaign's own metrics from the full-rate traces).
// `gravsweep model rank DIR` then works on the folder without rerunning anything, and it is
// small enough to keep in git (the reproduction dataset, REPRODUCTION.md).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "results/io/bed_file.h"
#include "results/io/job_reports.h"
#include "results/io/trace_file.h"
#include "results/measurements/campaign.h"
#include "results/measurements/trial.h"
#include "results/processing/resample.h"
#include "results/io/table.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/campaign_options.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/pipeline/build_version.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/filter.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct ExportOptions {
  std::string db = "campaign.db";
  std::string files;
  std::string out;
  std::vector<std::string> where;
  std::string sweep;
  double rate_hz = 2000;
  bool allow_dirty = false;
};

/// Drops per code version, refusing (UsageError) a dataset with drops from a dirty build unless
/// --allow-dirty: a dataset must name the commits that made it.
std::map<std::string, int> check_provenance(const std::vector<std::string>& versions, const ExportOptions& o) {
  std::map<std::string, int> count;
  for (const auto& v : versions) ++count[v];
  std::vector<std::string> dirty;
  int n_dirty = 0;
  for (const auto& [v, n] : count)
    if (pipeline::is_dirty_build(v)) dirty.push_back(fmt::format("{} ({} drops)", v, n)), n_dirty += n;
  if (!dirty.empty() && !o.allow_dirty)
    throw UsageError(fmt::format(
        "{}: {} of {} drops come from builds with uncommitted changes: {}. A dataset must name the commit that "
        "made it: run them again with a build of a clean commit, or give --allow-dirty (recorded in "
        "{}/provenance.json)",
        o.db, n_dirty, versions.size(), fmt::join(dirty, ", "), o.out));
  return count;
}

/// The beds of the drops to export, by bed job (one read each), and their count per code version,
/// refusing (UsageError) a bed from a dirty build unless --allow-dirty, as check_provenance refuses
/// a drop: a drop of a clean build on a bed of uncommitted code is not reproducible either.
using BedsByJob = std::map<std::string, std::optional<results::BedFacts>>;
std::map<std::string, int> check_bed_provenance(const BedsByJob& beds, const ExportOptions& o) {
  std::map<std::string, int> count;
  std::vector<std::string> dirty;
  for (const auto& [job, bed] : beds) {
    const std::string v = bed ? bed->code_version : std::string("unknown (bed file not found)");
    ++count[v];
    if (pipeline::is_dirty_build(v)) dirty.push_back(fmt::format("{} ({})", job, v));
  }
  if (!dirty.empty() && !o.allow_dirty)
    throw UsageError(
        fmt::format("{}: {} of {} beds come from builds with uncommitted changes: {}. A dataset must name the commit "
                    "that made its beds too: prepare them again with a build of a clean commit, or give --allow-dirty "
                    "(recorded in {}/provenance.json)",
                    o.db, dirty.size(), beds.size(), fmt::join(dirty, ", "), o.out));
  return count;
}

/// Columns of trials.csv after the trial record's own (results::trial_fields()): the DEM
/// provenance that the record does not carry.
const std::vector<std::string> kDemColumns = {"source", "contact_start_s", "sweep",           "scenario_file",
                                              "dt_s",   "grains",          "lateral_offset_m"};

std::vector<std::string> trials_header() {
  std::vector<std::string> h;
  for (const auto& f : results::trial_fields()) h.emplace_back(f.key);
  h.insert(h.end(), kDemColumns.begin(), kDemColumns.end());
  return h;
}

std::string num(double v) { return std::isfinite(v) ? fmt::format("{}", v) : std::string(); }

/// The bed a drop used: its recorded path, or the bed job's output in this campaign.
std::optional<results::BedFacts> bed_of(db::Database& db, const queue::CampaignPaths& paths,
                                        const results::TraceData& td, const std::string& bed_job) {
  std::vector<fs::path> candidates{td.bed_file};
  if (const std::string out = queue::done_output_path(db, bed_job); !out.empty()) candidates.push_back(paths.abs(out));
  for (const auto& p : candidates) {
    std::error_code ec;
    if (!p.empty() && fs::exists(p, ec)) return results::read_bed(p);
  }
  return std::nullopt;
}

/// Writes traces/<job>.csv: t_s, accel_m_s2 (decimated with its anti-alias filter), position_m
/// and velocity_m_s (every k-th sample: they are smooth). Returns the new sample rate.
double write_trace_csv(const fs::path& path, const results::TraceData& td, double rate_hz) {
  const std::size_t step =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(td.info.sample_rate_hz / rate_hz)));
  const auto t = results::every_nth(td.raw.t_s, step);
  const auto a = results::decimate(td.raw.accel_up_m_s2, td.info.sample_rate_hz, step);
  const auto z = results::every_nth(td.raw.depth_m, step);
  const auto v = results::every_nth(td.raw.velocity_down_m_s, step);
  std::ofstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error(fmt::format("{}: cannot write", path.string()));
  f << "t_s,accel_m_s2,position_m,velocity_m_s\n";
  for (std::size_t i = 0; i < t.size(); ++i) f << fmt::format("{:.6f},{:.6g},{:.7g},{:.6g}\n", t[i], a[i], z[i], v[i]);
  if (!f) throw std::runtime_error(fmt::format("{}: write error", path.string()));
  return td.info.sample_rate_hz / static_cast<double>(step);
}

/// One trials.csv row: the trial record of the drop (prepared by prepare_dem_trial: the same facts
/// and processing settings the model verbs use), pointing at the exported trace and its rate.
std::vector<std::string> trial_row(const std::string& sweep, const results::TraceData& td,
                                   const std::optional<results::BedFacts>& bed, double rate_hz) {
  results::Trial ti = td.info;
  const std::string& job = ti.job_id;
  ti.trace_file = "traces/" + job + ".csv";
  ti.sample_rate_hz = rate_hz;
  ti.bulk_density_kg_m3 = NAN;
  if (bed && !bed->report_json.empty()) {
    const json r = json::parse(bed->report_json, nullptr, false);
    try {  // a report this build cannot read leaves the density unknown, as a missing one does
      if (r.is_object()) ti.bulk_density_kg_m3 = results::bed_summary_of_json(r, "bed report").bulk_density_kg_m3;
    } catch (const std::runtime_error&) {
    }
  }
  std::vector<std::string> row;
  for (const auto& f : results::trial_fields()) row.push_back(f.number ? num(ti.*f.number) : ti.*f.text);
  const json m = json::parse(td.metrics_json.empty() ? "{}" : td.metrics_json, nullptr, false);
  const auto metric = [&](const char* k) {
    return m.is_object() && m.contains(k) && m[k].is_number() ? m[k].dump() : std::string();
  };
  for (std::string v :
       {std::string("dem"), td.raw.contact_start_s ? num(*td.raw.contact_start_s) : std::string(), sweep,
        "scenarios/" + job + ".json", num(td.dt_s), metric("grains"), metric("lateral_offset_m")})
    row.push_back(std::move(v));
  return row;
}

void write_text_file(const fs::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary);
  f << text;
  if (!f) throw std::runtime_error(fmt::format("{}: cannot write", p.string()));
}

void run_export(const ExportOptions& o) {
  if (!(o.rate_hz > 0)) throw UsageError(fmt::format("--rate-hz: expected a rate > 0 Hz, found {}", o.rate_hz));
  db::Database db = queue::open_campaign(o.db, queue::OpenMode::read, o.files);  // refuses a non-campaign
  const queue::CampaignPaths paths(o.db, o.files);
  queue::ResultsTable t;
  try {
    t = queue::query_results(db, queue::ResultsQuery{o.where, {}, o.sweep, "sweep", -1});
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  const auto col = [&](const std::string& name) {
    const auto it = std::find(t.columns.begin(), t.columns.end(), name);
    if (it == t.columns.end())
      throw std::runtime_error(fmt::format("{}: results table has no column '{}'", o.db, name));
    return static_cast<std::size_t>(it - t.columns.begin());
  };
  const std::size_t c_job = col("job_id"), c_sweep = col("sweep"), c_kind = col("kind"), c_trace = col("trace_path"),
                    c_bed = col("bed_job_id"), c_version = col("code_version");
  const auto exported = [&](const std::vector<json>& r) {
    return r[c_kind].is_string() && r[c_kind].get<std::string>() == "drop" && r[c_trace].is_string();
  };
  std::vector<std::string> versions;
  for (const auto& r : t.rows)
    if (exported(r)) versions.push_back(r[c_version].is_string() ? r[c_version].get<std::string>() : "unknown");
  const auto by_version = check_provenance(versions, o);
  BedsByJob beds;
  for (const auto& r : t.rows) {
    const std::string bed_job = r[c_bed].is_string() ? r[c_bed].get<std::string>() : std::string();
    if (!exported(r) || beds.count(bed_job)) continue;
    beds[bed_job] = bed_of(db, paths, results::read_trace(paths.abs(r[c_trace].get<std::string>())), bed_job);
  }
  const auto beds_by_version = check_bed_provenance(beds, o);
  const fs::path out(o.out);
  fs::create_directories(out / "traces");
  fs::create_directories(out / "scenarios");
  results::Table trials(trials_header()), results_csv(t.columns);
  for (const auto& r : t.rows) {
    if (!exported(r)) continue;
    const std::string job = r[c_job].get<std::string>();
    const fs::path trace_path = paths.abs(r[c_trace].get<std::string>());
    results::TraceData td = results::read_trace(trace_path);
    results::prepare_dem_trial(td, {job, job, trace_path});
    const auto& bed = beds.at(r[c_bed].is_string() ? r[c_bed].get<std::string>() : std::string());
    const double rate = write_trace_csv(out / "traces" / (job + ".csv"), td, o.rate_hz);
    write_text_file(out / "scenarios" / (job + ".json"), json::parse(td.scenario_json).dump(2) + "\n");
    trials.add(trial_row(r[c_sweep].get<std::string>(), td, bed, rate));
    std::vector<std::string> cells;
    for (const auto& v : r) cells.push_back(v.is_null() ? "" : v.is_string() ? v.get<std::string>() : v.dump());
    results_csv.add(std::move(cells));
  }
  write_text_file(out / "provenance.json", json{{"exported_by", pipeline::build_version()},
                                                {"drops_by_code_version", by_version},
                                                {"beds_by_code_version", beds_by_version},
                                                {"allow_dirty", o.allow_dirty},
                                                {"sweep", o.sweep},
                                                {"where", o.where}}
                                                   .dump(2) +
                                               "\n");
  // CSV files are written last, each under a temporary name: an interrupted export leaves no
  // trials.csv that points at missing traces.
  for (const auto& [name, table] : {std::pair{"results.csv", &results_csv}, std::pair{"trials.csv", &trials}}) {
    write_text_file(out / (std::string(name) + ".tmp"), table->csv());
    fs::rename(out / (std::string(name) + ".tmp"), out / name);
  }
  fmt::print("{} drops exported to {} (trials.csv, traces/ at {} Hz, scenarios/, results.csv)\n", trials.size(),
             out.string(), o.rate_hz);
}

}  // namespace

void setup_export(CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  auto* sub = app.add_subcommand(
      "export",
      "Write a campaign's finished drops as a measurement campaign (docs/formats/measurements.md):\n"
      "OUT/trials.csv (one row per drop: gravity, impact speed, fill, projectile, grains, sample rate,\n"
      "source = dem, the engine's first-contact time, sweep, job, code version), OUT/traces/<job>.csv\n"
      "(t_s, accel_m_s2, position_m, velocity_m_s at --rate-hz after a 4th-order anti-alias low-pass\n"
      "at 0.4 x the new rate), OUT/scenarios/<job>.json (the scenario of each drop) and OUT/results.csv\n"
      "(the campaign's results table, metrics from the full-rate traces). The folder is what `gravsweep\n"
      "measurements import` and `gravsweep model ...` read. OUT/provenance.json gives the code version of\n"
      "every drop; drops, or beds, from a build with uncommitted changes (a code version ending in\n"
      "-dirty) are refused (exit 2) unless --allow-dirty, which provenance.json records.\n\n"
      "Example:\n"
      "  gravsweep export --db paper.db --out data/reproduction --sweep part1_chrono_1g");
  add_campaign_options(sub, o->db, &o->files);
  sub->add_option("--out", o->out, "folder to write")->required();
  sub->add_option("--where", o->where, "filter, e.g. 'gravity_m_s2<1' (repeatable)");
  sub->add_option("--sweep", o->sweep, "only this sweep");
  sub->add_option("--rate-hz", o->rate_hz, "sample rate of the exported traces")->capture_default_str();
  sub->add_flag("--allow-dirty", o->allow_dirty,
                "export drops from builds with uncommitted changes too (recorded in provenance.json)");
  sub->callback([o]() { run_export(*o); });
}

}  // namespace gravsweep::cli
