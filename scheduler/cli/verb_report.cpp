// `gravsweep report DIR --out REPORT`: the figures and the summary page of a model-vs-measurement
// comparison: Fig. 9 with model lines, residuals against depth and speed coloured by gravity,
// zstop against H (Fig. 10), the candidate ranking and the error falling.
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "results/model/model.h"
#include "results/report/report.h"
#include "results/report/table.h"
#include "scheduler/cli/campaign_input.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {
struct ReportOptions {
  std::string dir, out = "report", baseline = "base", model;
  std::vector<std::string> where;
  int folds = 6;
};
}  // namespace

void setup_report(CLI::App& app) {
  auto o = std::make_shared<ReportOptions>();
  auto* sub = app.add_subcommand(
      "report",
      "Compare collision models with a measurement campaign and write PNG figures and a summary\n"
      "page (summary.md) into --out: fig9_metrics_vs_vc.png (apeak, zstop, tstop vs vc with the\n"
      "model lines), residual_vs_depth_speed.png (coloured by gravity), fig10_zstop_vs_H.png,\n"
      "ranking.png and error_falls.png, plus the CSV files behind them. Without --model the\n"
      "missing effect is searched for (as `gravsweep model rank`) and the winner is added.\n\n"
      "Examples:\n"
      "  gravsweep report ../shared/data/measurements/depth-friction-dev --out report-dev\n"
      "  gravsweep report campaign.db --out report-sweep    # the drops of `submit` + `work`");
  sub->add_option("dir", o->dir,
                  "campaign database from `submit`/`work` (every finished drop is a trial), SQLite file from "
                  "`measurements import`, or lab campaign folder")
      ->required();
  sub->add_option("--where", o->where, "filter the trials, grammar of `gravsweep results` (e.g. 'gravity_m_s2<1')");
  sub->add_option("--out", o->out, "report folder")->capture_default_str();
  sub->add_option("--baseline", o->baseline, "the 'before' model")->capture_default_str();
  sub->add_option("--model", o->model, "the 'after' model (default: baseline + discovered terms)");
  sub->add_option("--folds", o->folds, "cross-validation folds")->check(CLI::Range(2, 100))->capture_default_str();
  sub->callback([o]() {
    auto in = load_campaign_input(o->dir, o->where);
    describe_input(o->dir, in);
    const results::Campaign& c = in.campaign;
    if (c.trials.size() < 6) throw UsageError(fmt::format("{}: only {} usable trials", o->dir, c.trials.size()));
    results::ModelSpec base, after;
    try {
      base = results::parse_model(o->baseline);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    const auto d = results::discover(c, base, o->folds);
    if (!o->model.empty()) {
      try {
        after = results::parse_model(o->model);
      } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
      }
    } else {
      after = base;
      for (const auto& n : d.added) {
        const auto& t = results::find_term(n);
        after.terms.push_back({&t, t.per_gravity, 1.0});
      }
    }
    std::vector<results::ModelSpec> specs{base};
    if (after.name() != base.name()) specs.push_back(after);
    const auto cm = results::compare_models(c, specs, o->folds);
    results::write_report_data(o->out, c, cm, specs, &d);
    std::string log;
    const int rc = results::run_plots(o->out, "all", log);
    if (rc != 0) throw std::runtime_error("plotting failed (python3 with matplotlib needed): " + log);
    // Summary page.
    namespace fs = std::filesystem;
    std::ofstream md(fs::path(o->out) / "summary.md");
    md << fmt::format("# Model vs measurements: {} ({})\n\n", o->dir, in.kind);
    md << fmt::format("{} trials, gravity levels:", c.trials.size());
    for (double g : c.gravity_levels()) md << fmt::format(" {} m/s2", g);
    md << fmt::format(". {} not usable{}\n\n", c.issues.size(), c.issues.empty() ? "." : ":");
    for (const auto& is : c.issues) md << fmt::format("- {}\n", is.to_string());
    md << fmt::format("{}## Verdict\n\n{}\n\n", c.issues.empty() ? "" : "\n", d.verdict);
    md << fmt::format("## Where {} fails\n\nResidual a_meas - a_model (in g) by quantile bins of each axis; eta2 is the share "
                      "of the residual variance the bins explain, the sign test counts trials whose within-trial slope "
                      "is up or down.\n\n```\n", d.baseline);
    for (const auto* axes : {&d.residual_before, &d.residual_after}) {
      results::Table t({"axis", "eta2", "trials_up", "trials_down", "mean_residual_over_g_by_bin"});
      for (const auto& a : *axes) {
        std::string bins;
        for (std::size_t i = 0; i < a.bin_center.size(); ++i)
          bins += fmt::format("{}{:.3g}:{:+.3f}", i ? " " : "", a.bin_center[i], a.bin_mean_r_over_g[i]);
        t.add({a.axis, results::num(a.eta2, 3), std::to_string(a.trials_positive), std::to_string(a.trials_negative), bins});
      }
      md << (axes == &d.residual_before ? "before (" + d.baseline + "):\n" : "\nafter (with the added terms):\n");
      md << t.render("table");
    }
    md << "```\n\n";
    md << "## Table 3 (paper's method: Eq. 2 fitted to apeak per gravity level)\n\n```\n";
    {
      results::Table t({"gravity_m_s2", "trials", "f0_N", "f0_se_N", "inv_d1_1_m", "inv_d1_se_1_m", "vt_m_s", "alpha", "alpha_se"});
      for (const auto& r : results::table3(c))
        t.add({results::num(r.g_m_s2), std::to_string(r.trials), results::num(r.f0_N, 3), results::num(r.f0_se_N, 2),
               results::num(r.inv_d1_1_m, 3), results::num(r.inv_d1_se_1_m, 2), results::num(r.vt_m_s, 3),
               results::num(r.alpha, 3), results::num(r.alpha_se, 2)});
      md << t.render("table");
    }
    md << "```\n\n## Held-out errors (grouped CV, whole trials held out)\n\n```\n";
    {
      results::Table t({"model", "trace_rel_pct", "zstop_rms_mm", "zstop_rel_pct", "tstop_rms_ms", "tstop_rel_pct", "apeak_rel_pct"});
      for (const auto& m : cm)
        t.add({m.name, results::num(m.errors.trace_rel_pct, 3), results::num(m.errors.zstop_rms_mm, 3),
               results::num(m.errors.zstop_rel_pct, 3), results::num(m.errors.tstop_rms_ms, 3),
               results::num(m.errors.tstop_rel_pct, 3), results::num(m.errors.apeak_rel_pct, 3)});
      md << t.render("table");
    }
    md << "```\n\n## Candidate ranking\n\n```\n";
    {
      results::Table t({"round", "term", "mean_rel_improvement_pct", "trials_better", "trials", "p_signed_rank", "significant"});
      for (std::size_t r = 0; r < d.rounds.size(); ++r)
        for (const auto& cd : d.rounds[r])
          t.add({std::to_string(r + 1), cd.term, results::num(100 * cd.mean_rel_improvement, 3),
                 std::to_string(cd.trials_better), std::to_string(cd.trials), results::num(cd.p_value, 2),
                 cd.significant ? "yes" : "no"});
      md << t.render("table");
    }
    md << "```\n\n## Figures\n\n";
    for (const char* png : {"fig9_metrics_vs_vc.png", "residual_vs_depth_speed.png", "fig10_zstop_vs_H.png",
                            "ranking.png", "error_falls.png"})
      md << fmt::format("![{}]({})\n\n", png, png);
    fmt::print("{}", log);
    fmt::print("{}\nverdict: {}\n", (fs::path(o->out) / "summary.md").string(), d.verdict);
  });
}

}  // namespace gravsweep::cli
