// Analytic walls: infinite planes, a flat disk bottom, and the concave inner side of a cylinder.
// Walls are fixed and of infinite mass; each has its own material.
#pragma once
#include <cmath>
#include <cstdint>
#include <string>

#include "engine/core/types.h"

namespace gravsweep {

enum class WallKind : std::uint8_t { plane, disk, cylinder };

struct Wall {
  WallKind kind = WallKind::plane;
  std::string name;
  std::uint8_t material = 0;
  Vec3 point_m = Vec3::Zero();  ///< plane: a point on it; disk: its centre; cylinder: base of the axis
  Vec3 normal = Vec3::UnitZ();  ///< plane/disk: unit normal pointing into the domain; cylinder: axis
  double radius_m = kInf;       ///< disk radius or cylinder radius
  double height_m = kInf;       ///< cylinder extent along its axis from point_m
  /// Concave cylinder: R* = R Rc / (Rc - R) (true curvature). False: flat-face R* = R, as Chrono's
  /// container built from boxes (docs/physics/contact-laws.md section 1.1).
  bool concave_curvature = true;

  static Wall plane(std::string name, const Vec3& point, const Vec3& inward_normal, std::uint8_t mat);
  static Wall disk(std::string name, const Vec3& centre, const Vec3& inward_normal, double radius_m, std::uint8_t mat);
  static Wall cylinder(std::string name, const Vec3& base, const Vec3& axis, double radius_m, double height_m,
                       std::uint8_t mat);
};

/// Contact of a sphere with a wall.
struct WallTouch {
  Vec3 n;             ///< unit normal from the sphere's centre towards the wall
  double overlap_m;   ///< radius - distance to the surface (> 0 when touching)
  double distance_m;  ///< centre-to-surface distance
  double R_eff_m;     ///< effective radius of the pair
};

/// True when the sphere (centre x, radius r) touches the wall; fills `out`. Inline: the force
/// loop calls it for every particle-wall candidate of every step.
inline bool touch_wall(const Wall& w, const Vec3& x, double r, WallTouch& out) {
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

/// Signed distance of a point from the wall surface, positive on the domain side.
double wall_distance(const Wall& w, const Vec3& x);

}  // namespace gravsweep
