// bed.h5: a prepared granular bed (Sunday et al. 2021 Sect. 2.2: mixed, settled, flattened,
// relaxed), saved so that many drops reuse it. Layout (results/io/README.md):
//
//   /                      attrs: format = "gravsweep-bed", format_version, code_version,
//                                 bed_key (JSON), scenario (JSON), report (JSON)
//   /container             attrs: diameter_m, wall_height_m, fill_height_m, surface_height_m,
//                                 gravity_m_s2, time_s (simulated time at the end of preparation)
//   /grains/position_m     (N, 3) float64, engine frame: z up, bottom disk at z = 0, axis x = y = 0
//   /grains/velocity_m_s   (N, 3)
//   /grains/omega_rad_s    (N, 3)
//   /grains/radius_m       (N)
//   /grains/mass_kg        (N)
//   /grains/material       (N) uint8, material id (0 grain, 1 wall, 2 projectile)
//
// Values are stored bit-exact, so a drop from a saved bed equals a drop from the bed in memory.
#pragma once
#include <filesystem>
#include <string>

#include "engine/core/particles.h"

namespace gravsweep::results {

/// What a bed file says beside its grains: the container, the preparation's outcome and where the
/// bed came from. The grains themselves go between the file and an engine `Particles` (a System's
/// own when a drop loads the bed, engine_records.h `load_bed`), with no other array form between.
struct BedFacts {
  double container_diameter_m = 0;
  double wall_height_m = 0;
  double fill_height_m = 0;
  double surface_height_m = 0;
  double gravity_m_s2 = 0;
  double time_s = 0;          ///< simulated time at the end of the preparation
  std::string bed_key_json;   ///< canonical JSON of what defines the bed
  std::string scenario_json;  ///< the scenario that prepared it
  std::string report_json;    ///< preparation report (grains, settling, bulk density, wall time)
  std::string code_version;
};

inline constexpr const char* kBedFormat = "gravsweep-bed";
inline constexpr long long kBedFormatVersion = 1;

/// Writes the grains (every particle of `grains` must be of size class grain: std::invalid_argument
/// otherwise) and the facts under a temporary name, then renames into place.
void write_bed(const std::filesystem::path& path, const Particles& grains, const BedFacts& facts);
/// Reads and checks the layout, and replaces `grains` by the file's: free solid spheres of size
/// class grain at their saved velocities and spins (Particles::complete_columns), no force yet.
/// Throws h5::H5Error naming the file and the missing piece, and ConfigError naming the file and
/// the grain whose radius, mass (density), position, velocity or spin lies outside any real bed's
/// range (a corrupt number); `grains` is left as it was then.
BedFacts read_bed(const std::filesystem::path& path, Particles& grains);
/// The same read and checks for a reader of the facts alone (the grains dropped).
BedFacts read_bed(const std::filesystem::path& path);

}  // namespace gravsweep::results
