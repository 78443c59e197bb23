// What a job's runner reports, the one form its outputs take from the runner to the results row.
#pragma once
#include <nlohmann/json.hpp>

namespace gravsweep::queue {

/// A runner's outputs, made once by the runner and carried as they are (moved) into the
/// completion (queue.h, Completion) and from there into the results row.
struct RunOutput {
  nlohmann::json metrics = nlohmann::json::object();  ///< {declared output key: value} (check_outputs)
  nlohmann::json report = nlohmann::json::object();   ///< free-form, kept in attempts.report_json
};

}  // namespace gravsweep::queue
