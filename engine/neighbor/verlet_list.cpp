#include "engine/neighbor/verlet_list.h"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "engine/core/error.h"

namespace gravsweep {

namespace {
constexpr std::size_t kMaxCells = std::size_t{1} << 26;
/// Rows per chunk of the list build's parallel pass (one buffer per chunk).
constexpr std::size_t kBuildChunk = 256;

/// The particles sorted into cell-listed (small) and scanned (large) ones, with the small ones'
/// bounding box and largest radius.
struct Classified {
  double large_threshold_m = 0;  ///< radius above which a particle is large
  double r_small_max_m = 0;      ///< 0: no small particle
  std::vector<std::uint32_t> large;
  Vec3 lo = Vec3::Constant(kInf), hi = Vec3::Constant(-kInf);
  [[nodiscard]] bool have_small() const { return r_small_max_m > 0; }
};

Classified classify(const Particles& p) {
  Classified c;
  double r_min = kInf;
  for (double r : p.radius_m) r_min = std::min(r_min, r);
  c.large_threshold_m = VerletList::kLargeRadiusFactor * r_min;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.radius_m[i] > c.large_threshold_m) {
      c.large.push_back(static_cast<std::uint32_t>(i));
      continue;
    }
    c.r_small_max_m = std::max(c.r_small_max_m, p.radius_m[i]);
    c.lo = c.lo.cwiseMin(p.position_m[i]);
    c.hi = c.hi.cwiseMax(p.position_m[i]);
  }
  return c;
}

/// Cubic cells of side 2 r_small_max + skin over the small particles' bounding box, numbered x
/// fastest, then y, then z.
struct CellGrid {
  Vec3 lo;
  double cell_m = 0;
  std::array<long, 3> dims{1, 1, 1};
  [[nodiscard]] std::size_t cells() const { return static_cast<std::size_t>(dims[0] * dims[1] * dims[2]); }
  [[nodiscard]] long coord(const Vec3& x, int a) const {
    return std::clamp<long>(static_cast<long>((x[a] - lo[a]) / cell_m), 0, dims[a] - 1);
  }
  [[nodiscard]] long index(long x, long y, long z) const { return (z * dims[1] + y) * dims[0] + x; }
  [[nodiscard]] long index_of(const Vec3& x) const { return index(coord(x, 0), coord(x, 1), coord(x, 2)); }
};

CellGrid make_grid(const Classified& c, double skin_m) {
  CellGrid g;
  g.lo = c.lo;
  g.cell_m = 2 * c.r_small_max_m + skin_m;
  if (!c.have_small()) return g;
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(c.lo[a]) || !std::isfinite(c.hi[a]))
      throw NumericalFailure("neighbour list: a particle position is not finite", -1, -1);
    g.dims[a] = std::max<long>(1, static_cast<long>((c.hi[a] - c.lo[a]) / g.cell_m) + 1);
  }
  if (static_cast<double>(g.dims[0]) * g.dims[1] * g.dims[2] > static_cast<double>(kMaxCells))
    throw NumericalFailure(fmt::format("neighbour list: particles spread over {:.3g} x {:.3g} x {:.3g} m, too many "
                                       "cells; a grain has probably left the container",
                                       c.hi[0] - c.lo[0], c.hi[1] - c.lo[1], c.hi[2] - c.lo[2]),
                           -1, -1);
  return g;
}

