// The impact scenario as a typed record (schemas/scenario.schema.json): what validate_scenario
// returns, read once into structs, so that every reader takes fields by name and type instead of
// by JSON pointer. It is the one stored form of the scenario's facts: the engine's inputs
// (SystemConfig, BedSpec, ProjectileSpec, DropStop, AdaptiveStep) are not kept beside it but made
// from it where they are used, by its member functions (scenario_engine.cpp), and where a
// sub-record's fields are the engine's own (/grains: GrainSpec) the record holds the engine struct.
// The defaults live in one place, the schema (filled by validate_scenario, with the versioned ones
// of scenario_defaults.h); a field the schema gives no default is a std::optional here, absent
// when the scenario omits it. Identities are computed from canonical JSON, never from the
// record's fields one by one: job ids from the point as written and bed keys from the validated
// JSON; the site seed (site_seed()) from to_json(record), which gives the validated JSON back
// exactly (tested on every committed scenario and sweep point), so its canonical text, and the
// seed, are the validated scenario's.
#pragma once
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "engine/core/material.h"
#include "engine/scenario/bed.h"
#include "engine/scenario/impact.h"
#include "engine/scenario/time_step.h"
#include "engine/system/system.h"

namespace gravsweep::pipeline {

/// /container: the cylinder and how deep the bed fills it (m).
struct ContainerSettings {
  double diameter_m = 0;
  double fill_height_m = 0;
};

/// /materials (and /bed/materials): the three bodies' materials.
struct MaterialSet {
  Material grain, wall, projectile;
};

/// /contact: the law, the rolling model, how two materials combine and per-pair overrides (keyed
/// "grain-grain", "grain-wall", "grain-projectile", "projectile-wall"; an empty override kept).
struct ContactSettings {
  std::string law;
  std::string rolling_model;
  std::string composition;  ///< "explicit_pair" or "chrono_min"
  bool clamp_normal = false;
  std::map<std::string, PairOverride> pairs;
};

/// /bed/settle: when a poured bed is at rest.
struct SettleSettings {
  double rms_speed_m_s = 0;
  double max_speed_m_s = 0;
  double max_time_s = 0;
  double check_interval_s = 0;
  std::optional<double> plateau_window_s;  ///< the creep-floor stop; absent: off
  double min_roll_vel_m_s = 0;
};

/// /bed/quench: grains moving against the force on them are stopped every interval_s for time_s.
struct QuenchSettings {
  double interval_s = 0;
  double time_s = 0;
};

/// /bed/time_step: the adaptive step of a bed's phases at its drop's gravity.
struct BedTimeStepSettings {
  double steps_per_contact = 0;
  double dt_max_s = 0;
  std::optional<bool> pour;  ///< also while pouring; absent: no
};

/// /bed: how the bed is poured, settled, flattened and relaxed.
struct BedSettings {
  std::uint64_t seed = 1;
  double dt_s = 0;
  double overfill_factor = 0;
  double packing_fraction = 0;
  std::optional<bool> lid;
  std::optional<double> placement_spacing_diameters;
  double settle_gravity_m_s2 = 0;  ///< 0: the drop's gravity
  double gravity_ramp_s = 0;
  SettleSettings settle;
  double relax_time_s = 0;
  std::optional<QuenchSettings> quench;
  std::optional<double> surface_relax_s;
  std::optional<BedTimeStepSettings> time_step;
  std::optional<MaterialSet> materials;  ///< absent: the drop's /materials
};

/// /projectile: the sphere, its impact (exactly one of speed and drop height) and its random start.
struct ProjectileSettings {
  double diameter_m = 0;
  double mass_kg = 0;
  std::optional<double> impact_speed_m_s;
  std::optional<double> drop_height_m;
  double start_gap_m = 0;
  double lateral_offset_max_grain_diameters = 0;
  double vertical_offset_max_grain_diameters = 0;
  std::uint64_t seed = 1;
  std::string site_draw;  ///< "point" or "seed"
};

/// /output: the trace's sampling and the paper's processing settings at 1 g.
struct OutputSettings {
  double sample_rate_hz = 0;
  double filter_cutoff_hz = 0;
  double end_threshold_g = 0;
  double end_speed_fraction = 0;
  double snapshot_interval_s = 0;  ///< grain snapshots; 0: none
};

/// /stop: when the drop ends. Each quantity absolute when given, else in the drop's scales
/// (speed in sqrt(g D), time in sqrt(D/g)); drop_stop() turns it into the engine's DropStop.
struct StopSettings {
  std::optional<double> speed_m_s;
  double speed_sqrt_gD = 0;
  std::optional<double> hold_time_s;
  double hold_time_sqrt_D_g = 0;
  std::optional<double> max_time_s;
  double max_time_sqrt_D_g = 0;

