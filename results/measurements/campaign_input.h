// What the model verbs and `measurements import` read, once it is trials: an input's kind, its
// trials (a Campaign), what `--where` left out and a note. This library reads the inputs it owns,
// a lab campaign folder (trials.csv + traces/) and an SQLite file from `measurements import`
// (table trials); a campaign database of the job queue (tables jobs, results) is read by the
// scheduler into the same record (scheduler/cli/campaign_input.h). `--where` (db/where.h) sees a
// trial as its fields (trial.h, the read-only aliases too), its attributes and its numeric metrics.
#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

#include "results/measurements/campaign.h"

namespace gravsweep::results {

struct CampaignInput {
  Campaign campaign;
  std::string kind;              ///< "campaign database (submit/work)", "imported SQLite file", "lab campaign folder"
  std::size_t filtered_out = 0;  ///< trials left out by --where
  std::string note;              ///< e.g. drop jobs not finished
};

inline constexpr const char* kLabFolderKind = "lab campaign folder";
inline constexpr const char* kImportedFileKind = "imported SQLite file";

/// Reads a lab campaign folder or an imported SQLite file, refuses unphysical numbers
/// (refuse_unphysical) and applies --where (filter_trials). Throws std::runtime_error naming
/// `path` and what was expected (no such path, an empty file, a file of neither kind, a bad --where).
/// `processing`: the choice given to every trial (ProcessingChoice; an imported file's trials are
/// processed again from their stored raw traces).
CampaignInput load_trial_input(const std::string& path, const std::vector<std::string>& where, double cutoff_hz = 500.0,
                               const ProcessingChoice& processing = {});

/// A trial as the row --where sees: its fields (with the read-only aliases), its attributes, its
/// numeric metrics (not the processing note: a trial may have a "note" attribute) and its impact
/// Froude number `impact_froude` = vc / sqrt(g D).
nlohmann::json where_row(const MeasuredTrial& t);

/// Keeps the trials whose where_row matches every expression and counts the others in
/// `in.filtered_out`. A malformed expression throws std::runtime_error naming `path`, even on no trials.
void filter_trials(const std::string& path, CampaignInput& in, const std::vector<std::string>& where);

/// Throws std::runtime_error when a trial's number lies outside its physical range (an imported
/// file written before `measurements import` checked them, or edited since): a fit on it would be
/// garbage or NaN. The message names `path`, the trial, the field, the value and the range.
void refuse_unphysical(const std::string& path, const CampaignInput& in);

/// Several inputs (e.g. one exported dataset per gravity level), each with its path, as one: the
/// trials and issues concatenated, the kinds and notes listed. Throws std::runtime_error when a
/// trial id appears in two inputs.
CampaignInput concatenate_inputs(std::vector<std::pair<std::string, CampaignInput>> inputs);

/// Prints to stderr what was read ("reading <path>: <kind>, n trials") and every trial left out
/// with its reason (unmeasurable or bad input).
void describe_input(const std::string& path, const CampaignInput& in);

}  // namespace gravsweep::results
