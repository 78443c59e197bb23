// Laboratory (or synthetic) measurement campaigns on disk (shared/formats/measurements.md):
// <dir>/trials.csv plus one accelerometer record per trial, processed as Sunday et al. 2021
// Sect. 2.3 does (results/processing/trace.h). Bad rows or traces are reported by file, line and
// column and do not stop the other trials.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "results/processing/trace.h"

namespace gravsweep::db {
class Database;
}

namespace gravsweep::results {

struct TrialInfo {
  std::string trial_id;
  std::string trace_file;
  double gravity_m_s2 = 0;
  double impact_velocity_m_s = 0;
  double fill_height_m = 0;
  double projectile_mass_kg = 0;
  double projectile_diameter_m = 0;
  double grain_diameter_m = 0;
  double bulk_density_kg_m3 = 0;
  double sample_rate_hz = 0;
  double drop_height_m = 0;  ///< 0 when absent; v = sqrt(2 g h) is used when the speed is empty
  std::map<std::string, std::string> attributes;  ///< other columns, kept as they are
};

struct Trial {
  TrialInfo info;
  Trace raw;
  ProcessedTrace processed;
  /// Samples used by trace-level fits: inside the collision, clear of the filter's transient.
  std::size_t fit_begin = 0, fit_end = 0;  ///< [begin, end)
};

/// One problem found while reading: file (relative to the campaign), 1-based line and column
/// (0 when not applicable) and what was expected.
struct ImportIssue {
  std::string file;
  int line = 0;
  int column = 0;
  std::string message;
  [[nodiscard]] std::string to_string() const;
};

struct Campaign {
  std::string directory;
  std::vector<Trial> trials;        ///< the trials read and processed successfully
  std::vector<ImportIssue> issues;  ///< one per rejected row or trace
  [[nodiscard]] std::vector<double> gravity_levels() const;  ///< sorted, descending
};

/// Reads and processes a campaign folder. Throws std::runtime_error only when trials.csv itself
/// cannot be read or lacks a required column; row- and trace-level problems become issues.
Campaign load_campaign(const std::string& directory, double cutoff_hz = 500.0);

/// Stores the campaign in the database (tables trials, trial_samples, trial_metrics, created when
/// missing), replacing earlier rows of the same trial ids. Returns the number of trials stored.
int store_campaign(db::Database& db, const Campaign& campaign);

/// Turns DEM runs (`gravsweep run` folders holding trace.h5, searched recursively under each root)
/// into a campaign folder: writes <out_dir>/trials.csv pointing at the traces, so the model verbs
/// treat simulations exactly as laboratory records. Unreadable traces become issues. Returns the
/// number of trials written.
int write_campaign_from_runs(const std::vector<std::string>& roots, const std::string& out_dir,
                             std::vector<ImportIssue>& issues);

/// Reads a campaign back from a database written by store_campaign (no reprocessing).
Campaign load_campaign_db(db::Database& db);

/// A campaign folder (read and processed) or an SQLite file (as imported).
Campaign load_campaign_any(const std::string& path, double cutoff_hz = 500.0);

}  // namespace gravsweep::results
