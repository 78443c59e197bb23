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
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace gravsweep::results {

struct BedData {
  std::vector<double> position_m;      ///< N x 3, row-major
  std::vector<double> velocity_m_s;    ///< N x 3
  std::vector<double> omega_rad_s;     ///< N x 3
  std::vector<double> radius_m;        ///< N
  std::vector<double> mass_kg;         ///< N
  std::vector<std::uint8_t> material;  ///< N
  double container_diameter_m = 0;
  double wall_height_m = 0;
  double fill_height_m = 0;
  double surface_height_m = 0;
  double gravity_m_s2 = 0;
  double time_s = 0;
  std::string bed_key_json;   ///< canonical JSON of what defines the bed
  std::string scenario_json;  ///< the scenario that prepared it
  std::string report_json;    ///< preparation report (grains, settling, bulk density, wall time)
  std::string code_version;

  [[nodiscard]] std::size_t size() const { return radius_m.size(); }
};

inline constexpr const char* kBedFormat = "gravsweep-bed";
inline constexpr long long kBedFormatVersion = 1;

/// Writes under a temporary name, then renames into place.
void write_bed(const std::filesystem::path& path, const BedData& bed);
/// Reads and checks the layout; throws h5::H5Error naming the file and the missing piece, and
/// ConfigError naming the file and the grain whose radius, mass (density), position, velocity or
/// spin lies outside any real bed's range (a corrupt number).
BedData read_bed(const std::filesystem::path& path);

}  // namespace gravsweep::results
