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

#include "results/report/report.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/queue/filter.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/table.h"

namespace gravsweep::cli {

namespace {

namespace fs = std::filesystem;

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
  db::Database db(o.db);
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
}

}  // namespace gravsweep::cli
