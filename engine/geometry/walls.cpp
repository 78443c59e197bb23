#include "engine/geometry/walls.h"

#include <cmath>

namespace gravsweep {

namespace {

/// A wall of `kind` with what every kind has: a name, a material, point_m and the unit `direction`
/// (Wall::normal: the inward normal of a plane or disk, the axis of a cylinder).
Wall placed_wall(WallKind kind, std::string name, const Vec3& point, const Vec3& direction, std::uint8_t mat) {
  Wall w;
  w.kind = kind;
  w.name = std::move(name);
  w.point_m = point;
  w.normal = direction.normalized();
  w.material = mat;
  return w;
}

}  // namespace

Wall Wall::plane(std::string name, const Vec3& point, const Vec3& inward_normal, std::uint8_t mat) {
  return placed_wall(WallKind::plane, std::move(name), point, inward_normal, mat);
}

Wall Wall::disk(std::string name, const Vec3& centre, const Vec3& inward_normal, double radius_m, std::uint8_t mat) {
  Wall w = placed_wall(WallKind::disk, std::move(name), centre, inward_normal, mat);
  w.radius_m = radius_m;
  return w;
}

Wall Wall::cylinder(std::string name, const Vec3& base, const Vec3& axis, double radius_m, double height_m,
                    std::uint8_t mat) {
  Wall w = placed_wall(WallKind::cylinder, std::move(name), base, axis, mat);
  w.radius_m = radius_m;
  w.height_m = height_m;
  return w;
}

double wall_distance(const Wall& w, const Vec3& x) {
  const Vec3 d = x - w.point_m;
  if (w.kind == WallKind::cylinder) {
    const Vec3 radial = d - d.dot(w.normal) * w.normal;
    return w.radius_m - radial.norm();
  }
  return d.dot(w.normal);
}

}  // namespace gravsweep
