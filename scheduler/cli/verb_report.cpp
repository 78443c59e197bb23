// `gravsweep report DIR --out REPORT`: the figures and the summary page of a model-vs-measurement
// comparison: Fig. 9 with model lines, residuals against depth and speed coloured by gravity,
// zstop against H (Fig. 10), the candidate ranking and the error falling.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "results/model/discover.h"
#include "results/model/model_spec.h"
#include "results/model/table3.h"
#include "results/report/html.h"
#include "results/report/report.h"
#include "results/io/table.h"
#include "scheduler/cli/campaign_input.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {
struct ReportOptions {
  std::vector<std::string> dirs;
  std::string out = "report", baseline = "base", model;
  std::vector<std::string> where;
  std::string files;  ///< files root of a postgresql:// input
  int folds = 6;
};
/// The figures of a report, each with its one-line caption.
std::vector<results::HtmlFigure> report_figures() {
  return {
      {"fig9_metrics_vs_vc.png",
       "Fig. 9 of Sunday et al. 2021: apeak, zstop and tstop against the collision velocity vc, one column per "
       "gravity level; dots are the trials, lines the models fitted on all trials."},
      {"residual_vs_depth_speed.png",
       "Residual a_meas - a_model (in g) against depth and speed, coloured by gravity, for the baseline and the "
       "extended model: a trend left over is a missing term."},
      {"fig10_zstop_vs_H.png",
       "Fig. 10: penetration depth zstop against the total height H = drop height + zstop (log-log), with the "
       "models' curves."},
      {"ranking.png",
       "Candidate terms by the mean held-out improvement of the trace error per trial (green: significant in a "
       "signed-rank test over trials, Bonferroni over the candidates)."},
      {"error_falls.png",
       "Held-out relative RMS errors of the trace, zstop, tstop and apeak per model (grouped CV, whole trials left "
       "out)."},
  };
}

/// The trials whose accelerometer saturated, and what of them the fits use; nothing when none did.
std::optional<results::HtmlSection> clipped_section(const results::Campaign& c) {
  results::Table t({"trial_id", "clipped_at_m_s2", "clipped_samples", "apeak_m_s2 (lower bound)", "zstop", "tstop"});
  for (const auto& tr : c.trials) {
    if (!(tr.info.clipped_at_m_s2 > 0)) continue;
    const std::string z = results::clip_exclusion(tr, results::ClippedMetric::zstop);
    t.add({tr.info.trial_id, results::num(tr.info.clipped_at_m_s2), results::num(tr.info.clipped_samples),
           results::num(tr.processed.metrics.apeak_m_s2),
           z.empty() ? fmt::format("kept (off by at most {} mm)", results::num(1e3 * tr.info.clip_depth_error_m, 2))
                     : fmt::format("left out (off by up to {} mm)", results::num(1e3 * tr.info.clip_depth_error_m, 2)),
           "kept"});
  }
  if (t.size() == 0) return std::nullopt;
  return results::HtmlSection{
      "Clipped accelerometer records",
      fmt::format(
          "{} trial{} saturated the accelerometer (a flat top of samples at the record's largest value). Their "
          "apeak is a lower bound: left out of Eq. 2 (Table 3), the apeak errors and the collapse; their samples "
          "up to the end of the flat top are left out of the trace fits. tstop is kept; zstop is kept when the "
          "depth integrated across the clip is off by at most {:g} % of it.",
          t.size(), t.size() == 1 ? "" : "s", 100 * results::kClipDepthTolerance),
      {{"", t}}};
}

