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

bool touch_wall(const Wall& w, const Vec3& x, double r, WallTouch& out) {
  const Vec3 d = x - w.point_m;
  switch (w.kind) {
    case WallKind::plane:
    case WallKind::disk: {
      const double dist = d.dot(w.normal);
      if (dist >= r || dist <= -r) return false;  // not touching, or fully behind the wall
      if (w.kind == WallKind::disk) {
        const Vec3 radial = d - dist * w.normal;
        if (radial.squaredNorm() > w.radius_m * w.radius_m) return false;
      }
      out.n = -w.normal;
      out.distance_m = dist;
      out.overlap_m = r - dist;
      out.R_eff_m = r;
      return true;
    }
    case WallKind::cylinder: {
      const double axial = d.dot(w.normal);
      if (axial < 0 || axial > w.height_m) return false;
      const Vec3 radial = d - axial * w.normal;
      const double rho = radial.norm();
      const double dist = w.radius_m - rho;
      if (dist >= r || rho <= 0) return false;
      out.n = radial / rho;
      out.distance_m = dist;
      out.overlap_m = r - dist;
      out.R_eff_m = w.concave_curvature ? r * w.radius_m / (w.radius_m - r) : r;
      return true;
    }
  }
  return false;
}

}  // namespace gravsweep
