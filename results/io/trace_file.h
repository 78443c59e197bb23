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
#include <type_traits>
#include <vector>

#include "results/processing/trace.h"
#include "results/processing/trial_record.h"

namespace gravsweep::results {

/// A DEM drop's record as trace.h5 holds it, and the trial it is measured as: a MeasuredTrial
/// itself, so the drop's facts are written once and processing (process_trial) reads and writes
/// the record in place. `info` holds the trial facts of the drop: gravity, the projectile's
/// diameter and mass, the grain diameter, the sample rate, the code version, and as its fill
/// height the measured bed surface above the container floor (trace.h5's surface_height_m: the
/// mean top of the grains in the central 60 % of the radius, depth z = 0 of the paper's frame, the
/// floor this far below it); its name and processing settings are set by prepare_dem_trial. `raw`
/// holds the columns process_trace reads (t_s, depth_m, velocity_down_m_s, accel_up_m_s2) and
/// contact_start_s; `processed` and `options` what process_trial makes of them. Beside them: the
/// engine's further columns and the drop's facts that are no trial's.
struct TraceData : MeasuredTrial {
  TraceData() { info.source = raw.source = TraceSource::dem; }
  std::vector<double> omega_rad_s;  ///< T x 3
  std::vector<double> position_m;   ///< T x 3
  std::vector<std::int32_t> contacts;
  std::vector<double> grain_kinetic_energy_J;
  double dt_s = 0;
  double release_height_m = 0, release_speed_m_s = 0;
  bool stopped = false;
  std::string scenario_json, bed_key_json, bed_file, metrics_json;

  [[nodiscard]] std::size_t size() const { return raw.t_s.size(); }
  /// Sets raw.contact_start_s from `contacts`: the engine's first contact is the last sample
  /// before the first one that counts a contact (none when no sample does). Not stored: read_trace
  /// and take_trace_columns call it.
  void mark_contact_start();
};

/// Where a field of trace.h5 lives in the record: a member of its part `Part` (Trial: the trial's
/// facts, `info`; Trace: the columns processing reads, `raw`) or a member of the record's own. The tables
/// below name either kind of member as it is (`&Trial::gravity_m_s2`, `&TraceData::dt_s`).
template <class T, class Part>
class TracePlace {
 public:
  // Implicit: a table's cell is the member itself.
  TracePlace(T Part::*in_part) : in_part_(in_part) {}  // NOLINT
  TracePlace(T TraceData::*own) : own_(own) {}         // NOLINT
  [[nodiscard]] T& of(TraceData& d) const { return in_part_ ? part(d).*in_part_ : d.*own_; }
  [[nodiscard]] const T& of(const TraceData& d) const { return in_part_ ? part(d).*in_part_ : d.*own_; }

 private:
  template <class Record>
  static auto& part(Record& d) {
    if constexpr (std::is_same_v<Part, Trial>)
      return d.info;
    else
      return d.raw;
  }
  T Part::*in_part_ = nullptr;
  T TraceData::*own_ = nullptr;
};

/// The fields of trace.h5, one table each, from which write_trace and read_trace are made: the
/// root's text attributes, the numeric attributes of /trace and its double columns (`width`
/// values a sample). `contacts` (int32), `stopped` (a flag) and `fill_height_m` (written for older
/// readers) are the fields outside them.
struct TraceText {
  const char* name;
  TracePlace<std::string, Trial> value;
};
struct TraceAttribute {
  const char* name;
  TracePlace<double, Trial> value;
};
struct TraceColumn {
  const char* name;
  TracePlace<std::vector<double>, Trace> values;
  std::size_t width;
  const char* unit;
  const char* description;
};
const std::vector<TraceText>& trace_texts();
const std::vector<TraceAttribute>& trace_attributes();
const std::vector<TraceColumn>& trace_columns();

inline constexpr const char* kTraceFormat = "gravsweep-trace";
inline constexpr long long kTraceFormatVersion = 1;

/// Writes under a temporary name, then renames into place.
void write_trace(const std::filesystem::path& path, const TraceData& trace);
TraceData read_trace(const std::filesystem::path& path);

}  // namespace gravsweep::results
