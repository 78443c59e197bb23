// What a job's runner reports, the one form its outputs take from the runner to the results row.
#pragma once
#include <nlohmann/json.hpp>

#include <functional>
#include <memory>
#include <string>

namespace gravsweep::queue {

/// Outputs a runner holds in typed records (a drop's metrics and DEM figures), read through the
/// records' field tables where a value is needed: the results row binds each value from the
/// record itself, and JSON text is written only where text is stored (outputs_json), so no copy of
/// the values is made on the way from the runner to the row.
class OutputRecord {
 public:
  /// visit(key, value): one output, its value a JSON scalar (null: none).
  using Visit = std::function<void(const std::string& key, const nlohmann::json& value)>;
  virtual ~OutputRecord() = default;
  /// Calls `visit` for every output the record holds, in its tables' order.
  virtual void each_output(const Visit& visit) const = 0;
};

/// A runner's outputs, made once by the runner and carried as they are (moved) into the
/// completion (queue.h, Completion) and from there into the results row.
struct RunOutput {
  /// Outputs a runner has in no typed record, written as values: {declared output key: value}
  /// (the noop kind, a test's kind). null: none.
  nlohmann::json values = nlohmann::json::object();
  /// Outputs held in a typed record (null: none); its keys are others than those of `values`.
  std::shared_ptr<const OutputRecord> record;
  nlohmann::json report = nlohmann::json::object();  ///< free-form, kept in attempts.report_json

  /// Calls `visit` for every output: those of `values` (an object; see check_outputs), then the
  /// record's.
  void each_output(const OutputRecord::Visit& visit) const;
  /// Every output as one JSON object {key: value}: the text form, for where outputs are stored as
  /// text (a trace file's `metrics` attribute, `run`'s metrics.json).
  [[nodiscard]] nlohmann::json outputs_json() const;
};

}  // namespace gravsweep::queue
