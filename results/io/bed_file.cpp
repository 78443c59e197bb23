#include "results/io/bed_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "engine/core/error.h"
#include "results/io/h5_visit.h"
#include "results/io/hdf5.h"

namespace gravsweep::results {

namespace {

// Physical ranges of a bed's grains, wide enough for any real bed (sand to boulders, aerogel to
// tungsten) and narrow enough to catch a corrupt number (a flipped exponent bit scales a value by
// 2^64 or more) before it becomes a numerical failure at step 0 without a name.
constexpr double kMaxGrainRadius_m = 1.0;
constexpr double kMaxGrainMass_kg = 1000.0;
constexpr double kMinGrainDensity_kg_m3 = 10.0;
constexpr double kMaxGrainDensity_kg_m3 = 1e5;
constexpr double kMaxGrainSpeed_m_s = 1000.0;
constexpr double kMaxGrainSpin_rad_s = 1e7;
constexpr double kContainerMargin = 10.0;  ///< container diameters a grain may lie outside it

[[noreturn]] void out_of_range(const std::filesystem::path& path, std::size_t grain, const std::string& what,
                               const std::string& expected) {
  throw ConfigError(fmt::format("bed {}: grain {}: {}, expected {}; the file is corrupt (or not a bed of real grains)",
                                path.string(), grain, what, expected));
}

/// Refuses a grain outside the physical ranges (ConfigError naming the file, the grain, the value).
void check_grain(const std::filesystem::path& path, const BedFacts& f, const Particles& g, std::size_t i) {
  const double r = g.radius_m[i], m = g.mass_kg[i];
  if (!(r > 0 && r <= kMaxGrainRadius_m))
    out_of_range(path, i, fmt::format("radius_m {}", r), fmt::format("0 < radius <= {} m", kMaxGrainRadius_m));
  if (!(m > 0 && m <= kMaxGrainMass_kg))
    out_of_range(path, i, fmt::format("mass_kg {}", m), fmt::format("0 < mass <= {} kg", kMaxGrainMass_kg));
  const double density = m / (4.0 / 3.0 * std::numbers::pi * r * r * r);
  if (!(density >= kMinGrainDensity_kg_m3 && density <= kMaxGrainDensity_kg_m3))
    out_of_range(path, i, fmt::format("mass_kg {} and radius_m {} make a density of {:.4g} kg/m3", m, r, density),
                 fmt::format("{} to {} kg/m3", kMinGrainDensity_kg_m3, kMaxGrainDensity_kg_m3));
  const Vec3& p = g.position_m[i];
  const Vec3& v = g.velocity_m_s[i];
  const Vec3& w = g.omega_rad_s[i];
  // Near the container, with a wide margin (a corrupt exponent scales a coordinate by 2^64, a real
  // grain is inside): radially within ten diameters, vertically from ten diameters below the floor
  // to ten above the highest of wall, fill and surface.
  const double d = f.container_diameter_m;
  const double margin_m = kContainerMargin * d;
  const double top_m = std::max({f.wall_height_m, f.fill_height_m, f.surface_height_m}) + margin_m;
  const bool inside = d > 0 ? std::hypot(p[0], p[1]) <= margin_m && p[2] >= -margin_m && p[2] <= top_m
                            : std::abs(p[0]) <= 1e3 && std::abs(p[1]) <= 1e3 && std::abs(p[2]) <= 1e3;
  if (!inside || !std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
    out_of_range(path, i, fmt::format("position_m ({}, {}, {})", p[0], p[1], p[2]),
                 d > 0
                     ? fmt::format("a point within {} container diameters ({} m) of the container", kContainerMargin, d)
                     : std::string("a finite point within 1 km"));
  if (!(std::hypot(v[0], v[1], v[2]) <= kMaxGrainSpeed_m_s))
    out_of_range(path, i, fmt::format("velocity_m_s ({}, {}, {})", v[0], v[1], v[2]),
                 fmt::format("a speed <= {} m/s", kMaxGrainSpeed_m_s));
  if (!(std::hypot(w[0], w[1], w[2]) <= kMaxGrainSpin_rad_s))
    out_of_range(path, i, fmt::format("omega_rad_s ({}, {}, {})", w[0], w[1], w[2]),
                 fmt::format("a spin <= {:g} rad/s", kMaxGrainSpin_rad_s));
}

/// The bed's layout (bed_file.h), for writing and reading alike (h5_visit.h): the facts, then the
/// grains' state and properties as the columns of the engine's Particles.
template <class Io>
void visit_bed(Io& io, hid_t root, BedFacts& f, Particles& g) {
  io.attr(root, "code_version", f.code_version);
  io.attr(root, "bed_key", f.bed_key_json);
  io.attr(root, "scenario", f.scenario_json);
  io.attr(root, "report", f.report_json);
  {
    h5::Handle c = io.group(root, "container");
    std::string description = "cylinder with a disk bottom at z = 0 (engine frame, z up), axis at x = y = 0";
    io.attr(c, "description", description);
    io.attr(c, "diameter_m", f.container_diameter_m);
    io.attr(c, "wall_height_m", f.wall_height_m);
    io.attr(c, "fill_height_m", f.fill_height_m);
    io.attr(c, "surface_height_m", f.surface_height_m);
    io.attr(c, "gravity_m_s2", f.gravity_m_s2);
    io.attr(c, "time_s", f.time_s);
  }
  h5::Handle grains = io.group(root, "grains");
  auto count = static_cast<long long>(g.size());
  io.attr(grains, "count", count);
  io.array(grains, "position_m", g.position_m, "m", "grain centres, engine frame (z up, bottom at z = 0)");
  io.array(grains, "velocity_m_s", g.velocity_m_s, "m/s", "grain velocities");
  io.array(grains, "omega_rad_s", g.omega_rad_s, "rad/s", "grain angular velocities");
  io.array(grains, "radius_m", g.radius_m, "m", "grain radii");
  io.array(grains, "mass_kg", g.mass_kg, "kg", "grain masses");
  io.array(grains, "material", g.material, "1", "material id (0 grain, 1 wall, 2 projectile)");
}

}  // namespace

void write_bed(const std::filesystem::path& path, const Particles& grains, const BedFacts& facts) {
  for (std::size_t i = 0; i < grains.size(); ++i)
    if (grains.size_class[i] != SizeClass::grain)
      throw std::invalid_argument(
          fmt::format("bed {}: particle {} is not a grain; a bed file holds grains only", path.string(), i));
  h5::write_atomically(path, [&](const std::filesystem::path& tmp) {
    h5::File f = h5::File::create(tmp);
    h5::set_attr(f.id(), "format", kBedFormat);
    h5::set_attr(f.id(), "format_version", kBedFormatVersion);
    h5visit::Writer w;
    w.storage = h5::Storage::compressed;  // a bed is kept and shared: its arrays deflated
    // The writer only reads the values.
    visit_bed(w, f.id(), const_cast<BedFacts&>(facts), const_cast<Particles&>(grains));
    f.close();
  });
}

BedFacts read_bed(const std::filesystem::path& path, Particles& grains) {
  h5::File file = h5::File::open_read(path);
  if (!h5::has_attr(file.id(), "format") || h5::get_attr_string(file.id(), "format") != kBedFormat)
    throw h5::H5Error(
        fmt::format("bed {}: not a gravsweep bed file (root attribute format != '{}')", path.string(), kBedFormat));
  const long long version = h5::get_attr_int(file.id(), "format_version");
  if (version != kBedFormatVersion)
    throw h5::H5Error(fmt::format("bed {}: format_version {} is not supported (expected {})", path.string(), version,
                                  kBedFormatVersion));
  BedFacts f;
  Particles g;  // moved into `grains` once read and checked
  h5visit::Reader r;
  visit_bed(r, file.id(), f, g);
  const std::size_t n = g.size();
  if (g.velocity_m_s.size() != n || g.omega_rad_s.size() != n || g.radius_m.size() != n || g.mass_kg.size() != n ||
      g.material.size() != n)
    throw h5::H5Error(fmt::format("bed {}: the /grains datasets do not all hold {} grains", path.string(), n));
  for (std::size_t i = 0; i < n; ++i) check_grain(path, f, g, i);
  g.complete_columns(0, SizeClass::grain);
  grains = std::move(g);
  return f;
}

BedFacts read_bed(const std::filesystem::path& path) {
  Particles dropped;
  return read_bed(path, dropped);
}

}  // namespace gravsweep::results
