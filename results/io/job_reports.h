// What a bed job and a drop job report beside the paper's metrics, each with one field table
// (record_fields.h): a drop's DEM figures (depths below the bed's mean surface, rest, steps, the
// run's setup), read by their table's getters from the drop's own record (DropRecord), and a
// bed's preparation report, a typed record of members. The job's JSON, its results columns and the bed file's `report`
// attribute are made from these tables.
#pragma once
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

#include "engine/scenario/impact.h"
#include "results/io/record_fields.h"
#include "results/io/trace_file.h"
#include "results/processing/trace.h"

namespace gravsweep::results {

/// How often a job's checkpoint served it: filled by the job's checkpointer.
struct CheckpointCounts {
  long long resumes = 0;               ///< attempts that continued from a checkpoint
  std::optional<double> resumed_at_s;  ///< simulated time the last resume started from
  long long written = 0;               ///< checkpoints this attempt wrote
};

/// A drop's outputs as its run holds them, in the records where they were made: the trace record
/// (the trial it was measured as: its samples' columns, its facts, dt, the release speed, the stop
/// flag, and the paper's metrics as processing made them in it), the engine's result (its samples
/// taken over by the trace; first contact, rest, steps, grains spilled, first touch) and the few
/// facts of the run kept from the System and the job as they end (the bed's grains, the impact
/// point, threads, wall time, checkpoints). The DEM's figures are read from it by their table
/// (dem_figure_fields()): no record of copies of them is made.
struct DropRecord {
  /// Whether the trace was measured (its processed metrics are the drop's); false: metrics_error
  /// says why not.
  bool measured = false;
  std::string metrics_error;
  /// The paper's metrics, where processing made them in the trace record; null when unmeasured.
  [[nodiscard]] const Metrics* metrics() const { return measured ? &trace.processed.metrics : nullptr; }
  TraceData trace;              ///< the drop's trace, as trace.h5 holds it, and its trial
  DropResult result;            ///< the engine's result, its samples taken by `trace` (left empty)
  long long bed_grains = 0;     ///< grains of the bed it was dropped into
  double lateral_offset_m = 0;  ///< impact point's distance from the container's axis
  long long threads = 0;
  double wall_time_s = 0;
  CheckpointCounts checkpoints;
};

/// The DEM's figures of a drop (engine frame facts in the paper's frame: depth z positive down
/// from the bed's mean surface), each read by a getter from the drop's record: a number, a number
/// that may be absent (JSON null), a count or a flag. The keys are disjoint from the paper's
/// metrics (metric_fields()): the processed `final_depth_m` is measured from the collision start,
/// `final_depth_below_surface_m` from the surface.
const std::vector<RecordField<DropRecord>>& dem_figure_fields();

/// A prepared bed's report (Sect. 2.2: pour, settle, flatten, relax), kept in bed.h5's `report`
/// attribute and in the bed job's results. A number a bed of an older build did not record reads
/// as NaN.
struct BedSummary {
  long long grains_placed = 0;
  long long grains_kept = 0;
  bool settled = false;    ///< criteria met in both phases
  std::string settle_end;  ///< how the pour's settling ended (SettleEnd)
  std::string relax_end;   ///< how the relaxation after flattening ended
  double settle_time_s = kNotRecorded;
  double relax_time_s = kNotRecorded;
  double quench_time_s = kNotRecorded;
  double surface_relax_s = kNotRecorded;
  double rms_speed_m_s = kNotRecorded;          ///< whole bed
  double max_speed_m_s = kNotRecorded;          ///< whole bed
  double max_surface_speed_m_s = kNotRecorded;  ///< grains of the surface layer
  long long surface_grains = 0;
  /// The slowest impact for which the bed counts as at rest (/at_rest); absent: none.
  std::optional<double> at_rest_for_impacts_above_m_s;
  double surface_height_m = kNotRecorded;
  double bulk_density_kg_m3 = kNotRecorded;
  long long steps = 0;
  double dt_s = kNotRecorded;
  long long threads = 0;
  double wall_time_s = kNotRecorded;
  long long checkpoint_resumes = 0;
  std::optional<double> resumed_at_s;
  long long checkpoints_written = 0;
};
const std::vector<RecordField<BedSummary>>& bed_summary_fields();

/// The checkpoint's counts into a bed's report.
inline void set_checkpoint_counts(BedSummary& r, const CheckpointCounts& c) {
  r.checkpoint_resumes = c.resumes;
  r.resumed_at_s = c.resumed_at_s;
  r.checkpoints_written = c.written;
}

nlohmann::json to_json(const BedSummary& b);
/// A bed's report from its JSON (bed.h5's `report`, a bed job's results); `where` names the
/// source in an error (a key of the wrong type).
BedSummary bed_summary_of_json(const nlohmann::json& j, const std::string& where);

}  // namespace gravsweep::results
