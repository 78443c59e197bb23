// trace.h5: the projectile's record during one drop (Sunday et al. 2021 Sect. 2.2-2.3), in the
// paper's frame: depth z positive down from the mean bed surface, velocity positive down,
// acceleration positive up (free fall reads -g, rest reads 0). Layout (results/io/README.md):
//
//   /                          attrs: format = "gravsweep-trace", format_version, code_version,
//                                     scenario (JSON), bed_key (JSON), bed_file, metrics (JSON)
//   /trace                     attrs: sample_rate_hz, dt_s, gravity_m_s2, surface_height_m,
//                                     release_height_m, release_speed_m_s, projectile_diameter_m,
//                                     projectile_mass_kg, fill_height_m (= surface_height_m, kept
//                                     for older readers), grain_diameter_m,
//                                     stopped (1: stop criterion met, 0: time cap)
//   /trace/t_s                 (T)    time since release
//   /trace/depth_m             (T)    depth of the projectile's lowest point below the surface
//   /trace/velocity_down_m_s   (T)
//   /trace/accel_up_m_s2       (T)    mean over the preceding sample interval
//   /trace/omega_rad_s         (T, 3) projectile angular velocity, engine frame
//   /trace/position_m          (T, 3) projectile centre, engine frame (z up, bottom at z = 0)
//   /trace/contacts            (T)    int32, grains and walls touching the projectile
//   /trace/grain_kinetic_energy_J (T)
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "results/processing/trace.h"

namespace gravsweep::results {

/// A DEM drop's record as trace.h5 holds it. It is the processing's Trace itself (source dem; t_s,
/// depth_m, velocity_down_m_s, accel_up_m_s2 and contact_start_s are read by process_trace as
/// they are, with no copy into another form), with the engine's further columns and the drop's facts.
struct TraceData : Trace {
  TraceData() { source = TraceSource::dem; }
  std::vector<double> omega_rad_s;  ///< T x 3
  std::vector<double> position_m;   ///< T x 3
  std::vector<std::int32_t> contacts;
  std::vector<double> grain_kinetic_energy_J;
  double sample_rate_hz = 0, dt_s = 0, gravity_m_s2 = 0;
  /// Measured bed surface above the container floor, m (mean top of the grains in the central
  /// 60 % of the radius, engine frame z up): depth z = 0 of the paper's frame, and the floor lies
  /// this far below it (z positive down). A DEM trial's fill height (trial_fields()).
  double surface_height_m = 0;
  double release_height_m = 0, release_speed_m_s = 0;
  double projectile_diameter_m = 0, projectile_mass_kg = 0, grain_diameter_m = 0;
  bool stopped = false;
  std::string scenario_json, bed_key_json, bed_file, metrics_json, code_version;

  [[nodiscard]] std::size_t size() const { return t_s.size(); }
  /// Sets contact_start_s from `contacts`: the engine's first contact is the last sample before the
  /// first one that counts a contact (none when no sample does). Not stored: read_trace and
  /// take_trace_columns call it.
  void mark_contact_start();
};

/// The fields of trace.h5, one table each, from which write_trace and read_trace (and a DEM trial's
/// facts, trial_fields()) are made: the root's text attributes, the numeric attributes of /trace
/// and its double columns (`width` values a sample). `contacts` (int32) and `stopped` (a flag)
/// are the two fields outside them.
struct TraceText {
  const char* name;
  std::string TraceData::*value;
};
struct TraceAttribute {
  const char* name;
  double TraceData::*value;
};
struct TraceColumn {
  const char* name;
  std::vector<double> TraceData::*values;
  std::size_t width;
  const char* unit;
  const char* description;
};
const std::vector<TraceText>& trace_texts();
const std::vector<TraceAttribute>& trace_attributes();
const std::vector<TraceColumn>& trace_columns();
/// The numeric /trace attribute `name` of `d`; std::logic_error naming it when there is none.
double trace_attribute(const TraceData& d, const std::string& name);

inline constexpr const char* kTraceFormat = "gravsweep-trace";
inline constexpr long long kTraceFormatVersion = 1;

/// Writes under a temporary name, then renames into place.
void write_trace(const std::filesystem::path& path, const TraceData& trace);
TraceData read_trace(const std::filesystem::path& path);

}  // namespace gravsweep::results