/// Counting sort of the small particles by cell: the particles of cell c are
/// cell_particles[cell_start[c] .. cell_start[c + 1]), in index order; particle_cell[i] is i's
/// cell (UINT32_MAX for a large particle).
void sort_into_cells(const Particles& p, const Classified& c, const CellGrid& g, std::vector<std::uint32_t>& cell_start,
                     std::vector<std::uint32_t>& cell_particles, std::vector<std::uint32_t>& particle_cell) {
  const std::size_t n = p.size(), n_cells = g.cells();
  particle_cell.assign(n, UINT32_MAX);
  cell_start.assign(n_cells + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (p.radius_m[i] > c.large_threshold_m) continue;
    const long cell = g.index_of(p.position_m[i]);
    particle_cell[i] = static_cast<std::uint32_t>(cell);
    ++cell_start[cell + 1];
  }
  for (std::size_t k = 0; k < n_cells; ++k) cell_start[k + 1] += cell_start[k];
  cell_particles.resize(cell_start[n_cells]);
  std::vector<std::uint32_t> fill(cell_start.begin(), cell_start.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    if (particle_cell[i] != UINT32_MAX) cell_particles[fill[particle_cell[i]]++] = static_cast<std::uint32_t>(i);
}

/// Pairs (i < j) with a large particle, sorted: the cells its cutoff box covers are scanned;
/// large-large pairs by brute force.
std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs_with_large(
    const Particles& p, const Classified& c, const CellGrid& g, double skin_m,
    const std::vector<std::uint32_t>& cell_start, const std::vector<std::uint32_t>& cell_particles) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::uint32_t L : c.large) {
    const Vec3& xL = p.position_m[L];
    const double reach = p.radius_m[L] + c.r_small_max_m + skin_m;
    if (c.have_small()) {
      std::array<long, 3> c0{}, c1{};
      for (int a = 0; a < 3; ++a) {
        c0[a] = std::clamp<long>(static_cast<long>(std::floor((xL[a] - reach - g.lo[a]) / g.cell_m)), 0, g.dims[a] - 1);
        c1[a] = std::clamp<long>(static_cast<long>(std::floor((xL[a] + reach - g.lo[a]) / g.cell_m)), 0, g.dims[a] - 1);
      }
      for (long cz = c0[2]; cz <= c1[2]; ++cz)
        for (long cy = c0[1]; cy <= c1[1]; ++cy)
          for (long cx = c0[0]; cx <= c1[0]; ++cx) {
            const long cell = g.index(cx, cy, cz);
            for (std::uint32_t k = cell_start[cell]; k < cell_start[cell + 1]; ++k) {
              const std::uint32_t j = cell_particles[k];
              const double cut = p.radius_m[L] + p.radius_m[j] + skin_m;
              if ((p.position_m[j] - xL).squaredNorm() < cut * cut) pairs.emplace_back(std::min(L, j), std::max(L, j));
            }
          }
    }
    for (std::uint32_t M : c.large) {
      if (M <= L) continue;
      const double cut = p.radius_m[L] + p.radius_m[M] + skin_m;
      if ((p.position_m[M] - xL).squaredNorm() < cut * cut) pairs.emplace_back(L, M);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

/// The small-small pairs of small particle i with j > i, from the 27 cells around i's.
struct SmallNeighbours {
  const Particles& p;
  const CellGrid& g;
  double skin_m;
  const std::vector<std::uint32_t>& cell_start;
  const std::vector<std::uint32_t>& cell_particles;
  template <class Emit>
  void operator()(std::size_t i, Emit&& emit) const {
    const Vec3& xi = p.position_m[i];
    const long cx = g.coord(xi, 0), cy = g.coord(xi, 1), cz = g.coord(xi, 2);
    for (long z = std::max(0L, cz - 1); z <= std::min(g.dims[2] - 1, cz + 1); ++z)
      for (long y = std::max(0L, cy - 1); y <= std::min(g.dims[1] - 1, cy + 1); ++y)
        for (long x = std::max(0L, cx - 1); x <= std::min(g.dims[0] - 1, cx + 1); ++x) {
          const long c = g.index(x, y, z);
          for (std::uint32_t k = cell_start[c]; k < cell_start[c + 1]; ++k) {
            const std::uint32_t j = cell_particles[k];
            if (j <= i) continue;
            const double cut = p.radius_m[i] + p.radius_m[j] + skin_m;
            if ((p.position_m[j] - xi).squaredNorm() < cut * cut) emit(j);
          }
        }
  }
};

/// Every row of the new list in one pass over the 27 neighbouring cells: rows in chunks of
/// kBuildChunk (dynamic: the density varies), each chunk written to its own buffer with a row's
/// large-particle pairs first and the row sorted; then the chunks copied into place after a
/// prefix sum of the row counts (count[i + 1]: row i's pairs). Searching the cells once instead of
/// twice (count, then fill) takes 4 % off the 0.1 m/s2 drop, which rebuilds every ~120 steps
/// (BENCHMARKS.md).
void list_rows(std::size_t n, const SmallNeighbours& small, const std::vector<std::uint32_t>& particle_cell,
               const std::vector<std::pair<std::uint32_t, std::uint32_t>>& large_pairs, int threads,
               std::vector<std::uint32_t>& new_offset, std::vector<std::uint32_t>& new_neighbor) {
  std::vector<std::uint32_t> count(n + 1, 0);  // count[i + 1]: row i's pairs
  const std::size_t n_chunks = (n + kBuildChunk - 1) / kBuildChunk;
  std::vector<std::vector<std::uint32_t>> chunk_neighbors(n_chunks);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (std::size_t ch = 0; ch < n_chunks; ++ch) {
    std::vector<std::uint32_t>& out = chunk_neighbors[ch];
    out.reserve(kBuildChunk * 8);  // a settled bed lists ~3.7 pairs a row
    const std::size_t i0 = ch * kBuildChunk, i1 = std::min(n, i0 + kBuildChunk);
    auto lp = std::lower_bound(large_pairs.begin(), large_pairs.end(),
                               std::pair<std::uint32_t, std::uint32_t>{static_cast<std::uint32_t>(i0), 0});
    for (std::size_t i = i0; i < i1; ++i) {
      const std::size_t row_start = out.size();
      for (; lp != large_pairs.end() && lp->first == i; ++lp) out.push_back(lp->second);
      if (particle_cell[i] != UINT32_MAX) small(i, [&](std::uint32_t j) { out.push_back(j); });
      std::sort(out.begin() + static_cast<std::ptrdiff_t>(row_start), out.end());
      count[i + 1] = static_cast<std::uint32_t>(out.size() - row_start);
    }
  }
  new_offset.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) new_offset[i + 1] = new_offset[i] + count[i + 1];
  new_neighbor.assign(new_offset[n], 0);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::size_t ch = 0; ch < n_chunks; ++ch)
    std::copy(chunk_neighbors[ch].begin(), chunk_neighbors[ch].end(),
              new_neighbor.begin() + new_offset[ch * kBuildChunk]);
}

}  // namespace

