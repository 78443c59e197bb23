#include "results/io/trace_file.h"

#include <fmt/format.h>

#include "results/io/hdf5.h"

namespace gravsweep::results {

Trace TraceData::to_trace() const {
  Trace t;
  t.source = TraceSource::dem;
  t.t_s = t_s;
  t.accel_up_m_s2 = accel_up_m_s2;
  t.depth_m = depth_m;
  t.velocity_down_m_s = velocity_down_m_s;
  // The engine's first contact: the last sample before the first one that counts a contact.
  for (std::size_t k = 0; k < contacts.size() && k < t_s.size(); ++k) {
    if (contacts[k] > 0) {
      t.contact_start_s = t_s[k == 0 ? 0 : k - 1];
      break;
    }
  }
  return t;
}

void write_trace(const std::filesystem::path& path, const TraceData& d) {
  const std::size_t n = d.size();
  if (d.depth_m.size() != n || d.velocity_down_m_s.size() != n || d.accel_up_m_s2.size() != n ||
      d.omega_rad_s.size() != 3 * n || d.position_m.size() != 3 * n || d.contacts.size() != n ||
      d.grain_kinetic_energy_J.size() != n)
    throw h5::H5Error(fmt::format("trace {}: inconsistent column lengths for {} samples", path.string(), n));
  h5::write_atomically(path, [&](const std::filesystem::path& tmp) {
    h5::File f = h5::File::create(tmp);
    h5::set_attr(f.id(), "format", kTraceFormat);
    h5::set_attr(f.id(), "format_version", kTraceFormatVersion);
    h5::set_attr(f.id(), "code_version", d.code_version);
    h5::set_attr(f.id(), "scenario", d.scenario_json);
    h5::set_attr(f.id(), "bed_key", d.bed_key_json);
    h5::set_attr(f.id(), "bed_file", d.bed_file);
    h5::set_attr(f.id(), "metrics", d.metrics_json);
    h5::Handle g = h5::create_group(f.id(), "trace");
    h5::set_attr(g, "description",
                 "projectile record, paper frame: depth positive down from the mean bed surface, "
                 "velocity positive down, acceleration positive up (free fall = -g)");
    h5::set_attr(g, "sample_rate_hz", d.sample_rate_hz);
    h5::set_attr(g, "dt_s", d.dt_s);
    h5::set_attr(g, "gravity_m_s2", d.gravity_m_s2);
    h5::set_attr(g, "surface_height_m", d.surface_height_m);
    h5::set_attr(g, "release_height_m", d.release_height_m);
    h5::set_attr(g, "release_speed_m_s", d.release_speed_m_s);
    h5::set_attr(g, "projectile_diameter_m", d.projectile_diameter_m);
    h5::set_attr(g, "projectile_mass_kg", d.projectile_mass_kg);
    // Format version 1 had both; gravsweep reads surface_height_m, older versions fill_height_m.
    h5::set_attr(g, "fill_height_m", d.surface_height_m);
    h5::set_attr(g, "grain_diameter_m", d.grain_diameter_m);
    h5::set_attr(g, "stopped", static_cast<long long>(d.stopped ? 1 : 0));
    h5::write_doubles(g, "t_s", d.t_s, {n}, "s", "time since release");
    h5::write_doubles(g, "depth_m", d.depth_m, {n}, "m",
                      "depth of the projectile's lowest point below the mean bed surface (positive down)");
    h5::write_doubles(g, "velocity_down_m_s", d.velocity_down_m_s, {n}, "m/s",
                      "vertical velocity of the projectile, positive down");
    h5::write_doubles(g, "accel_up_m_s2", d.accel_up_m_s2, {n}, "m/s2",
                      "vertical acceleration, positive up (free fall = -g), mean over the preceding sample interval");
    h5::write_doubles(g, "omega_rad_s", d.omega_rad_s, {n, 3}, "rad/s", "projectile angular velocity (engine frame)");
    h5::write_doubles(g, "position_m", d.position_m, {n, 3}, "m",
                      "projectile centre, engine frame (z up, container bottom at z = 0)");
    h5::write_int32(g, "contacts", d.contacts, "1", "grains and walls touching the projectile");
    h5::write_doubles(g, "grain_kinetic_energy_J", d.grain_kinetic_energy_J, {n}, "J",
                      "translational + rotational kinetic energy of all grains");
    f.close();
  });
}

TraceData read_trace(const std::filesystem::path& path) {
  h5::File f = h5::File::open_read(path);
  if (!h5::has_attr(f.id(), "format") || h5::get_attr_string(f.id(), "format") != kTraceFormat)
    throw h5::H5Error(fmt::format("trace {}: not a gravsweep trace file (root attribute format != '{}')", path.string(),
                                  kTraceFormat));
  const long long version = h5::get_attr_int(f.id(), "format_version");
  if (version != kTraceFormatVersion)
    throw h5::H5Error(fmt::format("trace {}: format_version {} is not supported (expected {})", path.string(), version,
                                  kTraceFormatVersion));
  TraceData d;
  d.code_version = h5::get_attr_string(f.id(), "code_version");
  d.scenario_json = h5::get_attr_string(f.id(), "scenario");
  d.bed_key_json = h5::get_attr_string(f.id(), "bed_key");
  d.bed_file = h5::get_attr_string(f.id(), "bed_file");
  d.metrics_json = h5::get_attr_string(f.id(), "metrics");
  h5::Handle g = h5::open_group(f.id(), "trace");
  d.sample_rate_hz = h5::get_attr_double(g, "sample_rate_hz");
  d.dt_s = h5::get_attr_double(g, "dt_s");
  d.gravity_m_s2 = h5::get_attr_double(g, "gravity_m_s2");
  d.surface_height_m = h5::get_attr_double(g, "surface_height_m");
  d.release_height_m = h5::get_attr_double(g, "release_height_m");
  d.release_speed_m_s = h5::get_attr_double(g, "release_speed_m_s");
  d.projectile_diameter_m = h5::get_attr_double(g, "projectile_diameter_m");
  d.projectile_mass_kg = h5::get_attr_double(g, "projectile_mass_kg");
  d.grain_diameter_m = h5::get_attr_double(g, "grain_diameter_m");
  d.stopped = h5::get_attr_int(g, "stopped") != 0;
  d.t_s = h5::read_doubles(g, "t_s");
  d.depth_m = h5::read_doubles(g, "depth_m");
  d.velocity_down_m_s = h5::read_doubles(g, "velocity_down_m_s");
  d.accel_up_m_s2 = h5::read_doubles(g, "accel_up_m_s2");
  d.omega_rad_s = h5::read_doubles(g, "omega_rad_s");
  d.position_m = h5::read_doubles(g, "position_m");
  d.contacts = h5::read_int32(g, "contacts");
  d.grain_kinetic_energy_J = h5::read_doubles(g, "grain_kinetic_energy_J");
  const std::size_t n = d.t_s.size();
  if (d.depth_m.size() != n || d.velocity_down_m_s.size() != n || d.accel_up_m_s2.size() != n ||
      d.omega_rad_s.size() != 3 * n || d.position_m.size() != 3 * n || d.contacts.size() != n ||
      d.grain_kinetic_energy_J.size() != n)
    throw h5::H5Error(fmt::format("trace {}: the /trace columns do not all hold {} samples", path.string(), n));
  return d;
}

}  // namespace gravsweep::results
