// `gravsweep plot`: figures of a campaign. `plot results` draws one column of the results table
// against another (each run, and the mean +/- standard deviation of the repeats at each x), one
// series per value of --group: the paper's Figs. 3 (zstop vs fill height), 6 (zstop vs mu_r) and
// the metrics-vs-vc panels of Figs. 4-9 come from it. Units follow the column names (cm, ms, m/s2
// on the axes, as the paper). `plot trace` is Fig. 2 of one record, `plot bed` Fig. 1 of one run
// (results/report/figures.h).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "results/report/figures.h"
#include "results/report/report.h"
#include "results/io/csv.h"
#include "results/io/table.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/campaign_options.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/queue/campaign.h"
#include "db/where.h"
#include "scheduler/queue/filter.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct PlotResultsOptions {
  std::string db = "campaign.db";
  std::vector<std::string> from;  ///< results CSV files read instead of --db
  std::string x, y, group, sweep, title, out, data;
  std::vector<std::string> where;
};

/// A value of the results table as the plotting script reads it (null: empty).
std::string xy_cell(const nlohmann::json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

/// A cell of a results CSV as the --where grammar compares it: empty is null, a number is a number
/// (booleans are written 0/1), anything else text.
json csv_value(const std::string& cell) {
  if (cell.empty()) return nullptr;
  char* end = nullptr;
  const double v = std::strtod(cell.c_str(), &end);
  if (end == cell.c_str() + cell.size() && std::isfinite(v)) return v;
  return cell;
}

/// The rows of results CSV files (`gravsweep results --format csv`, `deploy/*.sh export`) that
/// match --sweep and --where, as the columns `cols`, in file order then row order.
queue::ResultsTable rows_of_csv_files(const PlotResultsOptions& o, const std::vector<std::string>& cols) {
  queue::ResultsTable t{cols, {}};
  for (const auto& file : o.from) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw UsageError(fmt::format("--from {}: cannot open the file", file));
    results::CsvReader csv(in);
    std::vector<std::string> names, fields;
    int line = 0;
    try {
      if (!csv.next(names, line)) throw UsageError(fmt::format("--from {}: empty file (expected a results CSV)", file));
      while (csv.next(fields, line)) {
        if (fields.size() != names.size())
          throw UsageError(fmt::format("{}:{}: {} fields, the header has {}", file, line, fields.size(), names.size()));
        json row = json::object();
        for (std::size_t i = 0; i < names.size(); ++i) row[names[i]] = csv_value(fields[i]);
        for (const auto& c : cols)
          if (!row.contains(c)) throw UsageError(fmt::format("--from {}: no column '{}' in its header", file, c));
        if (!o.sweep.empty() && row.value("sweep", json()) != json(o.sweep)) continue;
        if (!db::row_matches(row, o.where)) continue;
        std::vector<json> r;
        for (const auto& c : cols) r.push_back(row[c]);
        t.rows.push_back(std::move(r));
      }
    } catch (const results::CsvSyntaxError& e) {
      throw UsageError(fmt::format("{}:{}:{}: {}", file, e.line, e.column, e.message));
    } catch (const std::invalid_argument& e) {
      throw UsageError(fmt::format("--from {}: {}", file, e.what()));
    }
  }
  return t;
}

