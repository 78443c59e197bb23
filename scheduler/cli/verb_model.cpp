// `gravsweep model`: collision models as sums of named terms, compared with a measurement
// campaign. Sub-verbs: terms, table3 (the paper's method), fit (before/after), rank (which
// effect is missing).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <unistd.h>
#include <string>
#include <vector>

#include "results/model/model.h"
#include "results/model/synth.h"
#include "results/report/report.h"
#include "results/report/table.h"
#include "scheduler/cli/campaign_input.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/format_option.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

using results::num;

constexpr const char* kDirHelp =
    "campaign database from `submit`/`work` (an SQLite file, or postgresql://user@host:port/dbname with "
    "--files; every finished drop is a trial), SQLite file from `measurements import`, or lab campaign folder; several "
    "are read as one campaign (e.g. one "
    "exported dataset per gravity level)";
constexpr const char* kWhereHelp =
    "filter the trials, grammar of `gravsweep results` (e.g. 'gravity_m_s2<1'); repeatable";

struct ModelOptions {
  std::vector<std::string> dir;  ///< one or more inputs, read as one campaign
  std::string model = "base+depth_friction";
  std::string baseline = "base";
  std::string format = "table";
  std::string plot;
  std::vector<std::string> where;
  std::string files;  ///< files root of a postgresql:// input
  int folds = 6;
  double alpha = 0.01;
  double min_improvement = 0.03;
};

results::Campaign load(const std::vector<std::string>& dir, const std::vector<std::string>& where,
                       const std::string& files) {
  auto in = load_campaign_inputs(dir, where, 500.0, files);
  if (in.campaign.trials.size() < 6)
    throw UsageError(fmt::format("{}: only {} usable trials; at least 6 are needed", fmt::join(dir, " + "),
                                 in.campaign.trials.size()));
  return std::move(in.campaign);
}

