// The one trial record (Trial: what is known about one impact before its trace is processed, a
// laboratory record or a DEM drop) and a trial with its traces (MeasuredTrial). Their field table,
// readers and the one processing entry, process_trial, are results/measurements (trial.h,
// campaign.h); the records are defined here, below results/io, so that a DEM drop's trace record
// (results/io/trace_file.h, TraceData) is the trial it is measured as, not a copy made into one.
#pragma once
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "results/processing/trace.h"
#include "results/processing/trace_source.h"

namespace gravsweep::results {

/// The one trial record. Every name of its fields (CSV header, SQLite column, JSON key) comes from
/// trial_fields() (results/measurements/trial.h); a DEM trace's attributes are read into its
/// fields where they live (trace_attributes(), results/io/trace_file.h).
struct Trial {
  std::string trial_id;
  TraceSource source = TraceSource::lab;
  std::string trace_file;  ///< relative to the campaign folder (lab) or absolute (dem)
  double gravity_m_s2 = 0;
  double impact_speed_m_s = 0;  ///< downward speed at first contact
  double fill_height_m = 0;     ///< bed depth: the floor below the surface (dem: measured surface height)
  double projectile_mass_kg = 0;
  double projectile_diameter_m = 0;
  double grain_diameter_m = 0;
  double bulk_density_kg_m3 = 0;
  double sample_rate_hz = 0;  ///< declared; checked against the timestamps
  double drop_height_m = 0;   ///< 0 when absent; v = sqrt(2 g h) when the speed is empty
  // Processing settings (Sunday et al. 2021 Sect. 2.3): the scenario's /output settings for a DEM
  // drop, the import's --cutoff and the paper's values for a lab record.
  double filter_cutoff_hz = 500.0;
  double end_threshold_g = 0.1;
  double end_speed_fraction = 0.1;
  /// The time scale of the cut-off and the hold (TimeScale: "froude" or "fixed"; empty: by the
  /// source, time_scale_for): with froude, filter_cutoff_hz is the cut-off of the paper's drop (1 g,
  /// D = 10 cm) and the one applied is scaled by sqrt(g / D) (metric_options).
  std::string time_scale;
  /// The rule that ends the collision (EndRule: "speed", the default, "paper" or "depth").
  std::string end_rule = "speed";
  // A saturated accelerometer, found by process_trial (lab records; 0 when not clipped): the level
  // of the flat top at the record's largest value, the samples on it, and how far the depth
  // integrated across it may be off (0 for a record with its own depth). Such a trial's apeak is a
  // lower bound (clip_exclusion()).
  double clipped_at_m_s2 = 0;
  double clipped_samples = 0;
  double clip_depth_error_m = 0;
  // Provenance.
  std::string job_id;                             ///< campaign drop job (dem), empty otherwise
  std::string code_version;                       ///< gravsweep version that wrote a DEM trace
  std::map<std::string, std::string> attributes;  ///< other trials.csv columns, kept as they are
};

/// A trial with its raw and processed trace, and the options it was processed with. A DEM drop's
/// trace record (TraceData) is one: processing reads and writes it in place.
struct MeasuredTrial {
  Trial info;
  Trace raw;
  ProcessedTrace processed;
  /// What `processed` was processed with: set once, by process_trial (metric_options(info), or the
  /// paper's fixed scales when a short lab record falls back to them), or read back with an
  /// imported campaign (load_campaign_db). Anything processed beside the trial takes these (the
  /// model's record that predicts its apeak as measured, the re-integrated line of Fig. 2), so it
  /// is processed alike without working out again what was applied.
  MetricOptions options;
  /// Samples used by trace-level fits: inside the collision, clear of the filter's transient.
  std::size_t fit_begin = 0, fit_end = 0;  ///< [begin, end)
  /// A CSV trace only: the file line of each sample and the 1-based column of accel_m_s2, so
  /// that a processing error about a sample (TraceError) names its line. Empty otherwise.
  std::vector<int> sample_lines;
  int accel_column = 0;
};

}  // namespace gravsweep::results
