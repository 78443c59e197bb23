// What every `gravsweep model` sub-verb shares: its inputs (one or more campaigns read as one, a
// --where filter, the files root of a postgresql:// input), its output format, the reading of the
// campaign and of a model's term list, and the per-axis residual table. One sub-verb a file:
// scheduler/cli/verb_model_<name>.cpp defines setup_model_<name>(CLI::App& model).
#pragma once
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "results/io/table.h"
#include "results/model/model_spec.h"
#include "results/model/residual_axes.h"

namespace gravsweep::cli {

/// The inputs and output format of a `model` sub-verb.
struct ModelInputs {
  std::vector<std::string> inputs;       ///< databases, imported SQLite files or lab folders, read as one
  std::vector<std::string> where;        ///< `gravsweep results` filters, all must hold
  std::string files;                     ///< files root of a postgresql:// input
  std::string format = "table";          ///< table, csv or json
  results::ProcessingChoice processing;  ///< --time-scale, --end-rule (empty: each trial's own)
};

/// Adds the positional inputs, --where, --files and --format to `sub`; returns `sub`.
CLI::App* add_model_inputs(CLI::App* sub, ModelInputs& o);

/// The campaign the inputs name, at least `min_trials` usable trials (UsageError otherwise).
results::Campaign load_model_campaign(const ModelInputs& o, std::size_t min_trials = 6);

/// A model from its term list ('base+depth_friction') or a JSON spec file; UsageError when unknown.
results::ModelSpec model_of(const std::string& text);

/// Residual a_meas - a_model in units of g along each axis (results::residual_axes), as a table
/// (axis, eta^2, split-half r, slope signs, bins), and that table printed.
results::Table residual_axes_table(const std::vector<results::AxisResidual>& axes);
void print_residual_axes(const std::vector<results::AxisResidual>& axes, const std::string& format);

}  // namespace gravsweep::cli
