// The translation of a typed scenario (scenario.h) into the engine's inputs (ScenarioParams): the
// system configurations of the bed and the drop, the bed and projectile specs, the drop's stop and
// at-rest criteria; validation and the rules across fields are in scenario_spec.cpp.
#include "scheduler/pipeline/scenario_spec.h"

#include <fmt/format.h>

#include <cmath>
#include <random>
#include <tuple>
#include <string>

#include "engine/scenario/paper_params.h"
#include "scheduler/queue/canonical.h"
#include "scheduler/pipeline/scenario_config.h"

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

DropStop drop_stop(const StopSettings& stop, double gravity_m_s2, double projectile_diameter_m) {
  const double speed_scale_m_s = std::sqrt(gravity_m_s2 * projectile_diameter_m);
  const double time_scale_s = std::sqrt(projectile_diameter_m / gravity_m_s2);
  DropStop out;
  out.speed_m_s = stop.speed_m_s.value_or(stop.speed_sqrt_gD * speed_scale_m_s);
  out.hold_time_s = stop.hold_time_s.value_or(stop.hold_time_sqrt_D_g * time_scale_s);
  out.max_time_s = stop.max_time_s.value_or(stop.max_time_sqrt_D_g * time_scale_s);
  return out;
}

double drop_min_roll_vel_m_s(const Scenario& s) {
  const RollingThresholdSettings& r = s.rolling_threshold;
  return r.min_roll_vel_m_s.value_or(r.min_roll_vel_at_9_81_m_s * std::sqrt(s.gravity_m_s2 / kEarthGravity_m_s2));
}

double reference_impact_speed_m_s(const Scenario& s) {
  if (s.projectile.impact_speed_m_s) return *s.projectile.impact_speed_m_s;
  const double h = std::max(s.projectile.drop_height_m.value_or(0.0), s.grains.diameter_m);
  return std::sqrt(2 * s.gravity_m_s2 * h);
}

std::uint64_t site_seed(const Scenario& s) {
  if (s.projectile.site_draw == "seed") return s.projectile.seed;
  // The sweep point: everything that makes one drop differ from another except the engine's
  // settings (threads, dt, output, stop), so thread counts and outputs never move the site. Its
  // canonical text is that of the scenario as validated (canonical JSON spells 2.0 as 2).
  const json all = to_json(s);
  const json point{{"gravity_m_s2", all.at("gravity_m_s2")},
                   {"projectile", all.at("projectile")},
                   {"grains", all.at("grains")},
                   {"container", all.at("container")}};
  const std::string hex = queue::sha256_hex(queue::canonical_json(point));
  return std::stoull(hex.substr(0, 16), nullptr, 16);
}

namespace {

/// /container, /grains and /bed as the engine's BedSpec (`settle_g`: the gravity the bed settles
/// at; relaxed at the drop's gravity when they differ).
BedSpec bed_spec_of(const Scenario& s, double settle_g) {
  BedSpec b;
  const BedSettings& bs = s.bed;
  b.container.diameter_m = s.container.diameter_m;
  b.grains.diameter_m = s.grains.diameter_m;
  b.grains.diameter_spread_m = s.grains.diameter_spread_m;
  b.grains.density_kg_m3 = s.grains.density_kg_m3;
  b.fill_height_m = s.container.fill_height_m;
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
  if (settle_g != s.gravity_m_s2) b.relax_gravity_m_s2 = Vec3(0, 0, -s.gravity_m_s2);
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

/// /projectile as the engine's ProjectileSpec, its random start drawn from the point's site seed.
ProjectileSpec projectile_spec_of(const Scenario& s) {
  const ProjectileSettings& pj = s.projectile;
  const double grain_diameter_m = s.grains.diameter_m;
  ProjectileSpec ps;
  ps.diameter_m = pj.diameter_m;
  ps.mass_kg = pj.mass_kg;
  ps.material = kProjectileMaterial;
  ps.impact_speed_m_s = pj.impact_speed_m_s;
  ps.drop_height_m = pj.drop_height_m;
  ps.start_gap_m = pj.start_gap_m;
  // Random start (paper, Chrono repeats: radial and vertical start within two grain diameters).
  std::mt19937_64 rng(site_seed(s));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double lat = pj.lateral_offset_max_grain_diameters * grain_diameter_m;
  const double r = lat * std::sqrt(u(rng));
  const double phi = 2 * kPi * u(rng);
  ps.lateral_offset_x_m = r * std::cos(phi);
  ps.lateral_offset_y_m = r * std::sin(phi);
  ps.vertical_offset_m = pj.vertical_offset_max_grain_diameters * grain_diameter_m * u(rng);
  return ps;
}

}  // namespace

ScenarioParams scenario_params(const Scenario& s) {
  ScenarioParams out;
  out.gravity_m_s2 = s.gravity_m_s2;
  const double settle_g = s.bed.settle_gravity_m_s2 > 0 ? s.bed.settle_gravity_m_s2 : s.gravity_m_s2;
  out.bed_config = base_config(s.contact, s.bed_materials(), s.integrator, s.threads);
  out.bed_config.dt_s = s.bed.dt_s;
  out.bed_config.gravity_m_s2 = Vec3(0, 0, -settle_g);
  out.drop_config = base_config(s.contact, s.materials, s.integrator, s.threads);
  out.drop_config.dt_s = s.dt_s;
  out.drop_config.gravity_m_s2 = Vec3(0, 0, -s.gravity_m_s2);
  out.drop_config.options.min_roll_vel_m_s = drop_min_roll_vel_m_s(s);

  out.bed = bed_spec_of(s, settle_g);
  out.projectile = projectile_spec_of(s);
  out.stop = drop_stop(s.stop, s.gravity_m_s2, s.projectile.diameter_m);
  if (s.time_step) {  // dt_max_s >= dt_s: check_size_and_steps
    out.time_step.steps_per_contact = s.time_step->steps_per_contact;
    out.time_step.dt_max_s = s.time_step->dt_max_s;
    // Optional and without a default, so that the job ids of existing sweeps stay.
    out.time_step.speed_bound = speed_bound_named(s.time_step->speed_bound.value_or("fastest_particle"));
  }
  out.at_rest.surface_speed_fraction = s.at_rest.surface_speed_fraction;
  out.at_rest.rms_speed_fraction = s.at_rest.rms_speed_fraction;
  out.at_rest.impact_speed_m_s = reference_impact_speed_m_s(s);
  out.at_rest.surface_radius_D = s.at_rest.surface_radius_D.value_or(0.0);  // 0: the whole surface
  out.sample_rate_hz = s.output.sample_rate_hz;
  out.snapshot_interval_s = s.output.snapshot_interval_s;
  return out;
}

ScenarioParams scenario_params(const json& validated) { return scenario_params(scenario_of(validated)); }

}  // namespace gravsweep::pipeline
