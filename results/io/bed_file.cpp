#include "results/io/bed_file.h"

#include <fmt/format.h>

#include "results/io/hdf5.h"

namespace gravsweep::results {

void write_bed(const std::filesystem::path& path, const BedData& b) {
  const std::size_t n = b.size();
  if (b.position_m.size() != 3 * n || b.velocity_m_s.size() != 3 * n || b.omega_rad_s.size() != 3 * n ||
      b.mass_kg.size() != n || b.material.size() != n)
    throw h5::H5Error(fmt::format("bed {}: inconsistent array sizes for {} grains", path.string(), n));
  h5::write_atomically(path, [&](const std::filesystem::path& tmp) {
    h5::File f = h5::File::create(tmp);
    h5::set_attr(f.id(), "format", kBedFormat);
    h5::set_attr(f.id(), "format_version", kBedFormatVersion);
    h5::set_attr(f.id(), "code_version", b.code_version);
    h5::set_attr(f.id(), "bed_key", b.bed_key_json);
    h5::set_attr(f.id(), "scenario", b.scenario_json);
    h5::set_attr(f.id(), "report", b.report_json);
    {
      h5::Handle c = h5::create_group(f.id(), "container");
      h5::set_attr(c, "description", "cylinder with a disk bottom at z = 0 (engine frame, z up), axis at x = y = 0");
      h5::set_attr(c, "diameter_m", b.container_diameter_m);
      h5::set_attr(c, "wall_height_m", b.wall_height_m);
      h5::set_attr(c, "fill_height_m", b.fill_height_m);
      h5::set_attr(c, "surface_height_m", b.surface_height_m);
      h5::set_attr(c, "gravity_m_s2", b.gravity_m_s2);
      h5::set_attr(c, "time_s", b.time_s);
    }
    h5::Handle g = h5::create_group(f.id(), "grains");
    h5::set_attr(g, "count", static_cast<long long>(n));
    const std::vector<hsize_t> d3{n, 3};
    h5::write_doubles(g, "position_m", b.position_m, d3, "m", "grain centres, engine frame (z up, bottom at z = 0)");
    h5::write_doubles(g, "velocity_m_s", b.velocity_m_s, d3, "m/s", "grain velocities");
    h5::write_doubles(g, "omega_rad_s", b.omega_rad_s, d3, "rad/s", "grain angular velocities");
    h5::write_doubles(g, "radius_m", b.radius_m, {n}, "m", "grain radii");
    h5::write_doubles(g, "mass_kg", b.mass_kg, {n}, "kg", "grain masses");
    h5::write_uint8(g, "material", b.material, "1", "material id (0 grain, 1 wall, 2 projectile)");
    f.close();
  });
}

BedData read_bed(const std::filesystem::path& path) {
  h5::File f = h5::File::open_read(path);
  if (!h5::has_attr(f.id(), "format") || h5::get_attr_string(f.id(), "format") != kBedFormat)
    throw h5::H5Error(
        fmt::format("bed {}: not a gravsweep bed file (root attribute format != '{}')", path.string(), kBedFormat));
  const long long version = h5::get_attr_int(f.id(), "format_version");
  if (version != kBedFormatVersion)
    throw h5::H5Error(fmt::format("bed {}: format_version {} is not supported (expected {})", path.string(), version,
                                  kBedFormatVersion));
  BedData b;
  b.code_version = h5::get_attr_string(f.id(), "code_version");
  b.bed_key_json = h5::get_attr_string(f.id(), "bed_key");
  b.scenario_json = h5::get_attr_string(f.id(), "scenario");
  b.report_json = h5::get_attr_string(f.id(), "report");
  {
    h5::Handle c = h5::open_group(f.id(), "container");
    b.container_diameter_m = h5::get_attr_double(c, "diameter_m");
    b.wall_height_m = h5::get_attr_double(c, "wall_height_m");
    b.fill_height_m = h5::get_attr_double(c, "fill_height_m");
    b.surface_height_m = h5::get_attr_double(c, "surface_height_m");
    b.gravity_m_s2 = h5::get_attr_double(c, "gravity_m_s2");
    b.time_s = h5::get_attr_double(c, "time_s");
  }
  h5::Handle g = h5::open_group(f.id(), "grains");
  std::vector<hsize_t> dims;
  b.position_m = h5::read_doubles(g, "position_m", &dims);
  if (dims.size() != 2 || dims[1] != 3)
    throw h5::H5Error(fmt::format("bed {}: /grains/position_m must have shape (N, 3)", path.string()));
  const std::size_t n = dims[0];
  b.velocity_m_s = h5::read_doubles(g, "velocity_m_s");
  b.omega_rad_s = h5::read_doubles(g, "omega_rad_s");
  b.radius_m = h5::read_doubles(g, "radius_m");
  b.mass_kg = h5::read_doubles(g, "mass_kg");
  b.material = h5::read_uint8(g, "material");
  if (b.velocity_m_s.size() != 3 * n || b.omega_rad_s.size() != 3 * n || b.radius_m.size() != n ||
      b.mass_kg.size() != n || b.material.size() != n)
    throw h5::H5Error(fmt::format("bed {}: the /grains datasets do not all hold {} grains", path.string(), n));
  return b;
}

}  // namespace gravsweep::results
