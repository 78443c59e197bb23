// The translation of a validated scenario into the engine's inputs (ScenarioParams): the system
// configurations of the bed and the drop, the bed and projectile specs, the drop's stop and
// at-rest criteria; validation and the rules across fields are in scenario_spec.cpp.
#include "scheduler/pipeline/scenario_spec.h"

#include <fmt/format.h>

#include <cmath>
#include <random>
#include <string>

#include "engine/scenario/paper_params.h"
#include "scheduler/queue/canonical.h"
#include "scheduler/pipeline/scenario_config.h"

// Typed JSON (nlohmann's from_json, found by argument-dependent lookup) for the engine's material
// types, read from a scenario the schema has validated (schemas/scenario.schema.json: /materials,
// /contact/pairs, /contact/composition). The engine stays free of JSON; these live beside the one
// place that reads them.
namespace gravsweep {

void from_json(const nlohmann::json& j, Material& m) {
  m.young_modulus_Pa = j.at("young_modulus_Pa");
  m.poisson_ratio = j.at("poisson_ratio");
  m.cor_normal = j.at("cor_normal");
  m.cor_tangential = j.at("cor_tangential");
  m.mu_static = j.at("mu_static");
  m.mu_rolling = j.at("mu_rolling");
  m.mu_twisting = j.at("mu_twisting");
  m.kn_N_m = j.at("kn_N_m");
  m.kt_N_m = j.at("kt_N_m");
  m.shape_beta = j.at("shape_beta");
}

void from_json(const nlohmann::json& j, PairOverride& o) {
  auto opt = [&](const char* k, std::optional<double>& f) {
    if (j.contains(k)) f = j.at(k).get<double>();
  };
  opt("cor_normal", o.cor_normal);
  opt("cor_tangential", o.cor_tangential);
  opt("mu_static", o.mu_static);
  opt("mu_rolling", o.mu_rolling);
  opt("mu_twisting", o.mu_twisting);
  opt("kn_N_m", o.kn_N_m);
  opt("kt_N_m", o.kt_N_m);
  opt("shape_beta", o.shape_beta);
}

/// An unknown name is an error, never a silent fallback to the first value (scenario_params may be
/// handed a scenario the schema did not see).
void from_json(const nlohmann::json& j, Composition& c) {
  const std::string name = j.get<std::string>();
  if (name == "explicit_pair")
    c = Composition::explicit_pair;
  else if (name == "chrono_min")
    c = Composition::chrono_min;
  else
    throw ConfigError(
        fmt::format("/contact/composition: found \"{}\", expected \"explicit_pair\" or \"chrono_min\"", name));
}

}  // namespace gravsweep

