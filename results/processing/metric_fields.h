// The one table of the paper's metrics (Metrics, trace.h): every representation of a processed
// collision (a drop job's results columns and the values bound to them, its trace's metrics text,
// the `trial_metrics` table of an imported campaign, a --where row, the report's figure records)
// is made from metric_fields(); nothing else lists them.
#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "results/processing/trace.h"

namespace gravsweep::results {

/// One field of Metrics and its names everywhere. Exactly one of `number`, `flag`, `text` is set.
struct MetricField {
  const char* key;   ///< JSON key, SQL column, CSV header (one name: units in it)
  const char* unit;  ///< SI unit ("1" for a flag, "" for text)
  /// One of Sect. 2.3's headline figures (vc, apeak, zstop, tstop and the rebound flag): the
  /// columns a summary table shows by default.
  bool headline;
  double Metrics::*number;
  bool Metrics::*flag;
  std::string Metrics::*text;
  [[nodiscard]] const char* sql_type() const { return number ? "REAL" : flag ? "INTEGER" : "TEXT"; }
};

/// The table, headline figures first.
const std::vector<MetricField>& metric_fields();

/// Field f of m as a JSON value (the flag as a JSON boolean, the note as a string).
nlohmann::json metric_json(const Metrics& m, const MetricField& f);
/// Every field, by metric_json.
void to_json(nlohmann::json& j, const Metrics& m);
/// The keys of the headline figures, in the table's order.
std::vector<std::string> headline_metric_keys();

}  // namespace gravsweep::results
