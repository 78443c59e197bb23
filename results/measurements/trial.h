// The one trial record's field table: what is known about one impact before its trace is
// processed, whether a laboratory record (trials.csv, docs/formats/measurements.md section 2) or a
// DEM drop (trace.h5 of `gravsweep run` or of a campaign's drop job). The record, Trial, is
// results/processing/trial_record.h. Every name of its fields (CSV header, SQLite column of the
// imported `trials` table, JSON key) comes from the one table trial_fields(); a DEM trace's
// attributes are read into the fields themselves (trace_attributes(), results/io/trace_file.h).
#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "results/processing/trace.h"
#include "results/processing/trace_source.h"
#include "results/processing/trial_record.h"

namespace gravsweep::results {

/// One problem found while reading: file (relative to the campaign), 1-based line and column
/// (0 when not applicable) and what was expected.
struct ImportIssue {
  std::string file;
  int line = 0;
  int column = 0;
  std::string message;
  /// bad_input: the campaign's files are wrong (import refuses them); unmeasurable: a valid DEM
  /// trace whose metrics cannot be found (no contact before the time cap, a rebound).
  enum class Kind { bad_input, unmeasurable } kind = Kind::bad_input;
  [[nodiscard]] std::string to_string() const;
};

/// One field of Trial and its names everywhere. A field is numeric (`number`) or text (`text`).
struct TrialField {
  const char* key;        ///< JSON key, CSV header and SQLite column (one name: units in it)
  const char* unit;       ///< SI unit ("" for text)
  bool csv_required;      ///< required column of trials.csv (docs/formats/measurements.md 2.1)
  double Trial::*number;  ///< nullptr for text fields
  std::string Trial::*text;
};
/// The table, in the order of trials.csv's required columns first.
const std::vector<TrialField>& trial_fields();

/// Read-only older names of trial fields: {older name, the field's key}. A trials.csv header, an
/// imported database's column or a JSON key of that name is read as the field; nothing is written
/// under it. `impact_velocity_m_s` is the laboratory format's name of the impact speed
/// (docs/formats/measurements.md) and the name gravsweep wrote before it had one name for it.
const std::vector<std::pair<std::string, std::string>>& trial_field_aliases();
/// The field key `name` stands for: itself, or the key of the field it is an alias of.
std::string trial_field_key(const std::string& name);

/// Empty when `value` lies in the physical range of the numeric trial field `key` (a field
/// without a range accepts any finite value), else what was expected, e.g. "a mass 0 < m <= 1000 kg".
/// The ranges are wide (asteroid to centrifuge gravity, grains of sand to boulders): they catch a
/// wrong unit or a corrupt number, never a real experiment.
std::string out_of_physical_range(const std::string& key, double value);

void to_json(nlohmann::json& j, const Trial& t);
void from_json(const nlohmann::json& j, Trial& t);

/// The processing options of a trial: the one place MetricOptions are made from trial facts. With
/// the froude time scale the cut-off and the hold are the trial's values at the paper's drop
/// (kPaperGravity_m_s2, kPaperProjectileDiameter_m) scaled to the trial's sqrt(g / D), so a 1 g
/// drop of a 10 cm projectile is processed as the paper does. Throws std::invalid_argument for an
/// unknown time scale or end rule.
MetricOptions metric_options(const Trial& t);
/// The trial's time scale: its own, or by its source when it names none: froude for a DEM drop
/// (no sensor; its trace runs in the drop's own time to its rest), fixed for a lab record. A lab
/// record carries a sensor's bias, read from its free fall and its rest, and is sized in seconds:
/// tens of ms of free fall and of rest are shorter than the edges of a drop-scaled filter below 1 g
/// (its contact step rings into the free fall; on synthetic records at 0.1 m/s2 with 30 ms of
/// rest the 90th-percentile zstop error rose from under 5 % to 36 %). `--time-scale froude` or
/// the column asks for it.
TimeScale time_scale_for(const Trial& t);
/// sqrt((g / D) / (9.81 m/s2 / 0.1 m)): the factor by which the froude time scale multiplies the
/// paper's frequencies (and divides its times) for this drop; 1 for a D that is not positive.
double froude_time_factor(double gravity_m_s2, double projectile_diameter_m);

/// The one gravity-level rule of every verb: two gravities are one level when they agree to
/// a relative 1e-6 (a level typed as 1.62 and computed as 1.6200000001 are one level).
bool same_gravity_level(double a_m_s2, double b_m_s2);
/// The distinct levels of a list of gravities, sorted descending (the first value of each level).
std::vector<double> gravity_levels_of(const std::vector<double>& g_m_s2);

}  // namespace gravsweep::results
