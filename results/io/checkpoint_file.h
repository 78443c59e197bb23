// <files>/checkpoints/<job>.ckpt.h5: a running drop saved between two samples, or a bed's
// preparation between two intervals, so that the next attempt of the job continues it bit for bit
// (engine/system/system_state.h; DropState in engine/scenario/impact.h, BedState in
// engine/scenario/bed.h). Layout in results/io/README.md:
//
//   /                      attrs: format = "gravsweep-drop-checkpoint", format_version, kind
//                                 ("drop" or "bed"), code_version, identity (JSON: what job this
//                                 is), wall_time_s, resumes, position_s, content_hash (see below)
//   /system                attrs: time_s, step, skin_m, list_builds, wall_count_at_build, flags,
//                                 the last step's counters; datasets gravity_m_s2 (1, 3),
//                                 domain_m (0 or 2, 3: lo, hi)
//   /particles/<array>     every particle array, (N, 3) or (N), engine frame, SI units
//   /neighbor_list/...     offset, neighbor, work_offset (uint32), history, frame_history
//                          (compound records), position_at_build_m (N, 3)
//   /walls/...             candidates (uint32 codes particle * walls + wall), history, frame_history
//   /drop                  (kind drop) attrs: the loop's counters and release facts
//   /drop/samples/<column> (kind drop) the trace so far, DropSamples' columns, (T) or (T, 3)
//   /bed                   (kind bed) attrs: the stage, its cursor, the wall height and the
//                          report of the finished stages
//
// Integrity: content_hash is a 64-bit FNV-1a over 64-bit words of every value the reader uses
// (arrays, attributes, strings, in one fixed order), computed from memory on write and again from
// what was read; any changed word changes it. A file cut short fails to open or to read. Either
// way read_checkpoint throws CheckpointError naming the file: the caller discards it.
// Written atomically: a temporary sibling, fsynced, renamed, its folder fsynced.
#pragma once
#include <filesystem>
#include <stdexcept>
#include <string>
#include <variant>

#include "engine/scenario/bed.h"
#include "engine/scenario/impact.h"

namespace gravsweep::results {

inline constexpr const char* kCheckpointFormat = "gravsweep-drop-checkpoint";
inline constexpr long long kCheckpointFormatVersion = 3;

struct CheckpointData {
  /// The System's state and the loop's: a drop's, or a bed preparation's.
  std::variant<DropState, BedState> state;
  std::string identity_json;  ///< what job this is (the caller's: scenario, bed checksum, ...)
  std::string code_version;   ///< the build that wrote it
  double wall_time_s = 0;     ///< wall time the drop ran before this checkpoint, all attempts
  long long resumes = 0;      ///< how many times the run was continued from a checkpoint
  /// Simulated time where the run stands: a drop's since its release, a bed's since its start.
  double position_s = 0;

  [[nodiscard]] const char* kind() const { return std::holds_alternative<DropState>(state) ? "drop" : "bed"; }
  [[nodiscard]] const DropState* drop() const { return std::get_if<DropState>(&state); }
  [[nodiscard]] const BedState* bed() const { return std::get_if<BedState>(&state); }
};

/// A checkpoint file that cannot be used: missing, not HDF5, cut short, of another format, or
/// failing its content hash. The message names the file and what is wrong.
class CheckpointError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Writes `c` to `path` atomically (temporary sibling, fsync, rename, fsync of the folder).
void write_checkpoint(const std::filesystem::path& path, const CheckpointData& c);

/// Reads and verifies a checkpoint; throws CheckpointError (file named) when it cannot be used.
CheckpointData read_checkpoint(const std::filesystem::path& path);

}  // namespace gravsweep::results
