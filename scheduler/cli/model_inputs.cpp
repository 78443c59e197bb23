#include "scheduler/cli/model_inputs.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <stdexcept>

#include "results/model/model_spec.h"
#include "results/model/residual_axes.h"
#include "results/io/table.h"
#include "scheduler/cli/campaign_input.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/format_option.h"

namespace gravsweep::cli {

namespace {

/// Filter passband of the traces every `model` sub-verb reads (Butterworth, Hz).
constexpr double kModelFilterHz = 500.0;

constexpr const char* kInputsHelp =
    "campaign database from `submit`/`work` (an SQLite file, or postgresql://user@host:port/dbname with --files; "
    "every finished drop is a trial), SQLite file from `measurements import`, or lab campaign folder; several are "
    "read as one campaign (e.g. one exported dataset per gravity level)";
constexpr const char* kWhereHelp =
    "filter the trials, grammar of `gravsweep results` (e.g. 'gravity_m_s2<1'; a trial of a folder or an imported "
    "file also has impact_froude = vc / sqrt(g D): 'impact_froude<=1'); repeatable";

}  // namespace

CLI::App* add_model_inputs(CLI::App* sub, ModelInputs& o) {
  sub->add_option("inputs", o.inputs, kInputsHelp)->required();
  sub->add_option("--where", o.where, kWhereHelp);
  add_input_files_option(sub, o.files);
  add_format_option(sub, o.format);
  add_processing_options(sub, o.processing);
  return sub;
}

results::Campaign load_model_campaign(const ModelInputs& o, std::size_t min_trials) {
  auto in = load_campaign_inputs(o.inputs, o.where, kModelFilterHz, o.files, o.processing);
  if (in.campaign.trials.size() < min_trials)
    throw UsageError(fmt::format("{}: only {} usable trials; at least {} are needed", fmt::join(o.inputs, " + "),
                                 in.campaign.trials.size(), min_trials));
  return std::move(in.campaign);
}

results::ModelSpec model_of(const std::string& text) {
  try {
    return results::parse_model(text);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

results::Table residual_axes_table(const std::vector<results::AxisResidual>& axes) {
  results::Table t({"axis", "eta2", "split_half_r", "trials_slope_up", "trials_slope_down", "sign_test_p",
                    "mean_residual_over_g_by_bin"});
  for (const auto& a : axes) {
    std::string bins;
    for (std::size_t i = 0; i < a.bin_center.size(); ++i)
      bins += fmt::format("{}{:.3g}:{:+.3f}", i ? " " : "", a.bin_center[i], a.bin_mean_r_over_g[i]);
    const bool trial_level = a.trials_positive + a.trials_negative == 0;
    t.add({a.axis, results::num(a.eta2, 3), results::num(a.split_half_r, 2),
           trial_level ? "-" : std::to_string(a.trials_positive), trial_level ? "-" : std::to_string(a.trials_negative),
           trial_level ? "-" : results::num(a.slope_sign_trials_p, 2), bins});
  }
  return t;
}

void print_residual_axes(const std::vector<results::AxisResidual>& axes, const std::string& format) {
  residual_axes_table(axes).print(format);
}

}  // namespace gravsweep::cli