results::ModelSpec spec_of(const std::string& s) {
  try {
    return results::parse_model(s);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

void print_params(const results::FittedModel& m, const std::string& format) {
  results::Table t({"parameter", "value", "std_error", "unit_note"});
  for (Eigen::Index j = 0; j < m.coef.size(); ++j)
    t.add({m.column_names[static_cast<std::size_t>(j)], num(m.coef(j)), num(std::sqrt(std::max(0.0, m.cov(j, j))), 2),
           "SE cluster-robust over trials"});
  t.print(format);
}

results::Table error_table(const std::vector<results::ComparedModel>& cm) {
  results::Table t({"model", "trace_rms_m_s2", "trace_rel_pct", "zstop_rms_mm", "zstop_rel_pct", "tstop_rms_ms",
                    "tstop_rel_pct", "apeak_rms_m_s2", "apeak_rel_pct", "trials"});
  for (const auto& m : cm) {
    const auto& e = m.errors;
    t.add({m.name, num(e.trace_rms_m_s2, 3), num(e.trace_rel_pct, 3), num(e.zstop_rms_mm, 3), num(e.zstop_rel_pct, 3),
           num(e.tstop_rms_ms, 3), num(e.tstop_rel_pct, 3), num(e.apeak_rms_m_s2, 3), num(e.apeak_rel_pct, 3),
           std::to_string(e.trials)});
  }
  return t;
}

/// When a term is added every reported error should fall, or the report says why one
/// does not. Compares the last model with `base` metric by metric (RMS in units, and relative).
void explain_rises(const std::vector<results::ComparedModel>& cm) {
  const results::ComparedModel* before = nullptr;
  for (const auto& m : cm)
    if (m.name == "base") before = &m;
  if (!before || &cm.back() == before) return;
  const auto &b = before->errors, &a = cm.back().errors;
  struct Pair {
    const char *metric, *unit;
    double rms_b, rms_a, rel_b, rel_a;
  };
  for (const Pair& p : {Pair{"zstop", "mm", b.zstop_rms_mm, a.zstop_rms_mm, b.zstop_rel_pct, a.zstop_rel_pct},
                        Pair{"tstop", "ms", b.tstop_rms_ms, a.tstop_rms_ms, b.tstop_rel_pct, a.tstop_rel_pct},
                        Pair{"apeak", "m_s2", b.apeak_rms_m_s2, a.apeak_rms_m_s2, b.apeak_rel_pct, a.apeak_rel_pct}}) {
    const bool rms_up = p.rms_a > p.rms_b, rel_up = p.rel_a > p.rel_b;
    if (rms_up && !rel_up)
      fmt::print(
          "note: {0}_rms_{1} rises {2:.3g} -> {3:.3g} while {0}_rel_pct falls {4:.3g} -> {5:.3g}: the RMS in "
          "{1} is set by the trials with the largest {0} (the fastest, at the highest gravity), the relative "
          "error weighs every trial alike; see `model residuals` for the trials\n",
          p.metric, p.unit, p.rms_b, p.rms_a, p.rel_b, p.rel_a);
    else if (rel_up && !rms_up)
      fmt::print(
          "note: {0}_rel_pct rises {2:.3g} -> {3:.3g} while {0}_rms_{1} falls: the relative error is set by "
          "the trials with the smallest {0} (slow or low-gravity ones); see `model residuals`\n",
          p.metric, p.unit, p.rel_b, p.rel_a);
    else if (rms_up && rel_up)
      fmt::print(
          "note: both {0} errors rise with {1}: it fits the trace better but predicts {0} worse held out; "
          "see `model residuals` for where\n",
          p.metric, cm.back().name);
  }
}

void print_axes(const std::vector<results::AxisResidual>& axes, const std::string& format) {
  results::Table t({"axis", "eta2", "split_half_r", "trials_slope_up", "trials_slope_down", "sign_test_p",
                    "mean_residual_over_g_by_bin"});
  for (const auto& a : axes) {
    std::string bins;
    for (std::size_t i = 0; i < a.bin_center.size(); ++i)
      bins += fmt::format("{}{:.3g}:{:+.3f}", i ? " " : "", a.bin_center[i], a.bin_mean_r_over_g[i]);
    const bool trial_level = a.trials_positive + a.trials_negative == 0;
    t.add({a.axis, num(a.eta2, 3), num(a.split_half_r, 2), trial_level ? "-" : std::to_string(a.trials_positive),
           trial_level ? "-" : std::to_string(a.trials_negative), trial_level ? "-" : num(a.slope_sign_trials_p, 2),
           bins});
  }
  t.print(format);
}

void print_ranking(const results::Discovery& d, const std::string& format) {
  results::Table t(
      {"round", "rank", "term", "mean_rel_improvement_pct", "trials_better", "trials", "p_signed_rank", "significant"});
  for (std::size_t r = 0; r < d.rounds.size(); ++r)
    for (std::size_t i = 0; i < d.rounds[r].size(); ++i) {
      const auto& c = d.rounds[r][i];
      t.add({std::to_string(r + 1), std::to_string(i + 1), c.term, num(100 * c.mean_rel_improvement, 3),
             std::to_string(c.trials_better), std::to_string(c.trials), num(c.p_value, 2),
             c.significant ? "yes" : "no"});
    }
  // The search beyond the named library: the nested-CV test of choosing a form, then the forms by
  // in-sample improvement (screening only: no test of their own).
  if (d.generated_searched) {
    const auto& g = d.generated_test;
    t.add({"generated", "1", g.term, num(100 * g.mean_rel_improvement, 3), std::to_string(g.trials_better),
           std::to_string(g.trials), num(g.p_value, 2), g.significant ? "yes" : "no"});
  }
  const std::size_t shown =
      format == "table" ? std::min<std::size_t>(6, d.generated_screened.size()) : d.generated_screened.size();
  for (std::size_t i = 0; i < shown; ++i) {
    const auto& c = d.generated_screened[i];
    t.add({"screened", std::to_string(i + 1), c.term, num(100 * c.mean_rel_improvement, 3), "-", "-", "-", "-"});
  }
  t.print(format);
  if (format == "table" && shown < d.generated_screened.size())
    fmt::print(
        "(round 'generated': the held-out test of choosing a form, nested CV; 'screened': in-sample gain of "
        "each form, {} more with --format csv)\n",
        d.generated_screened.size() - shown);
}

}  // namespace

void setup_model(CLI::App& app) {
  auto* sub = app.add_subcommand("model",
                                 "Collision models m dv/dt = m g - R(z, v, g) as sums of named terms, compared with a\n"
                                 "measurement campaign. Run `gravsweep model terms` for the term library.");
  sub->require_subcommand(1);
  setup_model_collapse(*sub);
  setup_model_lolo(*sub);

  auto* terms = sub->add_subcommand("terms", "List the registered model terms.\n\nExample:\n  gravsweep model terms");
  auto tf = std::make_shared<std::string>("table");
  add_format_option(terms, *tf);
  terms->callback([tf]() {
    results::Table t({"term", "parameters", "default_sharing", "meaning", "references"});
    for (const auto& r : results::term_registry()) {
      std::string p;
      for (const auto& x : r.params) p += (p.empty() ? "" : " ") + x;
      t.add({r.name, p, r.per_gravity ? "per_gravity" : "shared", r.meaning, r.references});
    }
    t.print(*tf);
  });

  auto o3 = std::make_shared<ModelOptions>();
  auto* t3 = sub->add_subcommand(
      "table3",
      "The paper's method (Sunday et al. 2021 Sect. 4): per gravity level fit Eq. 2 to apeak(vc),\n"
      "print f0, 1/d1, vt (Eq. 5) and alpha (zstop ~ H^alpha) with standard errors, as Table 3,\n"
      "and bootstrap errors of f0 and 1/d1 over whole drops (*_boot_se_*: they include the\n"
      "scatter between impact sites, which the least-squares errors understate when sites repeat).\n\n"
      "Examples:\n  gravsweep model table3 ../shared/data/measurements/depth-friction-dev\n"
      "  gravsweep model table3 campaign.db --where 'impact_speed_m_s>=0.5'");
  t3->add_option("dir", o3->dir, kDirHelp)->required();
  t3->add_option("--where", o3->where, kWhereHelp);
  add_input_files_option(t3, o3->files);
  add_format_option(t3, o3->format);
  t3->callback([o3]() {
    const auto c = load(o3->dir, o3->where, o3->files);
    results::Table t({"gravity_m_s2", "trials", "f0_N", "f0_se_N", "f0_boot_se_N", "inv_d1_1_m", "inv_d1_se_1_m",
                      "inv_d1_boot_se_1_m", "vt_m_s", "vt_se_m_s", "alpha", "alpha_se", "note"});
    for (const auto& r : results::table3(c))
      t.add({num(r.g_m_s2), std::to_string(r.trials), num(r.f0_N, 3), num(r.f0_se_N, 2), num(r.f0_boot_se_N, 2),
             num(r.inv_d1_1_m, 3), num(r.inv_d1_se_1_m, 2), num(r.inv_d1_boot_se_1_m, 2), num(r.vt_m_s, 3),
             num(r.vt_se_m_s, 2), num(r.alpha, 3), num(r.alpha_se, 2), r.note});
    t.print(o3->format);
  });

  auto of = std::make_shared<ModelOptions>();
  auto* fit = sub->add_subcommand(
      "fit",
      "Fit a model to the traces (least squares on m (a + g) = R(z, v) over each collision, clear\n"
      "of the filter's transient, trials weighted equally, standard errors cluster-robust over\n"
      "trials), then print the held-out errors (whole trials left out, grouped K-fold) of the\n"
      "paper's Eq. 2-4, the baseline and the model side by side: trace RMS, zstop, tstop, apeak.\n\n"
      "Examples:\n"
      "  gravsweep model fit ../shared/data/measurements/depth-friction-dev --model base+depth_friction\n"
      "  gravsweep model fit DIR --model spec.json --plot fall.png --format csv\n"
      "The figure of the error falling is written to --plot (default error_falls.png).");
  fit->add_option("dir", of->dir, kDirHelp)->required();
  fit->add_option("--where", of->where, kWhereHelp);
  add_input_files_option(fit, of->files);
  fit->add_option("--model", of->model, "model: 'base+depth_friction' or a JSON spec file")->capture_default_str();
  fit->add_option("--baseline", of->baseline, "the 'before' model")->capture_default_str();
  fit->add_option("--folds", of->folds, "cross-validation folds (whole trials)")
      ->check(CLI::Range(2, 100))
      ->capture_default_str();
  of->plot = "error_falls.png";
  fit->add_option("--plot", of->plot, "write the error-falling figure (PNG) here")->capture_default_str();
  auto no_plot = std::make_shared<bool>(false);
  fit->add_flag("--no-plot", *no_plot, "do not write the figure");
  add_format_option(fit, of->format);
  fit->callback([of, no_plot]() {
    if (*no_plot) of->plot.clear();
    const auto c = load(of->dir, of->where, of->files);
    const auto base = spec_of(of->baseline);
    const auto spec = spec_of(of->model);
    const auto fm = results::fit_model(spec, c);
    if (of->format == "table")
      fmt::print("Model {} fitted on {} trials ({} samples):\n", spec.name(), fm.trials_used, fm.samples_used);
    print_params(fm, of->format);
    const auto cm = results::compare_models(c, {base, spec}, of->folds);
    if (of->format == "table")
      fmt::print("\nHeld-out errors ({}-fold grouped CV, whole trials held out), before and after:\n", of->folds);
    error_table(cm).print(of->format);
    if (of->format == "table") explain_rises(cm);
    if (!of->plot.empty()) {
      namespace fs = std::filesystem;
      const fs::path png = fs::absolute(of->plot);
      // The plot's data go to a private temporary folder, removed afterwards.
      struct Tmp {
        fs::path p;
        ~Tmp() {
          std::error_code ec;
          fs::remove_all(p, ec);
        }
      } tmp{fs::temp_directory_path() / fmt::format("gravsweep-fit-{}", ::getpid())};
      results::write_report_data(tmp.p.string(), c, cm, {base, spec}, nullptr);
      std::string log;
      if (results::run_plots(tmp.p.string(), "errors", log) != 0) throw std::runtime_error("plotting failed: " + log);
      fs::create_directories(png.parent_path());
      fs::copy_file(tmp.p / "error_falls.png", png, fs::copy_options::overwrite_existing);
      if (of->format == "table") fmt::print("\nwrote {}\n", png.string());
    }
  });

  auto ores = std::make_shared<ModelOptions>();
  ores->model = "base";
  auto* res = sub->add_subcommand(
      "residuals",
      "Where a model fails: fit it on all trials, then print per trial the residuals of the\n"
      "metrics (model - measured zstop, tstop, apeak; RMS of a_meas - a_model over the trace)\n"
      "with gravity, impact speed and fill height, and per sample the mean residual (in g) in\n"
      "quantile bins of depth, speed, time since contact, gravity, impact speed and fill height,\n"
      "with eta^2 (share of residual variance the binning explains) and a sign test over trials\n"
      "of the within-trial slope.\n\n"
      "Example:\n  gravsweep model residuals ../shared/data/measurements/depth-friction-dev --model base");
  res->add_option("dir", ores->dir, kDirHelp)->required();
  res->add_option("--where", ores->where, kWhereHelp);
  add_input_files_option(res, ores->files);
  res->add_option("--model", ores->model, "model: 'base' or a JSON spec file")->capture_default_str();
  add_format_option(res, ores->format);
  res->callback([ores]() {
    const auto c = load(ores->dir, ores->where, ores->files);
    const auto fm = results::fit_model(spec_of(ores->model), c);
    results::Table t({"trial_id", "gravity_m_s2", "vc_m_s", "fill_height_m", "trace_rms_m_s2", "dzstop_mm", "dtstop_ms",
                      "dapeak_m_s2"});
    // apeak as measured: the model's record filtered like the trial, with the other trials'
    // fluctuations about the model at its level (results/model/model.h).
    std::vector<std::vector<double>> fluct;
    for (const auto& tr : c.trials) fluct.push_back(results::relative_residuals(fm, tr));
    for (std::size_t i = 0; i < c.trials.size(); ++i) {
      const auto& tr = c.trials[i];
      const auto p = results::predict(fm, tr, results::same_level_fluctuations(c, fluct, i));
      const auto& m = tr.processed.metrics;
      t.add({tr.info.trial_id, num(tr.info.gravity_m_s2), num(m.vc_m_s), num(tr.info.fill_height_m),
             num(std::sqrt(results::trial_trace_mse(fm, tr)), 3),
             p.stopped ? num(1e3 * (p.zstop_m - m.zstop_m), 3) : "nan",
             p.stopped ? num(1e3 * (p.tstop_s - m.tstop_s), 3) : "nan", num(p.apeak_m_s2 - m.apeak_m_s2, 3)});
    }
    if (ores->format == "table") fmt::print("Per trial ({} fitted on all trials; model - measured):\n", fm.spec.name());
    t.print(ores->format);
    if (ores->format == "table") fmt::print("\nPer sample, residual a_meas - a_model in units of g, by axis:\n");
    print_axes(results::residual_axes(fm, c), ores->format);
  });

  struct DetectOptions {
    int seeds = 5, null_seeds = 20;
    std::vector<std::string> terms{"depth_friction", "immersion_drag", "bottom_stiffening", "viscous_drag"};
    std::string format = "table";
  };
  auto od = std::make_shared<DetectOptions>();
  auto* det = sub->add_subcommand(
      "check-detection",
      "Validate `model rank` on synthetic laboratories (docs/physics/force-laws.md 2.4 step 4): for each hidden\n"
      "term, write --seeds campaigns with `synth` (72 trials each, default noise), rank, and count\n"
      "how often the hidden term is ranked first and significant; then --null-seeds campaigns with\n"
      "nothing hidden, counting how often anything is reported. Campaigns go to a temporary folder.\n\n"
      "Example:\n  gravsweep model check-detection --seeds 5 --null-seeds 20");
  det->add_option("--seeds", od->seeds, "campaigns per hidden term")->capture_default_str();
  det->add_option("--null-seeds", od->null_seeds, "campaigns with nothing hidden")->capture_default_str();
  det->add_option("--terms", od->terms, "hidden terms to test")->delimiter(',')->capture_default_str();
  add_format_option(det, od->format);
  det->callback([od]() {
    namespace fs = std::filesystem;
    const fs::path root = fs::temp_directory_path() / fmt::format("gravsweep-detect-{}", ::getpid());
    struct Cleanup {
      fs::path p;
      ~Cleanup() {
        std::error_code ec;
        fs::remove_all(p, ec);
      }
    } cleanup{root};
    results::Table t({"hidden_term", "campaigns", "ranked_first", "first_and_significant", "anything_reported"});
    auto run_one = [&](const std::string& model, unsigned seed, const std::vector<double>& fills) {
      results::SynthOptions so;
      so.seed = seed;
      if (!fills.empty()) so.fill_height_m = fills;
      const fs::path dir = root / fmt::format("{}-{}", model, seed);
      results::write_synthetic_campaign(dir.string(), spec_of(model), so);
      const auto c = results::load_campaign(dir.string());
      auto d = results::discover(c, spec_of("base"), 6, 0.01, 0.03, 1);
      fs::remove_all(dir);
      return d;
    };
    for (const auto& term : od->terms) {
      int first = 0, sig = 0, any = 0;
      for (int s = 1; s <= od->seeds; ++s) {
        const auto d =
            run_one("base+" + term, static_cast<unsigned>(s),
                    term == "bottom_stiffening" ? std::vector<double>{0.05, 0.06, 0.08} : std::vector<double>{});
        const auto& top = d.rounds.front().front();
        const bool ok = top.term == term || (term == "depth_friction" && top.term == "gravity_depth_friction");
        first += ok;
        sig += ok && top.significant;
        any += !d.added.empty() || d.structure_left;
      }
      t.add({term, std::to_string(od->seeds), std::to_string(first), std::to_string(sig), std::to_string(any)});
    }
    int any = 0;
    for (int s = 1; s <= od->null_seeds; ++s) {
      const auto d = run_one("base", static_cast<unsigned>(100 + s), {});
      any += !d.added.empty() || d.structure_left;
    }
    t.add({"(nothing hidden)", std::to_string(od->null_seeds), "-", "-", std::to_string(any)});
    t.print(od->format);
  });

  auto orank = std::make_shared<ModelOptions>();
  auto* rank = sub->add_subcommand(
      "rank",
      "Which effect is missing: fit the baseline, show where it fails (residuals against depth,\n"
      "speed, time since contact, gravity, impact speed, fill height), then rank every other\n"
      "registered term by its held-out improvement with whole trials left out (grouped CV) and\n"
      "a Wilcoxon signed-rank test over trials (not samples), Bonferroni over candidates. Adds the winner and\n"
      "repeats while a term is significant, then says which effect is missing, 'no missing\n"
      "effect found', 'partly explained by X; structure left along <axis>', or 'structure left\n"
      "that no named term explains' with where it lies. When a term was added, structure is left, or\n"
      "the residual's within-trial slope has the same sign in nearly every trial (sign test p < 1e-6,\n"
      "however weak: 'the residuals trend consistently along <axis>'), the same test runs\n"
      "over a generated family of forms (z^a |v|^b, exp(-z/l), 1-exp(-z/l) and their products with\n"
      "z, |v|, v^2; each per gravity level or shared) and a significant one is reported by its\n"
      "formula, never by a physical name, with the held-out errors without and with it; fit it\n"
      "like a named term: --model 'base+z^1*v^1'.\n\n"
      "Examples:\n  gravsweep model rank ../shared/data/measurements/depth-friction-dev\n"
      "  gravsweep model rank campaign.db          # the drops of `gravsweep submit` + `work`\n"
      "  gravsweep model rank data/reproduction/chrono_1g --where 'impact_velocity_m_s<0.5'  # one regime\n"
      "  gravsweep model rank data/gravity_sweep/g9.81 data/gravity_sweep/g1.62 --scaled  # one law for all g");
  rank->alias("discover");
  rank->add_option("dir", orank->dir, kDirHelp)->required();
  rank->add_option("--where", orank->where, kWhereHelp);
  add_input_files_option(rank, orank->files);
  rank->add_option("--baseline", orank->baseline, "starting model")->capture_default_str();
  rank->add_flag_callback(
      "--scaled", [orank]() { orank->baseline = "scaled_base"; },
      "scaled mode: start from one gravity-scaled law for every level (scaled_base: phi m g + m v^2/d1) and "
      "rank only terms that are one law for all levels too, so an effect whose size does not follow g "
      "(e.g. cohesion) is found instead of absorbed level by level; same as --baseline scaled_base");
  rank->add_option("--folds", orank->folds, "cross-validation folds")->check(CLI::Range(2, 100))->capture_default_str();
  rank->add_option("--alpha", orank->alpha, "family-wise significance level")->capture_default_str();
  rank->add_option("--min-improvement", orank->min_improvement, "minimum mean relative improvement")
      ->capture_default_str();
  add_format_option(rank, orank->format);
  rank->callback([orank]() {
    const auto c = load(orank->dir, orank->where, orank->files);
    const auto base = spec_of(orank->baseline);
    const auto d = results::discover(c, base, orank->folds, orank->alpha, orank->min_improvement);
    if (orank->format == "table") fmt::print("Where {} fails (residual a_meas - a_model in units of g):\n", d.baseline);
    print_axes(d.residual_before, orank->format);
    if (orank->format == "table") fmt::print("\nCandidate terms by held-out improvement:\n");
    print_ranking(d, orank->format);
    if (orank->format == "table")
      fmt::print("\nVerdict: {}\n", d.verdict);
    else
      std::fprintf(stderr, "verdict: %s\n", d.verdict.c_str());
  });
}

}  // namespace gravsweep::cli
