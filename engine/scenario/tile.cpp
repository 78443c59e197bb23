#include "engine/scenario/tile.h"

#include <fmt/format.h>

#include <algorithm>

#include "engine/core/error.h"

namespace gravsweep {

namespace {

bool in_patch(const System& s, std::size_t i, double half_side_m) {
  const auto& p = s.particles;
  if (p.size_class[i] != SizeClass::grain || p.inv_mass_1_kg[i] == 0) return false;
  const double reach = half_side_m - p.radius_m[i];
  const Vec3& x = p.position_m[i];
  return std::abs(x.x()) < reach && std::abs(x.y()) < reach;
}

}  // namespace

std::size_t grains_in_patch(const System& source, double patch_side_m) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < source.particles.size(); ++i) n += in_patch(source, i, 0.5 * patch_side_m);
  return n;
}

std::size_t tile_bed(const System& source, const TileSpec& spec, System& out) {
  if (!(spec.patch_side_m > 0) || spec.nx < 1 || spec.ny < 1)
    throw ConfigError(fmt::format("tile_bed: patch side {} m and {} x {} copies must be positive", spec.patch_side_m,
                                  spec.nx, spec.ny));
  const double L = spec.patch_side_m, half = 0.5 * L;
  const auto& p = source.particles;
  double top = 0;
  for (std::size_t cx = 0; cx < static_cast<std::size_t>(spec.nx); ++cx)
    for (std::size_t cy = 0; cy < static_cast<std::size_t>(spec.ny); ++cy) {
      const Vec3 shift(half + static_cast<double>(cx) * L, half + static_cast<double>(cy) * L, 0.0);
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (!in_patch(source, i, half)) continue;
        const ParticleIndex k =
            out.particles.add(p.position_m[i] + shift, p.radius_m[i], p.mass_kg[i], p.material[i], SizeClass::grain);
        out.particles.set_velocity(k, p.velocity_m_s[i], p.omega_rad_s[i]);
        top = std::max(top, p.position_m[i].z() + p.radius_m[i]);
      }
    }
  if (out.particles.size() == 0)
    throw ConfigError(fmt::format("tile_bed: no grain of the source lies inside a {} m patch", L));
  const std::uint8_t mat = source.walls.empty() ? 0 : source.walls.front().material;
  const double X = spec.nx * L, Y = spec.ny * L;
  out.walls.push_back(Wall::plane("floor", Vec3::Zero(), Vec3::UnitZ(), mat));
  out.walls.push_back(Wall::plane("x_low", Vec3::Zero(), Vec3::UnitX(), mat));
  out.walls.push_back(Wall::plane("x_high", Vec3(X, 0, 0), -Vec3::UnitX(), mat));
  out.walls.push_back(Wall::plane("y_low", Vec3::Zero(), Vec3::UnitY(), mat));
  out.walls.push_back(Wall::plane("y_high", Vec3(0, Y, 0), -Vec3::UnitY(), mat));
  const double margin = 0.05;
  out.mutable_config().domain = Domain{Vec3(-margin, -margin, -margin), Vec3(X + margin, Y + margin, top + 1.0)};
  out.invalidate();
  return out.particles.size();
}

}  // namespace gravsweep
