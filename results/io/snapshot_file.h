// DIR/snapshots.h5 + DIR/snapshots.xdmf: the grains and the projectile during a drop,
// written when the scenario's /output/snapshot_interval_s is > 0 (`gravsweep run` by default).
// ParaView and VisIt open the .xdmf directly: a temporal collection, each step a spatial
// collection of two point sets, "grains" and "projectile" (Polyvertex + attributes). Layout in
// results/io/README.md:
//
//   /                                   attrs: format = "gravsweep-snapshots", format_version,
//                                              interval_s, grains, snapshots, code_version
//   /grains/radius_m                    (N) float64 (constant during a drop, stored once)
//   /projectile/radius_m                (1)
//   /snapshots/t_s                      (K) float64, time since release
//   /snapshots/<k>/grains/position_m    (N, 3) float64, engine frame (z up, bottom at z = 0)
//   /snapshots/<k>/grains/velocity_m_s  (N, 3)
//   /snapshots/<k>/grains/omega_rad_s   (N, 3)
//   /snapshots/<k>/grains/contacts      (N) int32, grains and walls touching each grain
//   /snapshots/<k>/projectile/...       the same fields for the one projectile
//
// <k> is the snapshot number, six digits ("000000"); the grains are in the order of bed.h5.
#pragma once
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace gravsweep::results {

inline constexpr const char* kSnapshotFormat = "gravsweep-snapshots";
inline constexpr long long kSnapshotFormatVersion = 1;

/// One point set (the grains, or the projectile) at one instant.
struct SnapshotPoints {
  std::vector<double> position_m;      ///< n x 3, row-major
  std::vector<double> velocity_m_s;    ///< n x 3
  std::vector<double> omega_rad_s;     ///< n x 3
  std::vector<std::int32_t> contacts;  ///< n
  [[nodiscard]] std::size_t size() const { return contacts.size(); }
};

struct Snapshot {
  double t_s = 0;  ///< time since release
  SnapshotPoints grains, projectile;
};

/// Appends snapshots to DIR/snapshots.h5 written under a temporary name; finish() renames it into
/// place and writes the XDMF index next to it. Destroyed unfinished (an error, an interrupted
/// run), it removes the temporary file: a reader never sees half a file.
class SnapshotWriter {
 public:
  SnapshotWriter(const std::filesystem::path& h5_path, const std::vector<double>& grain_radius_m,
                 double projectile_radius_m, double interval_s, const std::string& code_version);
  ~SnapshotWriter();
  SnapshotWriter(const SnapshotWriter&) = delete;
  SnapshotWriter& operator=(const SnapshotWriter&) = delete;

  void append(const Snapshot& s);
  /// Closes the HDF5 file, renames it and writes <stem>.xdmf; returns the XDMF path.
  std::filesystem::path finish();
  [[nodiscard]] std::size_t count() const { return times_.size(); }
  /// Bytes of state one snapshot stores (positions, velocities, angular velocities, contacts).
  [[nodiscard]] std::size_t bytes_per_snapshot() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<double> times_;
};

/// Where the snapshots of a drop go: snapshots.h5 next to a trace.h5, else <trace stem>.snapshots.h5
/// (a campaign's traces/<job>.a<n>.h5 -> traces/<job>.a<n>.snapshots.h5).
std::filesystem::path snapshot_path_for(const std::filesystem::path& trace_path);

/// The XDMF index of a snapshots file (XDMF 2 syntax: ParaView's and VisIt's readers).
std::string snapshot_xdmf(const std::string& h5_file_name, std::size_t grains, const std::vector<double>& t_s);

/// Number of snapshots and their times; throws h5::H5Error when `path` is not a snapshots file.
std::vector<double> read_snapshot_times(const std::filesystem::path& path);
/// Snapshot k (k < 0: the last one).
Snapshot read_snapshot(const std::filesystem::path& path, long long k);

}  // namespace gravsweep::results
