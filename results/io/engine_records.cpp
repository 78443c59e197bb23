// Engine state <-> file records (see engine_records.h).
#include "results/io/engine_records.h"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>
#include <utility>

#include "engine/scenario/bed.h"
#include "engine/scenario/paper_params.h"

namespace gravsweep::results {

namespace {

/// The state of particles [begin, end) as a snapshot's point set.
void gather_points(const Particles& p, const std::vector<int>& contacts, std::size_t begin, std::size_t end,
                   SnapshotPoints& out) {
  for (std::size_t i = begin; i < end; ++i) {
    push_xyz(out.position_m, p.position_m[i]);
    push_xyz(out.velocity_m_s, p.velocity_m_s[i]);
    push_xyz(out.omega_rad_s, p.omega_rad_s[i]);
    out.contacts.push_back(contacts[i]);
  }
}

}  // namespace

BedFacts bed_facts_of(const System& sys) {
  BedFacts f;
  for (const auto& w : sys.walls)
    if (w.kind == WallKind::cylinder) f.wall_height_m = w.height_m;
  f.time_s = sys.time_s();
  return f;
}

BedFacts load_bed(System& sys, const std::filesystem::path& bed) {
  if (sys.particles.size() != 0)
    throw std::invalid_argument(fmt::format("bed {}: loaded into a system that already holds {} particles",
                                            bed.string(), sys.particles.size()));
  const BedFacts f = read_bed(bed, sys.particles);
  ContainerSpec cs;
  cs.diameter_m = f.container_diameter_m;
  add_container_walls(sys, cs, f.wall_height_m, kWallMaterial);
  return f;
}

TraceData take_trace_columns(DropResult& dr, double nominal_rate_hz) {
  DropSamples& s = dr.samples;
  const double sample_dt = s.size() > 1 ? s.t_s[1] - s.t_s[0] : 1.0 / nominal_rate_hz;
  TraceData td;
  td.raw.t_s = std::move(s.t_s);
  td.raw.depth_m = std::move(s.depth_m);
  td.raw.velocity_down_m_s = std::move(s.velocity_down_m_s);
  td.raw.accel_up_m_s2 = std::move(s.accel_up_m_s2);
  td.omega_rad_s = std::move(s.omega_rad_s);
  td.position_m = std::move(s.position_m);
  td.contacts = std::move(s.contacts);
  td.grain_kinetic_energy_J = std::move(s.grain_kinetic_energy_J);
  s = DropSamples{};  // taken: empty, not a moved-from state
  td.info.sample_rate_hz = 1.0 / sample_dt;
  td.release_height_m = dr.release_height_m;
  td.release_speed_m_s = dr.release_speed_m_s;
  td.stopped = dr.stopped;
  td.mark_contact_start();
  return td;
}

Snapshot snapshot_of(const System& sys, ParticleIndex projectile, double t_s) {
  const std::vector<int> c = sys.contact_counts();
  Snapshot sn;
  sn.t_s = t_s;
  gather_points(sys.particles, c, 0, projectile, sn.grains);
  gather_points(sys.particles, c, projectile, projectile + 1, sn.projectile);
  return sn;
}

BedSummary bed_summary_of(const System& sys, const BedReport& rep, const BedRestState& rest,
                          double at_rest_for_impacts_above_m_s) {
  BedSummary r;
  r.grains_placed = static_cast<long long>(rep.grains_placed);
  r.grains_kept = static_cast<long long>(rep.grains_kept);
  r.settled = rep.settled;
  r.settle_end = to_string(rep.settle_end);
  r.relax_end = to_string(rep.relax_end);
  r.settle_time_s = rep.settle_time_s;
  r.relax_time_s = rep.relax_time_s;
  r.quench_time_s = rep.quench_time_s;
  r.surface_relax_s = rep.surface_relax_s;
  r.rms_speed_m_s = rest.rms_speed_m_s;
  r.max_speed_m_s = rest.max_speed_m_s;
  r.max_surface_speed_m_s = rest.max_surface_speed_m_s;
  r.surface_grains = static_cast<long long>(rest.surface_grains);
  if (std::isfinite(at_rest_for_impacts_above_m_s)) r.at_rest_for_impacts_above_m_s = at_rest_for_impacts_above_m_s;
  r.surface_height_m = rep.surface_height_m;
  r.bulk_density_kg_m3 = rep.bulk_density_kg_m3;
  r.steps = sys.step_count();
  r.dt_s = sys.config().dt_s;
  r.threads = sys.threads();
  return r;
}

}  // namespace gravsweep::results
