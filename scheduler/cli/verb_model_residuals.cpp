// `gravsweep model residuals`: where a model fails, per trial (model - measured zstop, tstop,
// apeak, the trace's RMS) and per sample along each axis (results::residual_axes).
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "results/model/fit.h"
#include "results/model/predict.h"
#include "results/model/residual_axes.h"
#include "results/io/table.h"
#include "scheduler/cli/model_inputs.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

using results::num;

struct ResidualsOptions {
  ModelInputs in;
  std::string model = "base";
};

/// Per trial: the model fitted on all trials against the measurement.
results::Table trial_residuals(const results::FittedModel& fm, const results::Campaign& c) {
  results::Table t({"trial_id", "gravity_m_s2", "vc_m_s", "fill_height_m", "trace_rms_m_s2", "dzstop_mm", "dtstop_ms",
                    "dapeak_m_s2"});
  // apeak as measured: the model's record filtered like the trial, with the other trials'
  // fluctuations about the model at its level (results/model/predict.h).
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
  return t;
}

void run_residuals(const ResidualsOptions& o) {
  const auto c = load_model_campaign(o.in);
  const auto fm = results::fit_model(model_of(o.model), c);
  const bool table = o.in.format == "table";
  if (table) fmt::print("Per trial ({} fitted on all trials; model - measured):\n", fm.spec.name());
  trial_residuals(fm, c).print(o.in.format);
  if (table) fmt::print("\nPer sample, residual a_meas - a_model in units of g, by axis:\n");
  print_residual_axes(results::residual_axes(fm, c), o.in.format);
}

}  // namespace

void setup_model_residuals(CLI::App& model) {
  auto o = std::make_shared<ResidualsOptions>();
  auto* sub = model.add_subcommand(
      "residuals",
      "Where a model fails: fit it on all trials, then print per trial the residuals of the\n"
      "metrics (model - measured zstop, tstop, apeak; RMS of a_meas - a_model over the trace)\n"
      "with gravity, impact speed and fill height, and per sample the mean residual (in g) in\n"
      "quantile bins of depth, speed, time since contact, gravity, impact speed and fill height,\n"
      "with eta^2 (share of residual variance the binning explains) and a sign test over trials\n"
      "of the within-trial slope.\n\n"
      "Example:\n  gravsweep model residuals ../shared/data/measurements/depth-friction-dev --model base");
  add_model_inputs(sub, o->in);
  sub->add_option("--model", o->model, "model: 'base' or a JSON spec file")->capture_default_str();
  sub->callback([o]() { run_residuals(*o); });
}

}  // namespace gravsweep::cli
