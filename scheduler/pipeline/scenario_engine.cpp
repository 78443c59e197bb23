// The engine's inputs made from the typed scenario (scenario.h) where they are used: the system
// configurations of the bed and the drop, the bed and projectile specs, the drop's stop and
// adaptive step, and the figures they are made from (site seed, rolling threshold, the impact
// speed the bed must be at rest for). Validation and the rules across fields are in
// scenario_spec.cpp.
#include "scheduler/pipeline/scenario.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <tuple>

#include "engine/core/error.h"
#include "engine/scenario/paper_params.h"
#include "scheduler/pipeline/scenario_config.h"
#include "scheduler/queue/canonical.h"

namespace gravsweep::pipeline {

using nlohmann::json;

namespace {

/// An unknown name is an error, never a silent fallback to the first value.
Composition composition_named(const std::string& name) {
  if (name == "explicit_pair") return Composition::explicit_pair;
  if (name == "chrono_min") return Composition::chrono_min;
  throw ConfigError(
      fmt::format("/contact/composition: found \"{}\", expected \"explicit_pair\" or \"chrono_min\"", name));
}

/// True when the override sets any coefficient (an empty one changes nothing and is not applied).
bool sets_any(const PairOverride& o) {
  return o.cor_normal || o.cor_tangential || o.mu_static || o.mu_rolling || o.mu_twisting || o.kn_N_m || o.kt_N_m ||
         o.shape_beta;
}

}  // namespace

namespace detail {

SystemConfig base_config(const ContactSettings& ct, const MaterialSet& m, const std::string& integrator, int threads) {
  SystemConfig c;
  c.contact_law = ct.law;
  c.rolling_model = ct.rolling_model;
  c.integrator = integrator;
  c.composition = composition_named(ct.composition);
  c.options.clamp_normal = ct.clamp_normal;
  c.materials.assign(3, Material{});
  for (const auto& [index, name, material] :
       {std::tuple{kGrainMaterial, "grain", &m.grain}, std::tuple{kWallMaterial, "wall", &m.wall},
        std::tuple{kProjectileMaterial, "projectile", &m.projectile}}) {
    c.materials[index] = *material;
    c.materials[index].name = name;
  }
  const std::pair<const char*, std::pair<int, int>> pairs[] = {
      {"grain-grain", {kGrainMaterial, kGrainMaterial}},
      {"grain-wall", {kGrainMaterial, kWallMaterial}},
      {"grain-projectile", {kGrainMaterial, kProjectileMaterial}},
      {"projectile-wall", {kWallMaterial, kProjectileMaterial}}};
  for (const auto& [name, key] : pairs)
    if (const auto it = ct.pairs.find(name); it != ct.pairs.end() && sets_any(it->second))
      c.pair_overrides[key] = it->second;
  c.threads = threads;
  return c;
}

}  // namespace detail

using detail::base_config;

DropStop StopSettings::drop_stop(double gravity_m_s2, double projectile_diameter_m) const {
  const double speed_scale_m_s = std::sqrt(gravity_m_s2 * projectile_diameter_m);
  const double time_scale_s = std::sqrt(projectile_diameter_m / gravity_m_s2);
  DropStop out;
  out.speed_m_s = speed_m_s.value_or(speed_sqrt_gD * speed_scale_m_s);
  out.hold_time_s = hold_time_s.value_or(hold_time_sqrt_D_g * time_scale_s);
  out.max_time_s = max_time_s.value_or(max_time_sqrt_D_g * time_scale_s);
  return out;
}

double Scenario::settle_gravity_m_s2() const {
  return bed.settle_gravity_m_s2 > 0 ? bed.settle_gravity_m_s2 : gravity_m_s2;
}

double Scenario::drop_min_roll_vel_m_s() const {
  const RollingThresholdSettings& r = rolling_threshold;
  return r.min_roll_vel_m_s.value_or(r.min_roll_vel_at_9_81_m_s * std::sqrt(gravity_m_s2 / kEarthGravity_m_s2));
}

double Scenario::reference_impact_speed_m_s() const {
  if (projectile.impact_speed_m_s) return *projectile.impact_speed_m_s;
  const double h = std::max(projectile.drop_height_m.value_or(0.0), grains.diameter_m);
  return std::sqrt(2 * gravity_m_s2 * h);
}

std::uint64_t Scenario::site_seed() const {
  if (projectile.site_draw == "seed") return projectile.seed;
  // The sweep point: everything that makes one drop differ from another except the engine's
  // settings (threads, dt, output, stop), so thread counts and outputs never move the site. Its
  // canonical text is that of the scenario as validated (canonical JSON spells 2.0 as 2).
  const json all = to_json(*this);
  const json point{{"gravity_m_s2", all.at("gravity_m_s2")},
                   {"projectile", all.at("projectile")},
                   {"grains", all.at("grains")},
                   {"container", all.at("container")}};
  const std::string hex = queue::sha256_hex(queue::canonical_json(point));
  return std::stoull(hex.substr(0, 16), nullptr, 16);
}

SystemConfig Scenario::bed_config() const {
  SystemConfig c = base_config(contact, bed_materials(), integrator, threads);
  c.dt_s = bed.dt_s;
  c.gravity_m_s2 = Vec3(0, 0, -settle_gravity_m_s2());
  return c;
}

SystemConfig Scenario::drop_config() const {
  SystemConfig c = base_config(contact, materials, integrator, threads);
  c.dt_s = dt_s;
  c.gravity_m_s2 = Vec3(0, 0, -gravity_m_s2);
  c.options.min_roll_vel_m_s = drop_min_roll_vel_m_s();
  return c;
}

BedSpec Scenario::bed_spec() const {
  BedSpec b;
  const BedSettings& bs = bed;
  b.container.diameter_m = container.diameter_m;
  b.grains = grains;
  b.fill_height_m = container.fill_height_m;
  b.overfill_factor = bs.overfill_factor;
  b.packing_fraction = bs.packing_fraction;
  // Optional fields without a default keep the bed keys of the beds made before them.
  b.placement_spacing_diameters = bs.placement_spacing_diameters.value_or(kLatticeSpacingDiameters);
  b.seed = bs.seed;
  b.settle.rms_speed_m_s = bs.settle.rms_speed_m_s;
  b.settle.max_speed_m_s = bs.settle.max_speed_m_s;
  b.settle.max_time_s = bs.settle.max_time_s;
  b.settle.check_interval_s = bs.settle.check_interval_s;
  b.settle.min_roll_vel_m_s = bs.settle.min_roll_vel_m_s;
  b.settle.plateau_window_s = bs.settle.plateau_window_s.value_or(0.0);  // 0: off
  b.relax_time_s = bs.relax_time_s;
  b.grain_material = kGrainMaterial;
  b.wall_material = kWallMaterial;
  if (settle_gravity_m_s2() != gravity_m_s2) b.relax_gravity_m_s2 = Vec3(0, 0, -gravity_m_s2);
  b.gravity_ramp_s = bs.gravity_ramp_s;
  if (bs.quench) {
    b.quench_interval_s = bs.quench->interval_s;
    b.quench_time_s = bs.quench->time_s;
  }
  b.surface_relax_s = bs.surface_relax_s.value_or(0.0);  // 0: none
  b.lid = bs.lid.value_or(false);
  if (bs.time_step) {  // dt_max_s >= dt_s: check_size_and_steps
    b.time_step.steps_per_contact = bs.time_step->steps_per_contact;
    b.time_step.dt_max_s = bs.time_step->dt_max_s;
    b.pour_time_step = bs.time_step->pour.value_or(false);
  }
  return b;
}

ProjectileSpec Scenario::projectile_spec() const {
  const ProjectileSettings& pj = projectile;
  const double grain_diameter_m = grains.diameter_m;
  ProjectileSpec ps;
  ps.diameter_m = pj.diameter_m;
  ps.mass_kg = pj.mass_kg;
  ps.material = kProjectileMaterial;
  ps.impact_speed_m_s = pj.impact_speed_m_s;
  ps.drop_height_m = pj.drop_height_m;
  ps.start_gap_m = pj.start_gap_m;
  // Random start (paper, Chrono repeats: radial and vertical start within two grain diameters).
  std::mt19937_64 rng(site_seed());
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double lat = pj.lateral_offset_max_grain_diameters * grain_diameter_m;
  const double r = lat * std::sqrt(u(rng));
  const double phi = 2 * kPi * u(rng);
  ps.lateral_offset_x_m = r * std::cos(phi);
  ps.lateral_offset_y_m = r * std::sin(phi);
  ps.vertical_offset_m = pj.vertical_offset_max_grain_diameters * grain_diameter_m * u(rng);
  return ps;
}

AdaptiveStep Scenario::drop_time_step() const {
  AdaptiveStep a;
  if (!time_step) return a;  // off
  a.steps_per_contact = time_step->steps_per_contact;
  a.dt_max_s = time_step->dt_max_s;  // >= dt_s: check_size_and_steps
  // Optional and without a default, so that the job ids of existing sweeps stay.
  a.speed_bound = speed_bound_named(time_step->speed_bound.value_or("fastest_particle"));
  return a;
}

}  // namespace gravsweep::pipeline
