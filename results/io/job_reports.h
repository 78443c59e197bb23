// What a bed job and a drop job report beside the paper's metrics, as typed records with one
// field table each (record_fields.h): a drop's DEM figures (depths below the bed's mean surface,
// rest, steps, the run's setup) and a bed's preparation report. The job's JSON, its results
// columns and the bed file's `report` attribute are made from these tables; readers (export,
// `run`'s summary) read the typed records back.
#pragma once
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

#include "results/io/record_fields.h"

namespace gravsweep::results {

/// How often a job's checkpoint served it: filled by the job's checkpointer.
struct CheckpointCounts {
  long long resumes = 0;               ///< attempts that continued from a checkpoint
  std::optional<double> resumed_at_s;  ///< simulated time the last resume started from
  long long written = 0;               ///< checkpoints this attempt wrote
};

/// The DEM side of a drop (engine frame facts in the paper's frame: depth z positive down from the
/// bed's mean surface). Its keys are disjoint from the paper's metrics (metric_fields()): the
/// processed record's `final_depth_m` is measured from the collision start, this record's
/// `final_depth_below_surface_m` from the surface.
struct DemFigures {
  double max_depth_m = 0;                    ///< deepest point of the projectile's bottom below the surface
  double final_depth_below_surface_m = 0;    ///< its depth at the last sample
  std::optional<double> first_contact_s;     ///< first contact with a grain, since release
  bool stopped = false;                      ///< Sect. 2.2's stop criterion met (false: time cap)
  long long grains_spilled_over_rim = 0;     ///< low-gravity ejecta removed (engine/scenario/impact.h)
  std::optional<double> rest_time_s;         ///< start of the hold that met the stop criterion
  std::optional<double> duration_to_rest_s;  ///< rest_time_s less the paper's collision start
  double simulated_time_s = 0;
  long long steps = 0;
  double dt_s = 0;
  double sample_rate_hz = 0;
  double gravity_m_s2 = 0;
  long long grains = 0;
  double surface_height_m = 0;  ///< engine z of the bed's mean surface (floor at 0)
  double release_speed_m_s = 0;
  double release_height_above_surface_m = 0;
  double first_touch_height_above_surface_m = 0;
  double lateral_offset_m = 0;  ///< impact point's distance from the container's axis
  long long threads = 0;
  double wall_time_s = 0;
  long long checkpoint_resumes = 0;
  std::optional<double> resumed_at_s;
  long long checkpoints_written = 0;
};
const std::vector<RecordField<DemFigures>>& dem_figure_fields();

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

/// The checkpoint's counts into a record of either kind.
template <class R>
void set_checkpoint_counts(R& r, const CheckpointCounts& c) {
  r.checkpoint_resumes = c.resumes;
  r.resumed_at_s = c.resumed_at_s;
  r.checkpoints_written = c.written;
}

nlohmann::json to_json(const DemFigures& d);
nlohmann::json to_json(const BedSummary& b);
/// A bed's report from its JSON (bed.h5's `report`, a bed job's results); `where` names the
/// source in an error (a key of the wrong type).
BedSummary bed_summary_of_json(const nlohmann::json& j, const std::string& where);

}  // namespace gravsweep::results
