// The field tables of a job's reports (see job_reports.h).
#include "results/io/job_reports.h"

#include <algorithm>

namespace gravsweep::results {

namespace {

/// The depth below the bed's mean surface at the deepest and at the last sample (0: no sample).
double max_depth_m(const DropRecord& d) {
  const auto& z = d.trace.raw.depth_m;
  return z.empty() ? 0.0 : *std::max_element(z.begin(), z.end());
}
double final_depth_m(const DropRecord& d) { return d.trace.raw.depth_m.empty() ? 0.0 : d.trace.raw.depth_m.back(); }

/// Sect. 2.2's stop criterion (speed < stop.speed_m_s after contact) met: how long after the
/// paper's collision start (a DEM-side duration next to tstop); none without both.
std::optional<double> duration_to_rest_s(const DropRecord& d) {
  if (!d.result.rest_s || !d.metrics()) return std::nullopt;
  return *d.result.rest_s - d.metrics()->t_start_s;
}

}  // namespace

// Each figure is read where the drop holds it: the trace record (its columns, dt, release speed,
// stop flag, and the trial facts in it: gravity, sample rate, the surface as the fill height), the
// engine's result (first contact, rest, steps, spilled grains, release and first-touch heights),
// the metrics, or the run's own facts.
const std::vector<RecordField<DropRecord>>& dem_figure_fields() {
  using D = DropRecord;
  using Maybe = std::optional<double>;
  static const std::vector<RecordField<D>> fields = {
      {.key = "max_depth_m", .unit = "m", .number = max_depth_m},
      {.key = "final_depth_below_surface_m", .unit = "m", .number = final_depth_m},
      {.key = "first_contact_s", .unit = "s", .maybe = [](const D& d) -> Maybe { return d.result.first_contact_s; }},
      {.key = "stopped", .unit = "1", .flag = [](const D& d) { return d.trace.stopped; }},
      {.key = "grains_spilled_over_rim",
       .unit = "1",
       .count = [](const D& d) { return static_cast<long long>(d.result.grains_spilled); }},
      {.key = "rest_time_s", .unit = "s", .maybe = [](const D& d) -> Maybe { return d.result.rest_s; }},
      {.key = "duration_to_rest_s", .unit = "s", .maybe = duration_to_rest_s},
      {.key = "simulated_time_s",
       .unit = "s",
       .number = [](const D& d) { return d.trace.raw.t_s.empty() ? 0.0 : d.trace.raw.t_s.back(); }},
      {.key = "steps", .unit = "1", .count = [](const D& d) { return d.result.steps; }},
      {.key = "dt_s", .unit = "s", .number = [](const D& d) { return d.trace.dt_s; }},
      {.key = "sample_rate_hz", .unit = "Hz", .number = [](const D& d) { return d.trace.info.sample_rate_hz; }},
      {.key = "gravity_m_s2", .unit = "m/s2", .number = [](const D& d) { return d.trace.info.gravity_m_s2; }},
      {.key = "grains", .unit = "1", .count = [](const D& d) { return d.bed_grains; }},
      {.key = "surface_height_m", .unit = "m", .number = [](const D& d) { return d.trace.info.fill_height_m; }},
      {.key = "release_speed_m_s", .unit = "m/s", .number = [](const D& d) { return d.trace.release_speed_m_s; }},
      {.key = "release_height_above_surface_m",
       .unit = "m",
       .number = [](const D& d) { return d.trace.release_height_m - d.trace.info.fill_height_m; }},
      {.key = "first_touch_height_above_surface_m",
       .unit = "m",
       .number = [](const D& d) { return d.result.first_touch_height_m - d.trace.info.fill_height_m; }},
      {.key = "lateral_offset_m", .unit = "m", .number = [](const D& d) { return d.lateral_offset_m; }},
      {.key = "threads", .unit = "1", .count = [](const D& d) { return d.threads; }},
      {.key = "wall_time_s", .unit = "s", .number = [](const D& d) { return d.wall_time_s; }},
      {.key = "checkpoint_resumes", .unit = "1", .count = [](const D& d) { return d.checkpoints.resumes; }},
      {.key = "resumed_at_s", .unit = "s", .maybe = [](const D& d) -> Maybe { return d.checkpoints.resumed_at_s; }},
      {.key = "checkpoints_written", .unit = "1", .count = [](const D& d) { return d.checkpoints.written; }},
  };
  return fields;
}

const std::vector<RecordField<BedSummary>>& bed_summary_fields() {
  using B = BedSummary;
  static const std::vector<RecordField<B>> fields = {
      {.key = "grains_placed", .unit = "1", .count = &B::grains_placed},
      {.key = "grains_kept", .unit = "1", .count = &B::grains_kept},
      {.key = "settled", .unit = "1", .flag = &B::settled},
      {.key = "settle_end", .unit = "", .text = &B::settle_end},
      {.key = "relax_end", .unit = "", .text = &B::relax_end},
      {.key = "settle_time_s", .unit = "s", .number = &B::settle_time_s},
      {.key = "relax_time_s", .unit = "s", .number = &B::relax_time_s},
      {.key = "quench_time_s", .unit = "s", .number = &B::quench_time_s},
      {.key = "surface_relax_s", .unit = "s", .number = &B::surface_relax_s},
      {.key = "rms_speed_m_s", .unit = "m/s", .number = &B::rms_speed_m_s},
      {.key = "max_speed_m_s", .unit = "m/s", .number = &B::max_speed_m_s},
      {.key = "max_surface_speed_m_s", .unit = "m/s", .number = &B::max_surface_speed_m_s},
      {.key = "surface_grains", .unit = "1", .count = &B::surface_grains},
      {.key = "at_rest_for_impacts_above_m_s", .unit = "m/s", .maybe = &B::at_rest_for_impacts_above_m_s},
      {.key = "surface_height_m", .unit = "m", .number = &B::surface_height_m},
      {.key = "bulk_density_kg_m3", .unit = "kg/m3", .number = &B::bulk_density_kg_m3},
      {.key = "steps", .unit = "1", .count = &B::steps},
      {.key = "dt_s", .unit = "s", .number = &B::dt_s},
      {.key = "threads", .unit = "1", .count = &B::threads},
      {.key = "wall_time_s", .unit = "s", .number = &B::wall_time_s},
      {.key = "checkpoint_resumes", .unit = "1", .count = &B::checkpoint_resumes},
      {.key = "resumed_at_s", .unit = "s", .maybe = &B::resumed_at_s},
      {.key = "checkpoints_written", .unit = "1", .count = &B::checkpoints_written},
  };
  return fields;
}

nlohmann::json to_json(const BedSummary& b) { return record_json(b, bed_summary_fields()); }

BedSummary bed_summary_of_json(const nlohmann::json& j, const std::string& where) {
  return record_of_json(j, bed_summary_fields(), where);
}

}  // namespace gravsweep::results
