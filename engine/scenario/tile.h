// Wide beds for the scaling benchmark (Sunday et al. 2021 Sect. 3.4, Fig. 8: cost against N): a
// square patch cut from a settled bed is copied side by side into a rectangular box, so a
// 500,000-grain bed keeps the contact density of the settled 8,000-grain bed without the hours
// that settling it from a pour would take. Engine frame: z up, floor at z = 0.
#pragma once
#include <cstddef>

#include "engine/system/system.h"

namespace gravsweep {

struct TileSpec {
  double patch_side_m = 0.22;  ///< side of the square patch, centred on the source's axis
  int nx = 1;                  ///< copies along x
  int ny = 1;                  ///< copies along y
};

/// Copies the free grains of `source` whose whole sphere lies inside the patch (centre at least
/// one radius from its edges, so copies never overlap) nx x ny times into `out`, which receives a
/// floor plane at z = 0 and four side planes around the tiled area (material of the source's
/// first wall). Velocities and spins are copied. Returns the number of grains in `out`.
std::size_t tile_bed(const System& source, const TileSpec& spec, System& out);

/// Grains of `source` one patch holds (what tile_bed copies per tile).
std::size_t grains_in_patch(const System& source, double patch_side_m);

}  // namespace gravsweep