/// The rows to plot: from the campaign database, or from the results CSV files of --from.
queue::ResultsTable rows_to_plot(const PlotResultsOptions& o, const std::vector<std::string>& cols) {
  if (!o.from.empty()) return rows_of_csv_files(o, cols);
  db::Database db = queue::open_campaign(o.db, queue::OpenMode::read);  // refuses a non-campaign
  try {
    return queue::query_results(db, queue::ResultsQuery{o.where, cols, o.sweep, o.x, -1});
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

void run_plot_results(const PlotResultsOptions& o) {
  if (o.out.empty() || fs::path(o.out).extension() != ".png")
    throw UsageError(fmt::format("--out: expected a file name ending in .png, found '{}'", o.out));
  if (!o.data.empty() && fs::path(o.data).extension() != ".csv")
    throw UsageError(fmt::format("--data: expected a file name ending in .csv, found '{}'", o.data));
  std::vector<std::string> cols{o.x, o.y};
  if (!o.group.empty()) cols.push_back(o.group);
  const queue::ResultsTable t = rows_to_plot(o, cols);
  std::size_t usable = 0;
  for (const auto& r : t.rows) usable += r[0].is_number() && r[1].is_number() ? 1 : 0;
  const std::string source = o.from.empty() ? o.db : fmt::format("{}", fmt::join(o.from, ", "));
  if (usable == 0)
    throw UsageError(fmt::format("{}: no finished run has numbers in both '{}' and '{}'{}", source, o.x, o.y,
                                 o.where.empty() && o.sweep.empty() ? "" : " (after --where/--sweep)"));
  results::ScratchDir tmp("plot");
  {
    results::Table xy({"x", "y", "group"});
    for (const auto& r : t.rows) xy.add({xy_cell(r[0]), xy_cell(r[1]), o.group.empty() ? "" : xy_cell(r[2])});
    std::ofstream f(tmp.path / "xy.csv", std::ios::binary);
    f << xy.csv();
  }
  if (!o.data.empty()) {  // the points behind the figure, columns named as in the results table
    results::Table xy(cols);
    for (const auto& r : t.rows) {
      std::vector<std::string> cells;
      for (const auto& v : r) cells.push_back(xy_cell(v));
      xy.add(cells);
    }
    fs::create_directories(fs::absolute(o.data).parent_path());
    std::ofstream f(o.data, std::ios::binary);
    f << xy.csv();
    if (!f) throw std::runtime_error(fmt::format("--data {}: cannot write the file", o.data));
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

void run_plot_trace(const results::Fig2Request& o) {
  results::Fig2Request rq = o;
  if (rq.out.empty()) rq.out = (fs::path(o.record).parent_path() / "fig2.png").string();
  const results::Metrics m = results::draw_fig2(rq);
  fmt::print("vc {:.3f} m/s, apeak {:.2f} m/s2, zstop {:.2f} cm, tstop {:.1f} ms: {}\n", m.vc_m_s, m.apeak_m_s2,
             100 * m.zstop_m, 1000 * m.tstop_s, fs::absolute(rq.out).string());
}

void run_plot_bed(const results::Fig1Request& o) {
  results::Fig1Request rq = o;
  if (rq.out.empty()) rq.out = (fs::path(o.bed).parent_path() / "fig1.png").string();
  const std::string what = results::draw_fig1(rq);
  fmt::print("{}: {}\n", what, fs::absolute(rq.out).string());
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
      "--where and --sweep select runs as in `gravsweep results`. --from reads results CSV files\n"
      "(`gravsweep results --format csv`, the committed data/*/results*.csv) instead of a campaign;\n"
      "--data writes the plotted points beside the figure, so that a committed figure can be checked\n"
      "against the data it was drawn from.\n\n"
      "Examples:\n"
      "  gravsweep plot results --db paper.db --sweep part3_fill_height --x fill_height_m --y zstop_m --out fig3.png\n"
      "  gravsweep plot results --db paper.db --x vc_m_s --y apeak_m_s2 --group gravity_m_s2 --out fig9a.png\n"
      "  gravsweep plot results --from data/reproduction/results_part4_rolling_friction.csv --x mu_rolling \\\n"
      "      --y zstop_m --out fig6.png --data fig6.csv");
  add_campaign_options(res, o->db, nullptr);
  res->add_option("--from", o->from, "results CSV files to plot instead of --db (repeatable; rows of all files)")
      ->check(CLI::ExistingFile)
      ->excludes(res->get_option("--db"));
  res->add_option("--x", o->x, "column on the horizontal axis (e.g. fill_height_m)")->required();
  res->add_option("--y", o->y, "column on the vertical axis (e.g. zstop_m)")->required();
  res->add_option("--group", o->group, "one series per value of this column (e.g. gravity_m_s2)");
  res->add_option("--where", o->where, "filter, e.g. 'gravity_m_s2<1' (repeatable)");
  res->add_option("--sweep", o->sweep, "only this sweep");
  res->add_option("--title", o->title, "figure title");
  res->add_option("--out", o->out, "PNG file to write")->required();
  res->add_option("--data", o->data, "also write the plotted points (the --x, --y, --group columns) to this CSV file");
  res->callback([o]() { run_plot_results(*o); });

  auto ot = std::make_shared<results::Fig2Request>();
  auto* tr = plot->add_subcommand(
      "trace",
      "Sunday et al. 2021 Fig. 2 for one record: acceleration, velocity and depth against the time\n"
      "since the collision start, raw and as the paper processes it (2nd-order 500 Hz Butterworth;\n"
      "velocity and depth re-integrated from the filtered acceleration: the paper's green line),\n"
      "with vc, apeak, zstop and tstop marked. A DEM trace.h5 is processed exactly as the campaign\n"
      "processed it (the scenario's filter and collision-end settings); a lab trace CSV with its\n"
      "campaign's trials.csv (in its folder or the one above). --compare lays another record, lab\n"
      "or DEM, over the first. Default output: fig2.png next to the record (`gravsweep run` writes\n"
      "it for every run). A record without contact is refused (exit 2).\n\n"
      "Examples:\n"
      "  gravsweep plot trace runs/1g/trace.h5\n"
      "  gravsweep plot trace runs/1g/trace.h5 --compare "
      "../shared/data/measurements/depth-friction-dev/traces/t001.csv\n"
      "  gravsweep plot trace campaign.files/traces/<job>.a1.h5 --out fig2.png");
  tr->add_option("record", ot->record, "a trace.h5 of `gravsweep run` or of a campaign, or a lab trace .csv")
      ->required();
  tr->add_option("--compare", ot->compare, "another record (trace.h5 or lab .csv) drawn over the first");
  tr->add_option("--out", ot->out, "PNG file to write (default: fig2.png next to the record)");
  tr->callback([ot]() { run_plot_trace(*ot); });

  auto ob = std::make_shared<results::Fig1Request>();
  auto* bd = plot->add_subcommand(
      "bed",
      "Sunday et al. 2021 Fig. 1 for one run: the container cut through its axis (the grains that\n"
      "the plane y = 0 cuts, drawn at their cut radius), coloured by each grain's radial position in\n"
      "the prepared bed, with the projectile at release (a) and at rest (b) from --trace. The grains\n"
      "of (b) come from the drop's snapshots.h5 when it has one (`gravsweep run` writes it), so the\n"
      "colours show how the impact displaced them; else the prepared bed is drawn. Default output:\n"
      "fig1.png next to the bed.\n\n"
      "Examples:\n"
      "  gravsweep plot bed runs/1g/bed.h5 --trace runs/1g/trace.h5\n"
      "  gravsweep plot bed runs/1g/bed.h5 --trace runs/1g/trace.h5 --at rest --out rest.png");
  bd->add_option("bed", ob->bed, "a bed.h5 of `gravsweep run` or of a campaign")->required();
  bd->add_option("--trace", ob->trace, "the drop's trace.h5: draws the projectile");
  bd->add_option("--at", ob->at, "only one panel: release or rest (default: both, with --trace)")
      ->check(CLI::IsMember({"release", "rest"}));
  bd->add_option("--snapshots", ob->snapshots, "the drop's snapshots.h5 (default: the one next to --trace)");
  bd->add_option("--out", ob->out, "PNG file to write (default: fig1.png next to the bed)");
  bd->callback([ob]() { run_plot_bed(*ob); });
}

}  // namespace gravsweep::cli
