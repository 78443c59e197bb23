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
                                  double cutoff_hz = 500.0, const std::string& files = {});

/// Reads several inputs (e.g. one exported dataset per gravity level) into one campaign: each is
/// read and described (describe_input) in turn, `--where` applied to each, then
/// results::concatenate_inputs. Throws UsageError when a trial id appears in two inputs.
CampaignInput load_campaign_inputs(const std::vector<std::string>& paths, const std::vector<std::string>& where,
                                   double cutoff_hz = 500.0, const std::string& files = {});

/// Adds --files: the files root of an input given as a `postgresql://` URL (where its traces are).
inline void add_input_files_option(CLI::App* sub, std::string& files) {
  sub->add_option("--files", files,
                  "the files root of a campaign given as postgresql://user@host:port/dbname (its traces are "
                  "read there; default for an SQLite campaign: <db stem>.files/ beside it)");
}

}  // namespace gravsweep::cli
