// `gravsweep plot`: figures of a campaign. `plot results` draws one column of the results table
// against another (each run, and the mean +/- standard deviation of the repeats at each x), one
// series per value of --group: the paper's Figs. 3 (zstop vs fill height), 6 (zstop vs mu_r) and
// the metrics-vs-vc panels of Figs. 4-9 come from it. Units follow the column names (cm, ms, m/s2
// on the axes, as the paper).
#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "results/io/trace_file.h"
#include "results/measurements/campaign.h"
#include "results/processing/trace.h"
#include "results/report/report.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/filter.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/table.h"

namespace gravsweep::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct PlotResultsOptions {
  std::string db = "campaign.db";
  std::string x, y, group, sweep, title, out;
  std::vector<std::string> where;
};

/// A private temporary folder for the plot's data, removed afterwards.
struct ScratchDir {
  fs::path path;
  ScratchDir() : path(fs::temp_directory_path() / fmt::format("gravsweep-plot-{}", ::getpid())) {
    fs::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
};

std::string csv_cell(const nlohmann::json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return queue::csv_escape(v.get<std::string>());
  return v.dump();
}

void run_plot_results(const PlotResultsOptions& o) {
  if (!fs::exists(o.db)) throw UsageError(fmt::format("--db: no campaign database at '{}'", o.db));
  if (o.out.empty() || fs::path(o.out).extension() != ".png")
    throw UsageError(fmt::format("--out: expected a file name ending in .png, found '{}'", o.out));
  db::Database db = queue::open_campaign(o.db, queue::OpenMode::read);  // refuses a non-campaign
  std::vector<std::string> cols{o.x, o.y};
  if (!o.group.empty()) cols.push_back(o.group);
  queue::ResultsTable t;
  try {
    t = queue::query_results(db, queue::ResultsQuery{o.where, cols, o.sweep, o.x, -1});
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  std::size_t usable = 0;
  for (const auto& r : t.rows) usable += r[0].is_number() && r[1].is_number() ? 1 : 0;
  if (usable == 0)
    throw UsageError(fmt::format("{}: no finished run has numbers in both '{}' and '{}'{}", o.db, o.x, o.y,
                                 o.where.empty() && o.sweep.empty() ? "" : " (after --where/--sweep)"));
  ScratchDir tmp;
  {
    std::ofstream f(tmp.path / "xy.csv");
    f << "x,y,group\n";
    for (const auto& r : t.rows)
      f << csv_cell(r[0]) << ',' << csv_cell(r[1]) << ',' << (o.group.empty() ? "" : csv_cell(r[2])) << '\n';
  }
  const fs::path out = fs::absolute(o.out);
  fs::create_directories(out.parent_path());
  {
    std::ofstream f(tmp.path / "xy.json");
    f << nlohmann::json{{"x", o.x}, {"y", o.y}, {"group", o.group}, {"title", o.title}, {"out", out.string()}}.dump();
  }
  std::string log;
  if (results::run_plots(tmp.path.string(), "xy", log) != 0) throw std::runtime_error("plotting failed: " + log);
  fmt::print("{} runs plotted: {}\n", usable, out.string());
}

struct PlotTraceOptions {
  std::string trace, out;
};

/// The campaign's processing of a DEM record: the one processing entry of the model verbs and
/// the drop job (read_dem_trial + process_trial: the scenario's filter and collision-end settings).
results::ProcessedTrace process_dem_trace(const std::string& file) {
  try {
    results::MeasuredTrial t = results::read_dem_trial({fs::path(file).stem().string(), "", file});
    results::process_trial(t);
    return t.processed;
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("{}: cannot process the record: {}", file, e.what()));
  }
}

void run_plot_trace(const PlotTraceOptions& o) {
  if (!fs::exists(o.trace)) throw UsageError(fmt::format("no trace file at '{}'", o.trace));
  const std::string out_name = o.out.empty() ? (fs::path(o.trace).parent_path() / "fig2.png").string() : o.out;
  if (fs::path(out_name).extension() != ".png")
    throw UsageError(fmt::format("--out: expected a file name ending in .png, found '{}'", out_name));
  results::TraceData td;
  try {
    td = results::read_trace(o.trace);
  } catch (const std::exception& e) {
    throw UsageError(fmt::format("{}: not a readable gravsweep trace.h5 ({})", o.trace, e.what()));
  }
  const results::ProcessedTrace p = process_dem_trace(o.trace);
  ScratchDir tmp;
  {
    std::ofstream f(tmp.path / "trace.csv");
    f << "t_s,accel_raw_m_s2,velocity_raw_m_s,depth_raw_m,accel_m_s2,velocity_m_s,depth_m\n";
    for (std::size_t i = 0; i < p.t_s.size(); ++i)
      f << fmt::format("{},{},{},{},{},{},{}\n", p.t_s[i], td.accel_up_m_s2[i], td.velocity_down_m_s[i], td.depth_m[i],
                       p.accel_up_m_s2[i], p.velocity_down_m_s[i], p.depth_m[i]);
  }
  const auto& m = p.metrics;
  const fs::path out = fs::absolute(out_name);
  fs::create_directories(out.parent_path());
  {
    const json metrics{{"vc_m_s", m.vc_m_s},   {"apeak_m_s2", m.apeak_m_s2}, {"zstop_m", m.zstop_m},
                       {"tstop_s", m.tstop_s}, {"t_start_s", m.t_start_s},   {"t_end_s", m.t_end_s}};
    std::ofstream f(tmp.path / "trace.json");
    f << json{{"out", out.string()}, {"source", "dem"}, {"metrics", metrics},
              {"title", fmt::format("{}: g = {} m/s2, vc = {:.3f} m/s", o.trace, td.gravity_m_s2, m.vc_m_s)}}
             .dump();
  }
  std::string log;
  if (results::run_plots(tmp.path.string(), "trace", log) != 0) throw std::runtime_error("plotting failed: " + log);
  fmt::print("vc {:.3f} m/s, apeak {:.2f} m/s2, zstop {:.2f} cm, tstop {:.1f} ms: {}\n", m.vc_m_s, m.apeak_m_s2,
             100 * m.zstop_m, 1000 * m.tstop_s, out.string());
}

}  // namespace

