#include "scheduler/queue/run_output.h"

namespace gravsweep::queue {

void RunOutput::each_output(const OutputRecord::Visit& visit) const {
  if (values.is_object())
    for (const auto& [key, value] : values.items()) visit(key, value);
  if (record) record->each_output(visit);
}

nlohmann::json RunOutput::outputs_json() const {
  nlohmann::json j = nlohmann::json::object();
  each_output([&](const std::string& key, const nlohmann::json& value) { j[key] = value; });
  return j;
}

}  // namespace gravsweep::queue