void VerletList::clear() {
  offset.clear();
  neighbor.clear();
  history.clear();
  frame_history.clear();
  work_offset.clear();
  position_at_build_.clear();
}

void VerletList::set_frame_history(bool keep) {
  keep_frame_ = keep;
  if (keep)
    frame_history.resize(history.size());
  else
    frame_history.clear();
}

std::size_t VerletList::bytes() const {
  return offset.capacity() * sizeof(std::uint32_t) + neighbor.capacity() * sizeof(std::uint32_t) +
         history.capacity() * sizeof(ContactHistory) + frame_history.capacity() * sizeof(FrameHistory) +
         position_at_build_.capacity() * sizeof(Vec3) + work_offset.capacity() * sizeof(std::uint32_t);
}

void VerletList::remap(const std::vector<long long>& new_index) {
  const std::size_t n_old = new_index.size();
  work_offset.clear();  // rows renumbered: the split weighs listed pairs until the next build
  if (offset.size() != n_old + 1) {
    clear();
    return;
  }
  std::vector<std::uint32_t> off{0};
  std::vector<std::uint32_t> nb;
  std::vector<ContactHistory> hist;
  std::vector<FrameHistory> frame;
  std::vector<Vec3> pos;
  nb.reserve(neighbor.size());
  hist.reserve(history.size());
  for (std::size_t i = 0; i < n_old; ++i) {
    if (new_index[i] < 0) continue;
    for (std::uint32_t k = offset[i]; k < offset[i + 1]; ++k) {
      const long long j = new_index[neighbor[k]];
      if (j < 0) continue;
      nb.push_back(static_cast<std::uint32_t>(j));  // order kept: new indices are monotone
      hist.push_back(history[k]);
      if (keep_frame_) frame.push_back(frame_history[k]);
    }
    off.push_back(static_cast<std::uint32_t>(nb.size()));
    pos.push_back(position_at_build_[i]);
  }
  offset = std::move(off);
  neighbor = std::move(nb);
  history = std::move(hist);
  frame_history = std::move(frame);
  position_at_build_ = std::move(pos);
}

void VerletList::extend(std::size_t n_total) {
  if (offset.empty() || n_total + 1 < offset.size()) {
    clear();
    return;
  }
  offset.resize(n_total + 1, offset.back());
  work_offset.clear();  // the split weighs listed pairs until the next build
  // NaN positions: needs_rebuild() sees every new particle as moved.
  position_at_build_.resize(n_total, Vec3::Constant(std::numeric_limits<double>::quiet_NaN()));
}