/// Verdict, tables and figures of the report, rendered into summary.md and index.html.
results::HtmlReport report_page(const std::string& dir, const CampaignInput& in, const results::Discovery& d,
                                const std::vector<results::ComparedModel>& cm) {
  const results::Campaign& c = in.campaign;
  results::HtmlReport page;
  page.title = fmt::format("Model vs measurements: {} ({})", dir, in.kind);
  page.summary = fmt::format("{} trials, gravity levels:", c.trials.size());
  for (double g : c.gravity_levels()) page.summary += fmt::format(" {} m/s2", g);
  page.summary += fmt::format(". {} not usable{}", c.issues.size(), c.issues.empty() ? "." : "");
  for (const auto& is : c.issues) page.issues.push_back(is.to_string());
  page.verdict = d.verdict;
  if (auto clipped = clipped_section(c)) page.sections.push_back(std::move(*clipped));
  {
    results::HtmlSection s;
    s.heading = fmt::format("Where {} fails", d.baseline);
    s.text =
        "Residual a_meas - a_model (in g) by quantile bins of each axis; eta2 is the share of the residual "
        "variance the bins explain, the sign test counts trials whose within-trial slope is up or down.";
    for (const auto* axes : {&d.residual_before, &d.residual_after}) {
      results::Table t({"axis", "eta2", "trials_up", "trials_down", "mean_residual_over_g_by_bin"});
      for (const auto& a : *axes) {
        std::string bins;
        for (std::size_t i = 0; i < a.bin_center.size(); ++i)
          bins += fmt::format("{}{:.3g}:{:+.3f}", i ? " " : "", a.bin_center[i], a.bin_mean_r_over_g[i]);
        t.add({a.axis, results::num(a.eta2, 3), std::to_string(a.trials_positive), std::to_string(a.trials_negative),
               bins});
      }
      s.tables.emplace_back(axes == &d.residual_before ? "before (" + d.baseline + ")" : "after (with the added terms)",
                            t);
    }
    page.sections.push_back(std::move(s));
  }
  {
    results::Table t(
        {"gravity_m_s2", "trials", "f0_N", "f0_se_N", "inv_d1_1_m", "inv_d1_se_1_m", "vt_m_s", "alpha", "alpha_se"});
    for (const auto& r : results::table3(c))
      t.add({results::num(r.g_m_s2), std::to_string(r.trials), results::num(r.f0_N, 3), results::num(r.f0_se_N, 2),
             results::num(r.inv_d1_1_m, 3), results::num(r.inv_d1_se_1_m, 2), results::num(r.vt_m_s, 3),
             results::num(r.alpha, 3), results::num(r.alpha_se, 2)});
    page.sections.push_back({"Table 3 (paper's method: Eq. 2 fitted to apeak per gravity level)", "", {{"", t}}});
  }
  {
    results::Table t(
        {"model", "trace_rel_pct", "zstop_rms_mm", "zstop_rel_pct", "tstop_rms_ms", "tstop_rel_pct", "apeak_rel_pct"});
    for (const auto& m : cm)
      t.add({m.name, results::num(m.errors.trace_rel_pct, 3), results::num(m.errors.zstop_rms_mm, 3),
             results::num(m.errors.zstop_rel_pct, 3), results::num(m.errors.tstop_rms_ms, 3),
             results::num(m.errors.tstop_rel_pct, 3), results::num(m.errors.apeak_rel_pct, 3)});
    page.sections.push_back({"Held-out errors (grouped CV, whole trials held out)", "", {{"", t}}});
  }
  {
    results::Table t(
        {"round", "term", "mean_rel_improvement_pct", "trials_better", "trials", "p_signed_rank", "significant"});
    for (std::size_t r = 0; r < d.rounds.size(); ++r)
      for (const auto& cd : d.rounds[r])
        t.add({std::to_string(r + 1), cd.term, results::num(100 * cd.mean_rel_improvement, 3),
               std::to_string(cd.trials_better), std::to_string(cd.trials), results::num(cd.p_value, 2),
               cd.significant ? "yes" : "no"});
    page.sections.push_back({"Candidate ranking", "", {{"", t}}});
  }
  page.figures = report_figures();
  return page;
}