  /// The engine's stop criterion of a drop at this gravity of a projectile of this diameter.
  [[nodiscard]] DropStop drop_stop(double gravity_m_s2, double projectile_diameter_m) const;
};

/// /time_step: the drop's adaptive step (engine/scenario/time_step.h).
struct TimeStepSettings {
  double steps_per_contact = 0;
  double dt_max_s = 0;
  std::optional<std::string> speed_bound;  ///< absent: "fastest_particle"
};

/// /at_rest: the bed's residual grain speeds a drop accepts, relative to its impact speed.
struct AtRestSettings {
  double surface_speed_fraction = 0;
  double rms_speed_fraction = 0;
  std::optional<double> surface_radius_D;  ///< absent: the whole surface
};

/// /rolling_threshold: the drop's rolling-friction regularisation speed.
struct RollingThresholdSettings {
  std::optional<double> min_roll_vel_m_s;
  double min_roll_vel_at_9_81_m_s = 0;
};

/// A validated impact scenario, field for field.
struct Scenario {
  std::optional<std::string> schema_uri;  ///< /$schema, for editors
  std::string name;
  std::string description;
  std::optional<int> defaults_version;
  double gravity_m_s2 = 0;
  ContainerSettings container;
  GrainSpec grains;  ///< /grains: the engine's own struct (diameter, spread +/-, density)
  MaterialSet materials;
  ContactSettings contact;
  std::string integrator;
  double dt_s = 0;
  int threads = 0;  ///< 0: all cores
  BedSettings bed;
  ProjectileSettings projectile;
  OutputSettings output;
  StopSettings stop;
  std::optional<TimeStepSettings> time_step;
  AtRestSettings at_rest;
  RollingThresholdSettings rolling_threshold;

  /// The materials the bed is prepared with: /bed/materials when given, else /materials.
  [[nodiscard]] const MaterialSet& bed_materials() const { return bed.materials ? *bed.materials : materials; }

  // The engine's inputs, made from the record at the point of use (scenario_engine.cpp); a caller
  // that runs with another thread count sets SystemConfig::threads on its copy.

  /// The system a bed is prepared in: /contact, bed_materials(), /integrator, /threads, /bed/dt_s
  /// and settle_gravity_m_s2().
  [[nodiscard]] SystemConfig bed_config() const;
  /// The system of the drop: /contact, /materials, /integrator, /threads, /dt_s, /gravity_m_s2 and
  /// the drop's rolling threshold (drop_min_roll_vel_m_s()).
  [[nodiscard]] SystemConfig drop_config() const;
  /// /container, /grains and /bed as the engine's bed preparation (relaxed at the drop's gravity
  /// when it settles at another).
  [[nodiscard]] BedSpec bed_spec() const;
  /// /projectile, its random start drawn from site_seed() (the same start at every call).
  [[nodiscard]] ProjectileSpec projectile_spec() const;
  /// /stop in the drop's scales.
  [[nodiscard]] DropStop drop_stop() const { return stop.drop_stop(gravity_m_s2, projectile.diameter_m); }
  /// /time_step, the drop's adaptive step (off when absent; its speed bound twice the fastest
  /// particle's speed when it names none).
  [[nodiscard]] AdaptiveStep drop_time_step() const;
  /// The gravity the bed is poured and settled at: /bed/settle_gravity_m_s2, or the drop's when 0.
  [[nodiscard]] double settle_gravity_m_s2() const;
  /// The drop's rolling-friction regularisation speed (/rolling_threshold): Chrono's value at
  /// 9.81 m/s2 scaled by sqrt(g / 9.81), or the absolute value given.
  [[nodiscard]] double drop_min_roll_vel_m_s() const;
  /// The impact speed the bed must be at rest for (/at_rest): impact_speed_m_s, or for a release
  /// from rest sqrt(2 g h) with h the drop height (at least one grain diameter).
  [[nodiscard]] double reference_impact_speed_m_s() const;
  /// The seed of the drop's random start: /projectile/seed mixed with the sweep point (gravity,
  /// projectile incl. its speed or drop height, grains, container) unless site_draw is "seed".
  [[nodiscard]] std::uint64_t site_seed() const;
};

/// The record of a scenario validate_scenario returned (every default filled). A key the record
/// does not know or a value of the wrong type is a std::runtime_error naming its JSON pointer
/// (the schema refuses both first: this guards against a scenario handed over unvalidated).
Scenario scenario_of(const nlohmann::json& validated);
/// The sub-records the scenario's validation reads before the whole scenario is known sound:
/// /materials (or /bed/materials), /contact and /stop.
MaterialSet material_set_of(const nlohmann::json& materials, const std::string& where = "/materials");
ContactSettings contact_settings_of(const nlohmann::json& contact);
StopSettings stop_settings_of(const nlohmann::json& stop);
/// The scenario as JSON: equal (as JSON values) to the validated scenario it was read from, with
/// an absent optional field omitted.
nlohmann::json to_json(const Scenario& s);

}  // namespace gravsweep::pipeline
