#include "engine/geometry/walls.h"

#include <cmath>

namespace gravsweep {

Wall Wall::plane(std::string name, const Vec3& point, const Vec3& inward_normal, std::uint8_t mat) {
  Wall w;
  w.kind = WallKind::plane;
  w.name = std::move(name);
  w.point_m = point;
  w.normal = inward_normal.normalized();
  w.material = mat;
  return w;
}

Wall Wall::disk(std::string name, const Vec3& centre, const Vec3& inward_normal, double radius_m, std::uint8_t mat) {
  Wall w = plane(std::move(name), centre, inward_normal, mat);
  w.kind = WallKind::disk;
  w.radius_m = radius_m;
  return w;
}

Wall Wall::cylinder(std::string name, const Vec3& base, const Vec3& axis, double radius_m, double height_m,
                    std::uint8_t mat) {
  Wall w;
  w.kind = WallKind::cylinder;
  w.name = std::move(name);
  w.point_m = base;
  w.normal = axis.normalized();
  w.radius_m = radius_m;
  w.height_m = height_m;
  w.material = mat;
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
