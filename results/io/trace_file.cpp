#include "results/io/trace_file.h"

#include <fmt/format.h>

#include "results/io/hdf5.h"

namespace gravsweep::results {

void TraceData::mark_contact_start() {
  raw.contact_start_s.reset();
  for (std::size_t k = 0; k < contacts.size() && k < raw.t_s.size(); ++k) {
    if (contacts[k] > 0) {
      raw.contact_start_s = raw.t_s[k == 0 ? 0 : k - 1];
      return;
    }
  }
}

const std::vector<TraceText>& trace_texts() {
  static const std::vector<TraceText> t = {{"code_version", &Trial::code_version},
                                           {"scenario", &TraceData::scenario_json},
                                           {"bed_key", &TraceData::bed_key_json},
                                           {"bed_file", &TraceData::bed_file},
                                           {"metrics", &TraceData::metrics_json}};
  return t;
}

const std::vector<TraceAttribute>& trace_attributes() {
  static const std::vector<TraceAttribute> t = {{"sample_rate_hz", &Trial::sample_rate_hz},
                                                {"dt_s", &TraceData::dt_s},
                                                {"gravity_m_s2", &Trial::gravity_m_s2},
                                                {"surface_height_m", &Trial::fill_height_m},
                                                {"release_height_m", &TraceData::release_height_m},
                                                {"release_speed_m_s", &TraceData::release_speed_m_s},
                                                {"projectile_diameter_m", &Trial::projectile_diameter_m},
                                                {"projectile_mass_kg", &Trial::projectile_mass_kg},
                                                {"grain_diameter_m", &Trial::grain_diameter_m}};
  return t;
}

const std::vector<TraceColumn>& trace_columns() {
  static const std::vector<TraceColumn> t = {
      {"t_s", &Trace::t_s, 1, "s", "time since release"},
      {"depth_m", &Trace::depth_m, 1, "m",
       "depth of the projectile's lowest point below the mean bed surface (positive down)"},
      {"velocity_down_m_s", &Trace::velocity_down_m_s, 1, "m/s", "vertical velocity of the projectile, positive down"},
      {"accel_up_m_s2", &Trace::accel_up_m_s2, 1, "m/s2",
       "vertical acceleration, positive up (free fall = -g), mean over the preceding sample interval"},
      {"omega_rad_s", &TraceData::omega_rad_s, 3, "rad/s", "projectile angular velocity (engine frame)"},
      {"position_m", &TraceData::position_m, 3, "m",
       "projectile centre, engine frame (z up, container bottom at z = 0)"},
      {"grain_kinetic_energy_J", &TraceData::grain_kinetic_energy_J, 1, "J",
       "translational + rotational kinetic energy of all grains"}};
  return t;
}

namespace {

/// True when every column holds `n` samples of its width.
bool columns_hold(const TraceData& d, std::size_t n) {
  for (const auto& c : trace_columns())
    if (c.values.of(d).size() != c.width * n) return false;
  return d.contacts.size() == n;
}

}  // namespace

void write_trace(const std::filesystem::path& path, const TraceData& d) {
  const std::size_t n = d.size();
  if (!columns_hold(d, n))
    throw h5::H5Error(fmt::format("trace {}: inconsistent column lengths for {} samples", path.string(), n));
  h5::write_atomically(path, [&](const std::filesystem::path& tmp) {
    h5::File f = h5::File::create(tmp);
    h5::set_attr(f.id(), "format", kTraceFormat);
    h5::set_attr(f.id(), "format_version", kTraceFormatVersion);
    for (const auto& a : trace_texts()) h5::set_attr(f.id(), a.name, a.value.of(d));
    h5::Handle g = h5::create_group(f.id(), "trace");
    h5::set_attr(g, "description",
                 "projectile record, paper frame: depth positive down from the mean bed surface, "
                 "velocity positive down, acceleration positive up (free fall = -g)");
    for (const auto& a : trace_attributes()) h5::set_attr(g, a.name, a.value.of(d));
    // Format version 1 had both; gravsweep reads surface_height_m, older versions fill_height_m.
    h5::set_attr(g, "fill_height_m", d.info.fill_height_m);
    h5::set_attr(g, "stopped", static_cast<long long>(d.stopped ? 1 : 0));
    for (const auto& c : trace_columns()) {
      const std::vector<hsize_t> dims = c.width == 1 ? std::vector<hsize_t>{n} : std::vector<hsize_t>{n, c.width};
      h5::write_doubles(g, c.name, c.values.of(d), dims, c.unit, c.description);
    }
    h5::write_int32(g, "contacts", d.contacts, "1", "grains and walls touching the projectile");
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
  for (const auto& a : trace_texts()) a.value.of(d) = h5::get_attr_string(f.id(), a.name);
  h5::Handle g = h5::open_group(f.id(), "trace");
  for (const auto& a : trace_attributes()) a.value.of(d) = h5::get_attr_double(g, a.name);
  d.stopped = h5::get_attr_int(g, "stopped") != 0;
  for (const auto& c : trace_columns()) c.values.of(d) = h5::read_doubles(g, c.name);
  d.contacts = h5::read_int32(g, "contacts");
  const std::size_t n = d.size();
  if (!columns_hold(d, n))
    throw h5::H5Error(fmt::format("trace {}: the /trace columns do not all hold {} samples", path.string(), n));
  d.mark_contact_start();
  return d;
}

}  // namespace gravsweep::results