namespace gravsweep::pipeline {

using nlohmann::json;

namespace {

/// The materials a bed is prepared with: /bed/materials when given, else /materials (the drop's).
const json& bed_materials(const json& s) {
  const json& b = s.at("bed");
  return b.contains("materials") ? b.at("materials") : s.at("materials");
}

}  // namespace

namespace detail {

/// The system configuration common to preparation and drop (dt and gravity set by the caller),
/// with the body materials `m` (/materials for the drop, bed_materials() for the preparation).
SystemConfig base_config(const json& s, const json& m) {
  SystemConfig c;
  const json& ct = s.at("contact");
  c.contact_law = ct.at("law");
  c.rolling_model = ct.at("rolling_model");
  c.integrator = s.at("integrator");
  c.composition = ct.at("composition").get<Composition>();
  c.options.clamp_normal = ct.at("clamp_normal");
  c.materials.assign(3, Material{});
  for (const auto& [index, name] : {std::pair{kGrainMaterial, "grain"}, std::pair{kWallMaterial, "wall"},
                                    std::pair{kProjectileMaterial, "projectile"}}) {
    c.materials[index] = m.at(name).get<Material>();
    c.materials[index].name = name;
  }
  const std::pair<const char*, std::pair<int, int>> pairs[] = {
      {"grain-grain", {kGrainMaterial, kGrainMaterial}},
      {"grain-wall", {kGrainMaterial, kWallMaterial}},
      {"grain-projectile", {kGrainMaterial, kProjectileMaterial}},
      {"projectile-wall", {kWallMaterial, kProjectileMaterial}}};
  for (const auto& [name, key] : pairs)
    if (ct.at("pairs").contains(name) && !ct.at("pairs").at(name).empty())
      c.pair_overrides[key] = ct.at("pairs").at(name).get<PairOverride>();
  c.threads = s.at("threads");
  return c;
}

}  // namespace detail

using detail::base_config;

DropStop drop_stop(const json& stop, double gravity_m_s2, double projectile_diameter_m) {
  const double speed_scale_m_s = std::sqrt(gravity_m_s2 * projectile_diameter_m);
  const double time_scale_s = std::sqrt(projectile_diameter_m / gravity_m_s2);
  auto pick = [&](const char* absolute, const char* scaled, double scale) {
    return stop.contains(absolute) ? stop.at(absolute).get<double>() : stop.at(scaled).get<double>() * scale;
  };
  DropStop out;
  out.speed_m_s = pick("speed_m_s", "speed_sqrt_gD", speed_scale_m_s);
  out.hold_time_s = pick("hold_time_s", "hold_time_sqrt_D_g", time_scale_s);
  out.max_time_s = pick("max_time_s", "max_time_sqrt_D_g", time_scale_s);
  return out;
}

double drop_min_roll_vel_m_s(const json& s) {
  const json& r = s.at("rolling_threshold");
  if (r.contains("min_roll_vel_m_s")) return r.at("min_roll_vel_m_s");
  return r.at("min_roll_vel_at_9_81_m_s").get<double>() *
         std::sqrt(s.at("gravity_m_s2").get<double>() / kEarthGravity_m_s2);
}

double reference_impact_speed_m_s(const json& s) {
  const json& p = s.at("projectile");
  if (p.contains("impact_speed_m_s")) return p.at("impact_speed_m_s");
  const double g = s.at("gravity_m_s2");
  const double h = std::max(p.at("drop_height_m").get<double>(), s["/grains/diameter_m"_json_pointer].get<double>());
  return std::sqrt(2 * g * h);
}

std::uint64_t site_seed(const json& s) {
  const json& pj = s.at("projectile");
  const auto seed = pj.at("seed").get<std::uint64_t>();
  if (pj.at("site_draw") == "seed") return seed;
  // The sweep point: everything that makes one drop differ from another except the engine's
  // settings (threads, dt, output, stop), so thread counts and outputs never move the site.
  const json point{{"gravity_m_s2", s.at("gravity_m_s2")},
                   {"projectile", pj},
                   {"grains", s.at("grains")},
                   {"container", s.at("container")}};
  const std::string hex = queue::sha256_hex(queue::canonical_json(point));
  return std::stoull(hex.substr(0, 16), nullptr, 16);
}

/// /container, /grains and /bed as the engine's BedSpec (`settle_g`: the gravity the bed settles
/// at; relaxed at `gravity_m_s2` when they differ).
BedSpec bed_spec_of(const json& s, double settle_g, double gravity_m_s2) {
  BedSpec b;
  b.container.diameter_m = s["/container/diameter_m"_json_pointer];
  b.grains.diameter_m = s["/grains/diameter_m"_json_pointer];
  b.grains.diameter_spread_m = s["/grains/diameter_spread_m"_json_pointer];
  b.grains.density_kg_m3 = s["/grains/density_kg_m3"_json_pointer];
  b.fill_height_m = s["/container/fill_height_m"_json_pointer];
  const json& bj = s.at("bed");
  b.overfill_factor = bj.at("overfill_factor");
  b.packing_fraction = bj.at("packing_fraction");
  // Optional and without a default, so that the bed keys of beds placed on the default lattice stay.
  b.placement_spacing_diameters = bj.value("placement_spacing_diameters", kLatticeSpacingDiameters);
  b.seed = bj.at("seed").get<std::uint64_t>();
  b.settle.rms_speed_m_s = bj["/settle/rms_speed_m_s"_json_pointer];
  b.settle.max_speed_m_s = bj["/settle/max_speed_m_s"_json_pointer];
  b.settle.max_time_s = bj["/settle/max_time_s"_json_pointer];
  b.settle.check_interval_s = bj["/settle/check_interval_s"_json_pointer];
  b.settle.min_roll_vel_m_s = bj["/settle/min_roll_vel_m_s"_json_pointer];
  // Optional and without a default (0 = off), so that the bed keys of existing beds stay.
  b.settle.plateau_window_s = bj.at("settle").value("plateau_window_s", 0.0);
  b.relax_time_s = bj.at("relax_time_s");
  b.grain_material = kGrainMaterial;
  b.wall_material = kWallMaterial;
  if (settle_g != gravity_m_s2) b.relax_gravity_m_s2 = Vec3(0, 0, -gravity_m_s2);
  b.gravity_ramp_s = bj.at("gravity_ramp_s");
  if (bj.contains("quench")) {
    b.quench_interval_s = bj["/quench/interval_s"_json_pointer];
    b.quench_time_s = bj["/quench/time_s"_json_pointer];
  }
  // Optional and without a default (0 = none), so that the bed keys of existing beds stay.
  b.surface_relax_s = bj.value("surface_relax_s", 0.0);
  b.lid = bj.value("lid", false);  // optional, no default: the bed keys of open beds stay
  if (bj.contains("time_step")) {  // dt_max_s >= dt_s: check_size_and_steps
    b.time_step.steps_per_contact = bj["/time_step/steps_per_contact"_json_pointer];
    b.time_step.dt_max_s = bj["/time_step/dt_max_s"_json_pointer];
    b.pour_time_step = bj.at("time_step").value("pour", false);  // optional, no default: bed keys stay
  }
  return b;
}

/// /projectile as the engine's ProjectileSpec, its random start drawn from the point's site seed.
ProjectileSpec projectile_spec_of(const json& s, double grain_diameter_m) {
  const json& pj = s.at("projectile");
  ProjectileSpec ps;
  ps.diameter_m = pj.at("diameter_m");
  ps.mass_kg = pj.at("mass_kg");
  ps.material = kProjectileMaterial;
  if (pj.contains("impact_speed_m_s")) ps.impact_speed_m_s = pj.at("impact_speed_m_s").get<double>();
  if (pj.contains("drop_height_m")) ps.drop_height_m = pj.at("drop_height_m").get<double>();
  ps.start_gap_m = pj.at("start_gap_m");
  // Random start (paper, Chrono repeats: radial and vertical start within two grain diameters).
  std::mt19937_64 rng(site_seed(s));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double lat = pj.at("lateral_offset_max_grain_diameters").get<double>() * grain_diameter_m;
  const double r = lat * std::sqrt(u(rng));
  const double phi = 2 * kPi * u(rng);
  ps.lateral_offset_x_m = r * std::cos(phi);
  ps.lateral_offset_y_m = r * std::sin(phi);
  ps.vertical_offset_m = pj.at("vertical_offset_max_grain_diameters").get<double>() * grain_diameter_m * u(rng);
  return ps;
}

ScenarioParams scenario_params(const json& s) {
  ScenarioParams out;
  out.gravity_m_s2 = s.at("gravity_m_s2");
  const double settle_g = s["/bed/settle_gravity_m_s2"_json_pointer].get<double>() > 0
                              ? s["/bed/settle_gravity_m_s2"_json_pointer].get<double>()
                              : out.gravity_m_s2;
  out.bed_config = base_config(s, bed_materials(s));
  out.bed_config.dt_s = s["/bed/dt_s"_json_pointer];
  out.bed_config.gravity_m_s2 = Vec3(0, 0, -settle_g);
  out.drop_config = base_config(s, s.at("materials"));
  out.drop_config.dt_s = s.at("dt_s");
  out.drop_config.gravity_m_s2 = Vec3(0, 0, -out.gravity_m_s2);
  out.drop_config.options.min_roll_vel_m_s = drop_min_roll_vel_m_s(s);

  out.bed = bed_spec_of(s, settle_g, out.gravity_m_s2);
  out.projectile = projectile_spec_of(s, out.bed.grains.diameter_m);
  const ProjectileSpec& ps = out.projectile;
  out.stop = drop_stop(s.at("stop"), out.gravity_m_s2, ps.diameter_m);
  if (s.contains("time_step")) {  // dt_max_s >= dt_s: check_size_and_steps
    out.time_step.steps_per_contact = s["/time_step/steps_per_contact"_json_pointer];
    out.time_step.dt_max_s = s["/time_step/dt_max_s"_json_pointer];
    // Optional and without a default, so that the job ids of existing sweeps stay.
    out.time_step.speed_bound =
        speed_bound_named(s["/time_step"_json_pointer].value("speed_bound", "fastest_particle"));
  }
  out.at_rest.surface_speed_fraction = s["/at_rest/surface_speed_fraction"_json_pointer];
  out.at_rest.rms_speed_fraction = s["/at_rest/rms_speed_fraction"_json_pointer];
  out.at_rest.impact_speed_m_s = reference_impact_speed_m_s(s);
  if (s.at("at_rest").contains("surface_radius_D"))
    out.at_rest.surface_radius_D = s["/at_rest/surface_radius_D"_json_pointer];
  out.sample_rate_hz = s["/output/sample_rate_hz"_json_pointer];
  out.snapshot_interval_s = s["/output/snapshot_interval_s"_json_pointer];

  return out;
}

}  // namespace gravsweep::pipeline
