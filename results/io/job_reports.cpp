// The field tables of a job's reports (see job_reports.h).
#include "results/io/job_reports.h"

namespace gravsweep::results {

const std::vector<RecordField<DemFigures>>& dem_figure_fields() {
  using D = DemFigures;
  static const std::vector<RecordField<D>> fields = {
      {.key = "max_depth_m", .unit = "m", .number = &D::max_depth_m},
      {.key = "final_depth_below_surface_m", .unit = "m", .number = &D::final_depth_below_surface_m},
      {.key = "first_contact_s", .unit = "s", .maybe = &D::first_contact_s},
      {.key = "stopped", .unit = "1", .flag = &D::stopped},
      {.key = "grains_spilled_over_rim", .unit = "1", .count = &D::grains_spilled_over_rim},
      {.key = "rest_time_s", .unit = "s", .maybe = &D::rest_time_s},
      {.key = "duration_to_rest_s", .unit = "s", .maybe = &D::duration_to_rest_s},
      {.key = "simulated_time_s", .unit = "s", .number = &D::simulated_time_s},
      {.key = "steps", .unit = "1", .count = &D::steps},
      {.key = "dt_s", .unit = "s", .number = &D::dt_s},
      {.key = "sample_rate_hz", .unit = "Hz", .number = &D::sample_rate_hz},
      {.key = "gravity_m_s2", .unit = "m/s2", .number = &D::gravity_m_s2},
      {.key = "grains", .unit = "1", .count = &D::grains},
      {.key = "surface_height_m", .unit = "m", .number = &D::surface_height_m},
      {.key = "release_speed_m_s", .unit = "m/s", .number = &D::release_speed_m_s},
      {.key = "release_height_above_surface_m", .unit = "m", .number = &D::release_height_above_surface_m},
      {.key = "first_touch_height_above_surface_m", .unit = "m", .number = &D::first_touch_height_above_surface_m},
      {.key = "lateral_offset_m", .unit = "m", .number = &D::lateral_offset_m},
      {.key = "threads", .unit = "1", .count = &D::threads},
      {.key = "wall_time_s", .unit = "s", .number = &D::wall_time_s},
      {.key = "checkpoint_resumes", .unit = "1", .count = &D::checkpoint_resumes},
      {.key = "resumed_at_s", .unit = "s", .maybe = &D::resumed_at_s},
      {.key = "checkpoints_written", .unit = "1", .count = &D::checkpoints_written},
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

nlohmann::json to_json(const DemFigures& d) { return record_json(d, dem_figure_fields()); }
nlohmann::json to_json(const BedSummary& b) { return record_json(b, bed_summary_fields()); }

BedSummary bed_summary_of_json(const nlohmann::json& j, const std::string& where) {
  return record_of_json(j, bed_summary_fields(), where);
}

}  // namespace gravsweep::results
