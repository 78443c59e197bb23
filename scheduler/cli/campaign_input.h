// What the model verbs (`model rank|fit|residuals|table3`, `report`, `measurements import`) read:
// a campaign database from `submit`/`work` (every finished drop job is a trial, its trace.h5 read
// from the campaign's files folder, `--where` on its results table), read here; an SQLite file from
// `measurements import` or a lab campaign folder (trials.csv + traces/), read by
// results/measurements/campaign_input.h. One record for all: results::CampaignInput.
#pragma once
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "results/measurements/campaign_input.h"

namespace gravsweep::cli {

using results::CampaignInput;
using results::describe_input;

/// Reads `path` (a file, a folder, or a `postgresql://` campaign whose traces are under `files`,
/// its files root); throws UsageError for what is not a campaign or a bad --where.
CampaignInput load_campaign_input(const std::string& path, const std::vector<std::string>& where,
                                  double cutoff_hz = 500.0, const std::string& files = {},
                                  const results::ProcessingChoice& processing = {});

/// Reads several inputs (e.g. one exported dataset per gravity level) into one campaign: each is
/// read and described (describe_input) in turn, `--where` applied to each, then
/// results::concatenate_inputs. Throws UsageError when a trial id appears in two inputs.
CampaignInput load_campaign_inputs(const std::vector<std::string>& paths, const std::vector<std::string>& where,
                                   double cutoff_hz = 500.0, const std::string& files = {},
                                   const results::ProcessingChoice& processing = {});

/// Adds --files: the files root of an input given as a `postgresql://` URL (where its traces are).
inline void add_input_files_option(CLI::App* sub, std::string& files) {
  sub->add_option("--files", files,
                  "the files root of a campaign given as postgresql://user@host:port/dbname (its traces are "
                  "read there; default for an SQLite campaign: <db stem>.files/ beside it)");
}

/// Adds --time-scale and --end-rule: the processing every trial read is given (empty: its own).
inline void add_processing_options(CLI::App* sub, results::ProcessingChoice& p) {
  sub->add_option("--time-scale", p.time_scale,
                  "the time scale of the low-pass cut-off and the end's hold for every trial: froude (the drop's "
                  "sqrt(D/g): the paper's 500 Hz and 2 ms at 1 g and D = 10 cm, scaled by sqrt(g/D); the default "
                  "of a DEM drop) or fixed (the paper's hertz and seconds at every gravity; the default of a lab "
                  "record, whose free fall and rest are sized in seconds)")
      ->check(CLI::IsMember({"froude", "fixed"}));
  sub->add_option("--end-rule", p.end_rule,
                  "the end of the collision for every trial: speed (the default: |a| < 0.1 g held, with the speed "
                  "below 0.1 vc), paper (|a| < 0.1 g held, as Sect. 2.3), depth (99 % of the maximum depth)")
      ->check(CLI::IsMember({"speed", "paper", "depth"}));
}

}  // namespace gravsweep::cli
