// System::save_state / restore_state (system_state.h): the exact dynamic state of a run.
#include <fmt/format.h>

#include <stdexcept>

#include "engine/system/law_registry.h"
#include "engine/system/system.h"

namespace gravsweep {

SystemState System::save_state() const {
  SystemState s;
  s.particles = particles;
  s.time_s = time_s_;
  s.step = step_;
  s.gravity_m_s2 = config_.gravity_m_s2;
  s.domain = config_.domain;
  s.skin_m = config_.skin_m;
  s.list_offset = nlist_.offset;
  s.list_neighbor = nlist_.neighbor;
  s.list_work_offset = nlist_.work_offset;
  s.pair_history = nlist_.history;
  s.pair_frame_history = nlist_.frame_history;
  s.position_at_build_m = nlist_.build_positions();
  s.list_builds = nlist_.builds();
  s.wall_candidates = wall_candidates_;
  s.wall_history = wall_history_;
  s.wall_frame_history = wall_frame_history_;
  s.wall_count_at_build = wall_count_at_build_;
  s.initialized = initialized_;
  s.rebuild_due = rebuild_due_;
  s.have_step_checks = have_step_checks_;
  s.have_forces = have_forces_;
  s.stats = stats_;
  return s;
}

void System::check_restorable(const SystemState& s) const {
  const auto bad = [](const std::string& what) {
    throw std::invalid_argument("system state cannot be restored: " + what);
  };
  const Particles& p = s.particles;
  const std::size_t n = p.size();
  std::size_t arrays_differ = 0;
  p.for_each_array([&](const auto& v) { arrays_differ += v.size() != n ? 1 : 0; });
  if (arrays_differ > 0) bad(fmt::format("{} particle arrays do not hold {} particles", arrays_differ, n));
  if (!s.list_offset.empty() && s.list_offset.size() != n + 1)
    bad(fmt::format("the neighbour list has {} row offsets for {} particles", s.list_offset.size(), n));
  if (!s.list_offset.empty() && s.list_offset.back() != s.list_neighbor.size())
    bad(fmt::format("the neighbour list's last offset {} is not its {} pairs", s.list_offset.back(),
                    s.list_neighbor.size()));
  if (s.pair_history.size() != s.list_neighbor.size())
    bad(fmt::format("{} pair histories for {} listed pairs", s.pair_history.size(), s.list_neighbor.size()));
  for (std::uint32_t j : s.list_neighbor)
    if (j >= n) bad(fmt::format("a listed pair names particle {} of {}", j, n));
  const bool frames = uses_frame_history(config_.contact_law, config_.rolling_model);
  if (frames ? s.pair_frame_history.size() != s.pair_history.size() : !s.pair_frame_history.empty())
    bad(fmt::format("{} frame histories for {} pairs; the law '{}' with rolling '{}' {} them",
                    s.pair_frame_history.size(), s.pair_history.size(), config_.contact_law, config_.rolling_model,
                    frames ? "keeps" : "does not keep"));
  if (!s.list_work_offset.empty() && s.list_work_offset.size() != n + 1)
    bad(fmt::format("{} work offsets for {} particles", s.list_work_offset.size(), n));
  if (s.wall_count_at_build != walls.size() && !s.wall_candidates.empty())
    bad(fmt::format("the wall candidates were made with {} walls, this system has {}", s.wall_count_at_build,
                    walls.size()));
  if (s.wall_history.size() != s.wall_candidates.size() ||
      (frames && s.wall_frame_history.size() != s.wall_candidates.size()))
    bad(fmt::format("{} wall histories ({} frame histories) for {} wall candidates", s.wall_history.size(),
                    s.wall_frame_history.size(), s.wall_candidates.size()));
  for (std::uint32_t code : s.wall_candidates)
    if (walls.empty() || code / walls.size() >= n) bad(fmt::format("a wall candidate code {} is out of range", code));
  if (!(s.skin_m > 0)) bad(fmt::format("skin {} m, expected > 0", s.skin_m));
}

void System::restore_state(SystemState s) {
  check_restorable(s);
  invalidate();
  particles = std::move(s.particles);
  config_.gravity_m_s2 = s.gravity_m_s2;
  config_.domain = s.domain;
  config_.skin_m = s.skin_m;
  // Validation, pair table, integrator and thread buffers as for any run; the list this builds
  // is then replaced by the saved one (a rebuild at another step than the saved run's would
  // change which pairs are listed, the thread split and so the rounding).
  initialize();
  const bool frames = nlist_.keeps_frame_history();
  nlist_.offset = std::move(s.list_offset);
  nlist_.neighbor = std::move(s.list_neighbor);
  nlist_.work_offset = std::move(s.list_work_offset);
  nlist_.history = std::move(s.pair_history);
  nlist_.frame_history = std::move(s.pair_frame_history);
  nlist_.restore_build(std::move(s.position_at_build_m), s.skin_m, s.list_builds, frames);
  wall_candidates_ = std::move(s.wall_candidates);
  wall_history_ = std::move(s.wall_history);
  wall_frame_history_ = std::move(s.wall_frame_history);
  wall_count_at_build_ = static_cast<std::size_t>(s.wall_count_at_build);
  time_s_ = s.time_s;
  step_ = s.step;
  initialized_ = s.initialized;
  rebuild_due_ = s.rebuild_due;
  have_step_checks_ = s.have_step_checks;
  have_forces_ = s.have_forces;
  stats_ = s.stats;
}

}  // namespace gravsweep
