#include "scheduler/sweep/impact_kinds.h"

#include "results/io/job_reports.h"
#include "results/processing/metric_fields.h"

namespace gravsweep::sweep {

queue::JobKind bed_kind() {
  static const queue::JobKind kind = queue::register_kind({"bed", "beds", ".h5", false, true, {}});
  return kind;
}

namespace {

/// What a drop's runner reports: its metrics JSON is written from the same tables.
std::vector<queue::OutputField> drop_outputs() {
  std::vector<queue::OutputField> outputs;
  queue::append_outputs(outputs, results::metric_fields());
  queue::append_outputs(outputs, results::dem_figure_fields());
  outputs.push_back({"metrics_error", "", "TEXT"});
  return outputs;
}

}  // namespace

queue::JobKind drop_kind() {
  static const queue::JobKind kind = queue::register_kind({"drop", "traces", ".h5", true, false, drop_outputs()});
  return kind;
}

namespace {
/// Registered when the program starts (before any campaign is opened), in this order, so that a
/// worker that only claims jobs knows both names and the files root knows both folders.
[[maybe_unused]] const bool kRegistered = (bed_kind(), drop_kind(), true);
}  // namespace

}  // namespace gravsweep::sweep
