// Measurement campaigns: trials (results/processing/trial_record.h, their field table
// results/measurements/trial.h) with their traces, processed as
// Sunday et al. 2021 Sect. 2.3 does (results/processing/trace.h) through one entry,
// process_trial(). Readers: lab campaign folders (trials.csv + traces/*.csv, lab_csv.cpp), DEM
// traces (trace.h5 of `gravsweep run` or of a campaign's drop jobs, dem_trace.cpp), and the
// SQLite tables written by store_campaign (campaign.cpp). Bad rows or traces are reported by
// file, line and column and do not stop the other trials.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "results/measurements/trial.h"
#include "results/processing/trace.h"

namespace gravsweep::db {
class Database;
}

namespace gravsweep::results {

struct TraceData;

struct Campaign {
  std::string directory;
  std::vector<MeasuredTrial> trials;                         ///< the trials read and processed successfully
  std::vector<ImportIssue> issues;                           ///< one per rejected row, trace or unmeasurable trial
  [[nodiscard]] std::vector<double> gravity_levels() const;  ///< same_gravity_level(), descending
  /// The indices of the trials of each level, in the order of gravity_levels().
  [[nodiscard]] std::vector<std::vector<std::size_t>> trials_by_level() const;
};

/// The one processing entry: options from the trial (metric_options; kept as t.options), bias
/// removal from the source, the fit window, a clipped record (mark_clipping). Throws
/// std::invalid_argument with the reason.
void process_trial(MeasuredTrial& t);

/// Processing a verb imposes on every trial it reads (Trial::time_scale, Trial::end_rule; empty:
/// each trial's own), for a sensitivity of a result to the processing.
struct ProcessingChoice {
  std::string time_scale, end_rule;
  [[nodiscard]] bool any() const { return !time_scale.empty() || !end_rule.empty(); }
};
/// Gives the trial the choice (the fields it names).
void apply_choice(Trial& t, const ProcessingChoice& p);
/// Gives every trial the choice and processes it again (from its raw trace); a trial that cannot
/// be processed so moves to the issues as unmeasurable, with the reason.
void reprocess_campaign(Campaign& c, const ProcessingChoice& p);

/// A saturated accelerometer's flat top: the longest run of consecutive raw samples at the
/// record's largest value (within kClipRelTolerance of it, as a sensor at full scale writes one
/// value), [begin, end), when it is at least kClipMinSamples long and above rest. A real peak with
/// sensor noise and grain-scale fluctuations never repeats its largest value.
struct ClippedRun {
  double level_m_s2 = 0;
  std::size_t begin = 0, end = 0;
};
inline constexpr std::size_t kClipMinSamples = 3;
inline constexpr double kClipRelTolerance = 1e-9;
std::optional<ClippedRun> clipped_run(const std::vector<double>& accel_up_m_s2);

/// Marks a processed lab trial whose record is clipped (Trial::clipped_at_m_s2, clipped_samples,
/// clip_depth_error_m; all 0 otherwise) and moves its fit window past the flat top and
/// `edge_samples` more (none left: an empty window). What stays usable (clip_exclusion): tstop
/// always (its start and end are threshold crossings far below the clip); zstop when the depth
/// integrated across the clip is off by at most kClipDepthTolerance of it (bring_to_rest takes the
/// missing impulse off from the contact on, so the error is at most that speed over the time
/// from contact to the clip's end; a record with its own depth is not integrated); apeak never.
void mark_clipping(MeasuredTrial& t, std::size_t edge_samples);
inline constexpr double kClipDepthTolerance = 0.02;
enum class ClippedMetric { apeak, zstop, tstop };
/// Why the metric of a clipped trial is left out of fits and error summaries; "" when it is used.
std::string clip_exclusion(const MeasuredTrial& t, ClippedMetric metric);
/// One line for a clipped trial (import table, report): the level, what is kept; "" otherwise.
std::string clip_summary(const MeasuredTrial& t);

/// Reads and processes a lab campaign folder. Throws std::runtime_error only when trials.csv itself
/// cannot be read or lacks a required column; row- and trace-level problems become issues.
/// `cutoff_hz` is the filter of trials whose row does not set filter_cutoff_hz.
Campaign load_campaign(const std::string& directory, double cutoff_hz = 500.0, const ProcessingChoice& processing = {});

/// A DEM trace (trace.h5) and what names it.
struct DemTraceRef {
  std::string trial_id;
  std::string job_id;  ///< empty outside a campaign database
  std::filesystem::path path;
};
/// Readies a DEM trace record to be processed as the trial it is (its facts are already the
/// trial's, read where they live): names it (ref), sets its processing settings from its
/// scenario's /output and its impact speed (the trace's own at first contact, from its metrics
/// text, else the release speed). The drop job and every reader of a trace measure it so.
void prepare_dem_trial(TraceData& trace, const DemTraceRef& ref);
/// Reads one trace.h5 into a trial (prepare_dem_trial), not yet processed: the record's trial
/// part, by move (its columns are not copied; the engine's further columns are left behind).
MeasuredTrial read_dem_trial(const DemTraceRef& ref);
/// Reads and processes DEM traces; unreadable or unmeasurable ones (no contact before the time
/// cap, a rebound) become issues naming the trace, the job and the reason.
Campaign load_dem_campaign(const std::string& label, const std::vector<DemTraceRef>& refs,
                           const ProcessingChoice& processing = {});

/// Stores the campaign in the database (tables trials and trial_metrics; samples stored once per
/// content: traces + trace_samples for the raw record, processed_traces + processed_samples for
/// the processed arrays, each named by its SHA-256, which trials share; the view trial_samples
/// gives every trial's rows; campaign_db.cpp), replacing earlier rows of the same trial ids and
/// removing samples no trial names. A database of the per-trial layout before (a table
/// trial_samples) is moved to the shared one first. Returns the number of trials stored.
int store_campaign(db::Database& db, const Campaign& campaign);

/// Turns DEM runs (`gravsweep run` folders holding trace.h5, and campaign files folders holding
/// traces/<job>.a<n>.h5, searched recursively under each root) into a campaign folder: copies
/// (or hard-links) each trace to <out_dir>/traces/<trial>.h5 and writes <out_dir>/trials.csv, so
/// the model verbs treat simulations exactly as laboratory records. Unreadable traces become
/// issues. Returns the number of trials written.
int write_campaign_from_runs(const std::vector<std::string>& roots, const std::string& out_dir,
                             std::vector<ImportIssue>& issues);

/// Reads a campaign back from a database written by store_campaign (no reprocessing), of either
/// layout (shared samples, or the per-trial table of an older gravsweep).
Campaign load_campaign_db(db::Database& db);

/// A campaign folder (read and processed) or an SQLite file (as imported).
Campaign load_campaign_any(const std::string& path, double cutoff_hz = 500.0);

}  // namespace gravsweep::results