bool VerletList::needs_rebuild(const Particles& p) const { return max_displacement2_m2(p) > 0.25 * skin_m_ * skin_m_; }

double VerletList::max_displacement2_m2(const Particles& p) const {
  const std::size_t n = p.size();
  if (position_at_build_.size() != n || offset.size() != n + 1) return kInf;
  double moved2_m2 = 0;  // a NaN displacement is not a maximum (as a comparison with it is false)
#pragma omp parallel for schedule(static) reduction(max : moved2_m2)
  for (std::size_t i = 0; i < n; ++i)
    moved2_m2 = std::max(moved2_m2, (p.position_m[i] - position_at_build_[i]).squaredNorm());
  return moved2_m2;
}

void VerletList::build(const Particles& p, double skin_m, int threads) {
  const std::size_t n = p.size();
  skin_m_ = skin_m;
  ++builds_;
  if (n == 0) {
    clear();
    offset.assign(1, 0);
    return;
  }
  // The cell scratch lives for this build only (a settled bed rebuilds rarely: never in the 2,000
  // steps of `gravsweep bench`), so the list holds none of it between builds.
  const Classified c = classify(p);
  const CellGrid grid = make_grid(c, skin_m);
  std::vector<std::uint32_t> cell_start, cell_particles, particle_cell;
  sort_into_cells(p, c, grid, cell_start, cell_particles, particle_cell);
  const std::vector<std::pair<std::uint32_t, std::uint32_t>> large_pairs =
      pairs_with_large(p, c, grid, skin_m, cell_start, cell_particles);
  const SmallNeighbours small{p, grid, skin_m, cell_start, cell_particles};
  std::vector<std::uint32_t> new_offset, new_neighbor;
  list_rows(n, small, particle_cell, large_pairs, threads, new_offset, new_neighbor);
  carry_histories(std::move(new_offset), std::move(new_neighbor), threads);
  position_at_build_ = p.position_m;
}

void VerletList::carry_histories(std::vector<std::uint32_t> new_offset, std::vector<std::uint32_t> new_neighbor,
                                 int threads) {
  // Both lists are sorted by j within each i, so merge. The touching pairs carried over (active
  // histories) of row i are counted on the way, into touching_in_row[i + 1], for the work prefix below.
  const std::size_t n = new_offset.size() - 1;
  std::vector<ContactHistory> new_history(new_neighbor.size());
  std::vector<FrameHistory> new_frame(keep_frame_ ? new_neighbor.size() : 0);
  const bool have_old = offset.size() == n + 1;
  std::vector<std::uint32_t> touching_in_row(n + 1, 0u);
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
  for (std::size_t i = 0; i < n; ++i) {
    if (!have_old) continue;
    std::uint32_t a = offset[i];
    const std::uint32_t a_end = offset[i + 1];
    std::uint32_t touching = 0;
    for (std::uint32_t b = new_offset[i]; b < new_offset[i + 1] && a < a_end; ++b) {
      while (a < a_end && neighbor[a] < new_neighbor[b]) ++a;
      if (a < a_end && neighbor[a] == new_neighbor[b]) {
        new_history[b] = history[a];
        if (keep_frame_) new_frame[b] = frame_history[a];
        touching += history[a].active ? 1u : 0u;
      }
    }
    touching_in_row[i + 1] = touching;
  }
  offset = std::move(new_offset);
  neighbor = std::move(new_neighbor);
  history = std::move(new_history);
  frame_history = std::move(new_frame);
  work_offset.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    work_offset[i + 1] =
        work_offset[i] + (offset[i + 1] - offset[i]) + work.touching * touching_in_row[i + 1] + work.row;
}

void VerletList::add_wall_work(const std::vector<std::uint32_t>& codes, std::size_t walls) {
  if (walls == 0 || work_offset.empty()) return;
  const std::size_t n = work_offset.size() - 1;
  std::uint32_t extra = 0;
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (; k < codes.size() && codes[k] / walls <= i; ++k) extra += work.wall;
    work_offset[i + 1] += extra;
  }
}

}  // namespace gravsweep