void setup_plot(CLI::App& app) {
  auto* plot = app.add_subcommand("plot", "Figures of a campaign (PNG, the paper's axes and units).");
  plot->require_subcommand(1);
  auto o = std::make_shared<PlotResultsOptions>();
  auto* res = plot->add_subcommand(
      "results",
      "One column of the results table against another: every run as a faint dot, and the mean\n"
      "+/- standard deviation of the repeats at each x, one series per value of --group. Units\n"
      "follow the column names: _m is drawn in cm, _s in ms, _m_s2 in m/s2 (the paper's axes).\n"
      "--where and --sweep select runs as in `gravsweep results`.\n\n"
      "Examples:\n"
      "  gravsweep plot results --db paper.db --sweep part3_fill_height --x fill_height_m --y zstop_m --out fig3.png\n"
      "  gravsweep plot results --db paper.db --x vc_m_s --y apeak_m_s2 --group gravity_m_s2 --out fig9a.png");
  res->add_option("--db", o->db, "campaign database")->capture_default_str();
  res->add_option("--x", o->x, "column on the horizontal axis (e.g. fill_height_m)")->required();
  res->add_option("--y", o->y, "column on the vertical axis (e.g. zstop_m)")->required();
  res->add_option("--group", o->group, "one series per value of this column (e.g. gravity_m_s2)");
  res->add_option("--where", o->where, "filter, e.g. 'gravity_m_s2<1' (repeatable)");
  res->add_option("--sweep", o->sweep, "only this sweep");
  res->add_option("--title", o->title, "figure title");
  res->add_option("--out", o->out, "PNG file to write")->required();
  res->callback([o]() { run_plot_results(*o); });

  auto ot = std::make_shared<PlotTraceOptions>();
  auto* tr = plot->add_subcommand(
      "trace",
      "Sunday et al. 2021 Fig. 2 for one drop: acceleration (raw and after the paper's 500 Hz\n"
      "Butterworth), velocity and depth against time, with the collision start and end, vc, apeak,\n"
      "zstop and tstop marked, processed exactly as the campaign processed it (the scenario's filter\n"
      "and collision-end settings). Default output: fig2.png next to the trace.\n\n"
      "Examples:\n"
      "  gravsweep plot trace runs/1g/trace.h5\n"
      "  gravsweep plot trace campaign.files/traces/<job>.a1.h5 --out fig2.png");
  tr->add_option("trace", ot->trace, "a trace.h5 of `gravsweep run` or of a campaign")->required();
  tr->add_option("--out", ot->out, "PNG file to write (default: fig2.png next to the trace)");
  tr->callback([ot]() { run_plot_trace(*ot); });
}

}  // namespace gravsweep::cli
