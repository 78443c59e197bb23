// Half Verlet neighbour list with a skin, built from a cell list. Each unordered pair (i, j), i < j,
// appears once, under i, with its ContactHistory stored beside it; histories survive rebuilds.
//
// Large particles (radius above kLargeRadiusFactor x the smallest radius, e.g. the 10 cm projectile
// among 1 cm grains) are kept out of the cells; their pairs come from scanning the cells their
// bounding box covers, so the cell size stays set by the grains (correct for any size ratio and for
// polydisperse grains).
#pragma once
#include <cstdint>
#include <vector>

#include "engine/contact/contact.h"
#include "engine/core/particles.h"

namespace gravsweep {

class VerletList {
 public:
  static constexpr double kLargeRadiusFactor = 2.5;

  /// Rebuilds the list for cutoff r_i + r_j + skin, carrying over histories of pairs still listed.
  void build(const Particles& p, double skin_m, int threads);

  /// True when some particle moved more than skin/2 since the last build (or nothing is built).
  [[nodiscard]] bool needs_rebuild(const Particles& p) const;

  [[nodiscard]] std::size_t pairs() const { return neighbor.size(); }
  [[nodiscard]] long long builds() const { return builds_; }
  [[nodiscard]] double skin_m() const { return skin_m_; }
  [[nodiscard]] std::size_t bytes() const;
  /// Positions at the last build (for the displacement check), or null when nothing is built.
  [[nodiscard]] const Vec3* positions_at_build(std::size_t n) const {
    return position_at_build_.size() == n && offset.size() == n + 1 ? position_at_build_.data() : nullptr;
  }

  // CSR storage: pairs of particle i are [offset[i], offset[i+1]).
  std::vector<std::uint32_t> offset;
  std::vector<std::uint32_t> neighbor;
  std::vector<ContactHistory> history;
  /// Beside history, only when frame histories are kept (set_frame_history); else empty.
  std::vector<FrameHistory> frame_history;

  /// Keep a FrameHistory per pair (the law or rolling model uses_frame_history). Switching it on
  /// gives every listed pair an empty record.
  void set_frame_history(bool keep);
  [[nodiscard]] bool keeps_frame_history() const { return keep_frame_; }

  /// Forget everything (after particles were added: indices changed).
  void clear();

  /// Particles were appended (indices of the others unchanged): the new ones get empty rows, so
  /// the next build() carries every existing history over. Needs a build before use.
  void extend(std::size_t n_total);

  /// Drops the removed particles and renumbers the rest (order kept), keeping the histories of
  /// the surviving pairs. new_index[i] is the new index of particle i, or -1 if removed.
  void remap(const std::vector<long long>& new_index);

 private:
  std::vector<Vec3> position_at_build_;
  double skin_m_ = 0;
  bool keep_frame_ = false;
  long long builds_ = 0;
  // Scratch of one build (released at its end).
  std::vector<std::uint32_t> cell_start_, cell_particles_, particle_cell_;
  std::vector<std::uint32_t> count_;
};

}  // namespace gravsweep
