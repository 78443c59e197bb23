// `gravsweep model fit`: a model fitted to the traces, and its held-out errors beside the paper's
// Eq. 2-4 and a baseline (before and after), with the figure of the error falling.
#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "results/model/law.h"
#include "results/model/level_out.h"
#include "results/model/cross_validation.h"
#include "results/model/fit.h"
#include "results/model/model_spec.h"
#include "results/report/report.h"
#include "results/io/table.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/model_inputs.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/pipeline/build_version.h"

namespace gravsweep::cli {

namespace {

using results::num;

struct FitOptions {
  ModelInputs in;
  std::string model = "base+depth_friction";
  std::string baseline = "base";
  int folds = 6;
  std::string leave_out = "trials";
  std::string plot = "error_falls.png";
  bool no_plot = false;
  std::string save;  ///< the law file (results/model/law.h); empty: none
  int resamples = results::kLawResamples;
  bool per_froude = false;      ///< the held-out errors by gravity level and Froude number too
  std::string weight = "auto";  ///< the units of each trial's residuals (ResidualUnits)
};

/// `--weight`: auto, trial-force or mg.
results::ResidualUnits residual_units_named(const std::string& w) {
  if (w == "trial-force") return results::ResidualUnits::trial_force;
  if (w == "mg") return results::ResidualUnits::gravity;
  return results::ResidualUnits::automatic;
}

/// `--save`: the law with its bootstrap, form error by Froude number and ranges.
void save_law(const FitOptions& o, const results::ModelSpec& spec, const results::Campaign& c) {
  results::SavedLaw law;
  try {
    law = results::make_saved_law(spec, c, o.resamples);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("--save {}: {}", o.save, e.what()));
  }
  law.code_version = pipeline::build_version();
  for (const auto& in : o.in.inputs) law.fitted_on += (law.fitted_on.empty() ? "" : " ") + in;
  for (const auto& w : o.in.where) law.fitted_on += " --where '" + w + "'";
  results::write_law(o.save, law);
  if (o.in.format == "table")
    fmt::print(
        "\nwrote {}: {} constants, {} bootstrap resamples, form error by Froude number ({}) at {} Froude numbers, "
        "fitted on {} trials at {} gravity levels\n",
        o.save, law.values.size(), law.bootstrap.size(), law.form_error_source, law.form_error.size(), law.trials,
        law.levels);
}

results::Table params_table(const results::FittedModel& m) {
  results::Table t({"parameter", "value", "std_error", "unit_note"});
  for (Eigen::Index j = 0; j < m.coef.size(); ++j)
    t.add({m.column_names[static_cast<std::size_t>(j)], num(m.coef(j)), num(std::sqrt(std::max(0.0, m.cov(j, j))), 2),
           "SE cluster-robust over trials"});
  return t;
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

/// The error-falling figure (results/report/plots) of the compared models, written to `png`; its
/// data go to a private temporary folder, removed afterwards.
void draw_error_falls(const results::Campaign& c, const std::vector<results::ComparedModel>& cm,
                      const std::vector<results::ModelSpec>& specs, const std::filesystem::path& png) {
  namespace fs = std::filesystem;
  struct Tmp {
    fs::path p;
    ~Tmp() {
      std::error_code ec;
      fs::remove_all(p, ec);
    }
  } tmp{fs::temp_directory_path() / fmt::format("gravsweep-fit-{}", ::getpid())};
  results::write_report_data(tmp.p.string(), c, cm, specs, nullptr);
  std::string log;
  if (results::run_plots(tmp.p.string(), "errors", log) != 0) throw std::runtime_error("plotting failed: " + log);
  fs::create_directories(png.parent_path());
  fs::copy_file(tmp.p / "error_falls.png", png, fs::copy_options::overwrite_existing);
}

/// Leave one projectile out, projectile by projectile: the held-out drops' mean signed error
/// (predicted - measured, % of measured) in zstop and tstop of each model.
results::Table projectile_table(const results::Campaign& c, const std::vector<results::ComparedModel>& cm) {
  std::vector<std::string> cols{"projectile_diameter_m", "projectile_mass_kg", "drops"};
  for (const auto& m : cm) {
    cols.push_back(m.name + ":zstop_err_pct");
    cols.push_back(m.name + ":tstop_err_pct");
  }
  results::Table t(cols);
  int projectiles = 0;
  const std::vector<int> of = results::projectile_index(c, &projectiles);
  for (int k = 0; k < projectiles; ++k) {
    std::vector<std::size_t> drops;
    for (std::size_t i = 0; i < of.size(); ++i)
      if (of[i] == k) drops.push_back(i);
    const auto& info = c.trials[drops.front()].info;
    std::vector<std::string> row{num(info.projectile_diameter_m), num(info.projectile_mass_kg),
                                 std::to_string(drops.size())};
    for (const auto& m : cm) {
      double ez = 0, et = 0;
      int nz = 0, nt = 0;
      for (const std::size_t i : drops) {
        const auto& p = m.held_out.pred[i];
        const auto& meas = c.trials[i].processed.metrics;
        if (!p.stopped) continue;
        if (meas.zstop_m > 0) ez += 100 * (p.zstop_m - meas.zstop_m) / meas.zstop_m, ++nz;
        if (meas.tstop_s > 0) et += 100 * (p.tstop_s - meas.tstop_s) / meas.tstop_s, ++nt;
      }
      row.push_back(nz ? num(ez / nz, 3) : "");
      row.push_back(nt ? num(et / nt, 3) : "");
    }
    t.add(row);
  }
  return t;
}

/// Each model's held-out predictions by gravity level and Froude number (results::froude_cells):
/// the signed mean errors (predicted - measured, % of measured) a median over every trial hides,
/// each cell flagged when beyond a target (zstop 10 %, tstop 15 %, as leave-one-level-out's).
struct ModelCells {
  std::string model;
  std::vector<results::FroudeCell> cells;
};
std::vector<ModelCells> model_cells(const results::Campaign& c, const std::vector<results::ComparedModel>& cm) {
  std::vector<ModelCells> out;
  for (const auto& m : cm) out.push_back({m.name, results::froude_cells(c, m.held_out.pred)});
  return out;
}

results::Table froude_table(const std::vector<ModelCells>& by_model) {
  results::Table t({"model", "gravity_m_s2", "impact_fr", "drops", "zstop_mean_err_pct", "zstop_min_err_pct",
                    "zstop_max_err_pct", "tstop_mean_err_pct", "beyond_target"});
  for (const auto& [model, cells] : by_model)
    for (const auto& [g, f] : cells)
      t.add({model, num(g), num(f.froude, 3), std::to_string(f.drops), num(f.zstop_mean_err_pct, 3),
             num(f.zstop_min_err_pct, 3), num(f.zstop_max_err_pct, 3), num(f.tstop_mean_err_pct, 3),
             f.misses ? "yes" : "no"});
  return t;
}

/// "model: 7 of 25 cells beyond a target (worst zstop +23.1 % at 0.1 m/s2, Fr 2)" per model.
void print_froude_verdicts(const std::vector<ModelCells>& by_model) {
  for (const auto& [model, cells] : by_model) {
    int beyond = 0;
    const results::FroudeCell* worst = nullptr;
    for (const auto& cell : cells) {
      beyond += cell.errors.misses;
      if (std::isfinite(cell.errors.zstop_mean_err_pct) &&
          (!worst || std::abs(cell.errors.zstop_mean_err_pct) > std::abs(worst->errors.zstop_mean_err_pct)))
        worst = &cell;
    }
    if (!worst) continue;
    fmt::print(
        "{}: {} of {} cells beyond a target (zstop {:g} %, tstop {:g} %); worst zstop {:+.1f} % at {:g} m/s2, "
        "Fr {:.2g}\n",
        model, beyond, cells.size(), results::kLevelOutZstopTargetPct, results::kLevelOutTstopTargetPct,
        worst->errors.zstop_mean_err_pct, worst->g_m_s2, worst->errors.froude);
  }
}

int projectile_count(const results::Campaign& c) {
  int n = 0;
  results::projectile_index(c, &n);
  return n;
}

/// The held-out errors in `table` or `csv`: the table of errors before and after, each projectile's
/// when it is held out, and (table) why an error does not fall.
void print_errors(const FitOptions& o, const results::Campaign& c, const std::vector<results::ComparedModel>& cm,
                  int folds) {
  const bool table = o.in.format == "table";
  if (table && folds == results::kLeaveOneProjectileOut)
    fmt::print("\nHeld-out errors (leave one projectile out: {} projectiles by diameter and mass), before and after:\n",
               projectile_count(c));
  else if (table)
    fmt::print("\nHeld-out errors ({}-fold grouped CV, whole trials held out), before and after:\n", o.folds);
  error_table(cm).print(o.in.format);
  if (folds == results::kLeaveOneProjectileOut) {
    if (table)
      fmt::print("\nEach projectile held out: mean signed error of its drops (predicted - measured, % of measured):\n");
    projectile_table(c, cm).print(o.in.format);
  }
  if (o.per_froude) {
    if (table)
      fmt::print(
          "\nBy gravity level and Froude number (held out; signed mean error, predicted - measured, % of "
          "measured):\n");
    const auto by_model = model_cells(c, cm);
    froude_table(by_model).print(o.in.format);
    if (table) print_froude_verdicts(by_model);
  }
  if (table) explain_rises(cm);
}

/// `--format json`: one document with the constants and the held-out errors (and each projectile's
/// when projectiles are held out), so that a script reads it with one parse.
void print_fit_json(const results::ModelSpec& spec, const results::FittedModel& fm, const results::Campaign& c,
                    const std::vector<results::ComparedModel>& cm, bool by_projectile) {
  nlohmann::json out = {{"model", spec.name()},
                        {"trials", fm.trials_used},
                        {"samples", fm.samples_used},
                        {"parameters", params_table(fm).json_value()},
                        {"held_out_errors", error_table(cm).json_value()}};
  if (by_projectile) out["projectiles_held_out"] = projectile_table(c, cm).json_value();
  out["by_froude"] = froude_table(model_cells(c, cm)).json_value();
  std::fputs((out.dump(2) + "\n").c_str(), stdout);
}

void run_fit(const FitOptions& o) {
  const bool table = o.in.format == "table";
  const auto c = load_model_campaign(o.in);
  auto base = model_of(o.baseline);
  auto spec = model_of(o.model);
  base.residual_units = spec.residual_units = residual_units_named(o.weight);
  const auto fm = results::fit_model(spec, c);
  const int folds = o.leave_out == "projectile" ? results::kLeaveOneProjectileOut : o.folds;
  const auto cm = results::compare_models(c, {base, spec}, folds);
  if (o.in.format == "json") {
    print_fit_json(spec, fm, c, cm, folds == results::kLeaveOneProjectileOut);
  } else {
    if (table) fmt::print("Model {} fitted on {} trials ({} samples):\n", spec.name(), fm.trials_used, fm.samples_used);
    params_table(fm).print(o.in.format);
    print_errors(o, c, cm, folds);
  }
  if (!o.save.empty()) save_law(o, spec, c);
  if (o.no_plot || o.plot.empty()) return;
  const std::filesystem::path png = std::filesystem::absolute(o.plot);
  draw_error_falls(c, cm, {base, spec}, png);
  if (table) fmt::print("\nwrote {}\n", png.string());
}

}  // namespace

void setup_model_fit(CLI::App& model) {
  auto o = std::make_shared<FitOptions>();
  auto* sub = model.add_subcommand(
      "fit",
      "Fit a model to the traces (least squares on m (a + g) = R(z, v) over each collision, clear\n"
      "of the filter's transient, trials weighted equally, standard errors cluster-robust over\n"
      "trials), then print the held-out errors (whole trials left out, grouped K-fold) of the\n"
      "paper's Eq. 2-4, the baseline and the model side by side: trace RMS, zstop, tstop, apeak.\n\n"
      "Examples:\n"
      "  gravsweep model fit ../shared/data/measurements/depth-friction-dev --model base+depth_friction\n"
      "  gravsweep model fit DIR --model spec.json --plot fall.png --format csv\n"
      "  gravsweep model fit data/gravity_sweep/g*/ --model scaled_base+gravity_depth_friction --save law.json\n"
      "The figure of the error falling is written to --plot (default error_falls.png). --save writes a\n"
      "law for all gravity levels (terms shared or carried by g^p) to a file that `model predict`\n"
      "applies to a gravity, speed, diameter and mass of one's own: its constants and their\n"
      "covariance, --resamples bootstrap resamples of them (whole drops, within each level), its\n"
      "error by Froude number (held out by gravity level) and the ranges it was fitted on\n"
      "(docs/formats/law.md). --format json prints one document: {model, trials, samples, parameters:\n"
      "[...], held_out_errors: [...], by_froude: [...] (the --per-froude table), and projectiles_held_out:\n"
      "[...] with --leave-out projectile}.\n"
      "--per-froude adds the held-out errors by gravity level and Froude number with the count of cells\n"
      "beyond a target; --weight mg gives the law's sensitivity to the weighting of the trials.");
  add_model_inputs(sub, o->in);
  sub->add_option("--model", o->model, "model: 'base+depth_friction' or a JSON spec file")->capture_default_str();
  sub->add_option("--baseline", o->baseline, "the 'before' model")->capture_default_str();
  sub->add_option("--folds", o->folds, "cross-validation folds (whole trials)")
      ->check(CLI::Range(2, 100))
      ->capture_default_str();
  sub->add_option("--leave-out", o->leave_out,
                  "trials: the folds of --folds, whole trials; projectile: each projectile (diameter and mass) "
                  "predicted by the model fitted on the others")
      ->check(CLI::IsMember({"trials", "projectile"}))
      ->capture_default_str();
  sub->add_option("--plot", o->plot, "write the error-falling figure (PNG) here")->capture_default_str();
  sub->add_flag("--no-plot", o->no_plot, "do not write the figure");
  sub->add_option("--save", o->save, "write the fitted law to this file (JSON; for `model predict`)");
  sub->add_option("--resamples", o->resamples, "bootstrap resamples of the constants saved with --save")
      ->check(CLI::Range(20, 100000))
      ->capture_default_str();
  sub->add_flag("--per-froude", o->per_froude,
                "also the held-out errors by gravity level and Froude number: each cell's signed mean error and "
                "whether it is beyond a target (zstop 10 %, tstop 15 %), which a median over all trials hides");
  sub->add_option("--weight", o->weight,
                  "units of each trial's residuals, trials weighted equally in them: auto (a law for all gravity "
                  "levels: the trial's own RMS force; a law per level: m g), trial-force, or mg (a fast drop's "
                  "residuals then count as much more as its force is larger): the law's sensitivity to the weighting")
      ->check(CLI::IsMember({"auto", "trial-force", "mg"}))
      ->capture_default_str();
  sub->callback([o]() { run_fit(*o); });
}

}  // namespace gravsweep::cli