/// The 'before' model and the 'after' one: --model, or the baseline plus the terms `d` added.
std::pair<results::ModelSpec, results::ModelSpec> report_models(const ReportOptions& o, const results::Campaign& c,
                                                                results::Discovery& d) {
  results::ModelSpec base, after;
  try {
    base = results::parse_model(o.baseline);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  d = results::discover(c, base, o.folds);
  if (!o.model.empty()) {
    try {
      after = results::parse_model(o.model);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  } else {
    after = results::parse_model(d.named_model);
  }
  return {base, after};
}

/// summary.md: the page's tables as text, and the figures that were drawn.
void write_summary_md(const std::string& out, const results::HtmlReport& page, bool with_issues) {
  namespace fs = std::filesystem;
  std::ofstream md(fs::path(out) / "summary.md");
  md << fmt::format("# {}\n\n{}", page.title, page.summary);
  md << fmt::format("{}\n\n", with_issues ? ":" : "");
  for (const auto& is : page.issues) md << fmt::format("- {}\n", is);
  md << fmt::format("{}## Verdict\n\n{}\n\n", with_issues ? "\n" : "", page.verdict);
  for (const auto& sec : page.sections) {
    md << fmt::format("## {}\n\n{}```\n", sec.heading, sec.text.empty() ? "" : sec.text + "\n\n");
    for (std::size_t i = 0; i < sec.tables.size(); ++i)
      md << (i ? "\n" : "") << (sec.tables[i].first.empty() ? "" : sec.tables[i].first + ":\n")
         << sec.tables[i].second.render("table");
    md << "```\n\n";
  }
  md << "## Figures\n\n";
  for (const auto& f : page.figures)
    if (fs::exists(fs::path(out) / f.file)) md << fmt::format("![{}]({})\n\n{}\n\n", f.file, f.file, f.caption);
}

void run_report(const ReportOptions& o) {
  const std::string inputs = fmt::format("{}", fmt::join(o.dirs, " + "));
  auto in = load_campaign_inputs(o.dirs, o.where, 500.0, o.files);
  const results::Campaign& c = in.campaign;
  if (c.trials.size() < 6) throw UsageError(fmt::format("{}: only {} usable trials", inputs, c.trials.size()));
  results::Discovery d;
  const auto [base, after] = report_models(o, c, d);
  std::vector<results::ModelSpec> specs{base};
  if (after.name() != base.name()) specs.push_back(after);
  const auto cm = results::compare_models(c, specs, o.folds);
  results::write_report_data(o.out, c, cm, specs, &d);
  std::string log;
  const int rc = results::run_plots(o.out, "all", log);
  if (rc != 0) throw std::runtime_error("plotting failed (python3 with matplotlib needed): " + log);
  // The same tables in summary.md and index.html.
  namespace fs = std::filesystem;
  results::HtmlReport page = report_page(inputs, in, d, cm);
  write_summary_md(o.out, page, !c.issues.empty());
  const fs::path html = results::write_html_report(o.out, page);
  fmt::print("{}", log);
  fmt::print("{}\n{} (one self-contained page: open it in a browser)\nverdict: {}\n",
             (fs::path(o.out) / "summary.md").string(), html.string(), d.verdict);
}

}  // namespace

void setup_report(CLI::App& app) {
  auto o = std::make_shared<ReportOptions>();
  auto* sub = app.add_subcommand(
      "report",
      "Compare collision models with a measurement campaign and write PNG figures, a summary\n"
      "page (summary.md) and index.html (one self-contained page, figures embedded, to send) into --out: "
      "fig9_metrics_vs_vc.png (apeak, zstop, tstop vs vc with the\n"
      "model lines), residual_vs_depth_speed.png (coloured by gravity), fig10_zstop_vs_H.png,\n"
      "ranking.png and error_falls.png, plus the CSV files behind them. Without --model the\n"
      "missing effect is searched for (as `gravsweep model rank`) and the winner is added.\n\n"
      "Examples:\n"
      "  gravsweep report ../shared/data/measurements/depth-friction-dev --out report-dev\n"
      "  gravsweep report campaign.db --out report-sweep    # the drops of `submit` + `work`\n"
      "  gravsweep report data/reproduction/chrono_1g_sites data/reproduction/chrono_0.1g --out r  # both gravity "
      "levels");
  sub->add_option("dir", o->dirs,
                  "campaign database from `submit`/`work` (an SQLite file, or postgresql://user@host:port/dbname "
                  "with --files; every finished drop is a trial), SQLite file from "
                  "`measurements import`, or lab campaign folder; several are read as one campaign (e.g. one "
                  "exported dataset per gravity level: Figs. 9 and 10 then show both)")
      ->required();
  sub->add_option("--where", o->where, "filter the trials, grammar of `gravsweep results` (e.g. 'gravity_m_s2<1')");
  add_input_files_option(sub, o->files);
  sub->add_option("--out", o->out, "report folder")->capture_default_str();
  sub->add_option("--baseline", o->baseline, "the 'before' model")->capture_default_str();
  sub->add_option("--model", o->model, "the 'after' model (default: baseline + discovered terms)");
  sub->add_option("--folds", o->folds, "cross-validation folds")->check(CLI::Range(2, 100))->capture_default_str();
  sub->callback([o]() { run_report(*o); });
}

}  // namespace gravsweep::cli
