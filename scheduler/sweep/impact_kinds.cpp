#include "scheduler/sweep/impact_kinds.h"

#include "results/processing/metric_fields.h"

namespace gravsweep::sweep {

queue::JobKind bed_kind() {
  static const queue::JobKind kind = queue::register_kind({"bed", "beds", ".h5", false, true, {}});
  return kind;
}

namespace {

/// Why a drop's trace could not be measured: the one output beside the two tables.
constexpr const char* kMetricsErrorKey = "metrics_error";

/// What a drop's runner reports (DropOutputs::each_output walks the same tables).
std::vector<queue::OutputField> drop_outputs() {
  std::vector<queue::OutputField> outputs;
  queue::append_outputs(outputs, results::metric_fields());
  queue::append_outputs(outputs, results::dem_figure_fields());
  outputs.push_back({kMetricsErrorKey, "", "TEXT"});
  return outputs;
}

}  // namespace

queue::JobKind drop_kind() {
  static const queue::JobKind kind = queue::register_kind({"drop", "traces", ".h5", true, false, drop_outputs()});
  return kind;
}

void DropOutputs::each_output(const Visit& visit) const {
  const results::Metrics* m = metrics();
  for (const auto& f : results::metric_fields()) {
    if (m)
      visit(f.key, results::metric_json(*m, f));
    else if (!f.text)
      visit(f.key, nullptr);  // unmeasured; the note is left out (NULL)
  }
  if (!m) visit(kMetricsErrorKey, metrics_error);
  for (const auto& f : results::dem_figure_fields()) visit(f.key, results::field_json<results::DropRecord>(*this, f));
}

namespace {
/// Registered when the program starts (before any campaign is opened), in this order, so that a
/// worker that only claims jobs knows both names and the files root knows both folders.
[[maybe_unused]] const bool kRegistered = (bed_kind(), drop_kind(), true);
}  // namespace

}  // namespace gravsweep::sweep
