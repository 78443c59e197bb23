// `gravsweep model collapse`: how well a campaign across gravity levels collapses when scaled by
// the Froude number (results/model/collapse.h), as a table and, with --plot, a figure.
#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

#include "results/model/collapse.h"
#include "results/report/figures.h"
#include "results/io/table.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/model_inputs.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

struct CollapseOptions {
  ModelInputs in;
  std::string plot;  ///< the figure's PNG; empty: none
};

void run_collapse(const CollapseOptions& o) {
  const auto c = load_model_campaign(o.in, 0);
  if (c.gravity_levels().size() < 2)
    throw UsageError(fmt::format("{} trials on {} gravity level(s): a collapse needs at least two levels",
                                 c.trials.size(), c.gravity_levels().size()));
  results::Table t({"metric", "levels", "trials", "common_scatter_pct", "within_scatter_pct", "between_levels_pct",
                    "collapse_ratio", "cells", "level_scatter_pct", "repeat_scatter_pct", "level_F", "level_p",
                    "verdict"});
  for (const auto& r : results::collapse(c)) {
    const std::string verdict =
        !(r.level_p >= 0) ? "untested: no Froude number with repeats at two levels"
        : r.level_p < results::kLevelEffectP
            ? fmt::format("levels differ at equal Fr (p = {:.2g})", r.level_p)
            : fmt::format("collapses: the levels differ by no more than the repeats (p = {:.2g})", r.level_p);
    t.add({r.metric, std::to_string(r.levels), std::to_string(r.trials), results::num(r.common_scatter_pct, 3),
           results::num(r.within_scatter_pct, 3), results::num(r.between_levels_pct, 3),
           results::num(r.collapse_ratio, 3), std::to_string(r.cells), results::num(r.level_scatter_pct, 3),
           results::num(r.repeat_scatter_pct, 3), results::num(r.level_f, 3), results::num(r.level_p, 2), verdict});
  }
  t.print(o.in.format);
  if (!o.plot.empty()) {
    results::draw_collapse(c, o.plot,
                           fmt::format("{} trials, {} gravity levels", c.trials.size(), c.gravity_levels().size()));
    if (o.in.format == "table") fmt::print("wrote {}\n", o.plot);
  }
}

}  // namespace

void setup_model_collapse(CLI::App& model) {
  auto o = std::make_shared<CollapseOptions>();
  auto* sub = model.add_subcommand(
      "collapse",
      "Froude-number collapse across gravity levels (paper II): zstop/D, tstop sqrt(g/D) and apeak/g\n"
      "against Fr = vc / sqrt(g D), D the projectile diameter (v^2/(g D) = Fr^2). For each scaled\n"
      "metric: the scatter of every trial about one common curve (a quadratic in ln Fr fitted to the\n"
      "log of the metric), the scatter of each level about its own curve (the repeat scatter), the\n"
      "distance between the levels' curves where their Froude ranges overlap, and the collapse ratio\n"
      "common / within: 1 when the levels fall on one curve, larger when they lie apart. The test of\n"
      "the level effect at equal Fr: a nested analysis of variance of ln(metric) over the cells (Froude\n"
      "number of the design, level) at the Froude numbers run at two or more levels: the level's\n"
      "variance component against the repeats' scatter within a cell, F and its p (below 0.01: the\n"
      "levels differ, the metric does not collapse).\n\n"
      "The traces are processed in each drop's own scales (--time-scale froude, the default: the\n"
      "paper's 500 Hz and 2 ms hold at 1 g and D = 10 cm, scaled by sqrt(g/D)); --time-scale fixed is\n"
      "the paper's hertz and seconds at every gravity, --end-rule paper|speed|depth the end of the\n"
      "collision (docs/reference.md, 'Processing').\n\n"
      "Examples:\n"
      "  gravsweep model collapse data/gravity_sweep/g9.81 data/gravity_sweep/g1.62 --plot collapse.png\n"
      "  gravsweep model collapse runs/gravity_sweep/sweep.db --where 'sweep~gravity_sweep_' --format csv\n"
      "  gravsweep model collapse data/gravity_sweep/g* --time-scale fixed    # the paper's 1 g processing");
  add_model_inputs(sub, o->in);
  sub->add_option("--plot", o->plot, "also draw the three scaled metrics against Fr, coloured by g (PNG)");
  sub->callback([o]() { run_collapse(*o); });
}

}  // namespace gravsweep::cli
