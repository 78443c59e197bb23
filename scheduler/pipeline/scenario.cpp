// The typed scenario read from and written to JSON: a field table per struct of numbers and texts
// (results/io/record_fields.h), the optional sub-objects and the integers by hand. Every key of
// the schema has its place here: a key read nowhere is an error, so a field added to the schema
// without a place in the record is found by the first scenario that sets it.
#include "scheduler/pipeline/scenario.h"

#include <fmt/format.h>

#include <iterator>
#include <set>
#include <stdexcept>
#include <vector>

#include "results/io/record_fields.h"

namespace gravsweep::pipeline {

using nlohmann::json;
using results::RecordField;

namespace {

template <class R>
using Fields = std::vector<RecordField<R>>;

const Fields<ContainerSettings>& container_fields() {
  static const Fields<ContainerSettings> f = {{"diameter_m", "m", &ContainerSettings::diameter_m},
                                              {"fill_height_m", "m", &ContainerSettings::fill_height_m}};
  return f;
}

/// /grains, read straight into the engine's GrainSpec.
const Fields<GrainSpec>& grain_fields() {
  static const Fields<GrainSpec> f = {{"diameter_m", "m", &GrainSpec::diameter_m},
                                      {"diameter_spread_m", "m", &GrainSpec::diameter_spread_m},
                                      {"density_kg_m3", "kg/m3", &GrainSpec::density_kg_m3}};
  return f;
}

/// A body's material as the scenario gives it (its density is /grains' or the projectile's mass).
const Fields<Material>& material_fields() {
  static const Fields<Material> f = {{"young_modulus_Pa", "Pa", &Material::young_modulus_Pa},
                                     {"poisson_ratio", "1", &Material::poisson_ratio},
                                     {"cor_normal", "1", &Material::cor_normal},
                                     {"cor_tangential", "1", &Material::cor_tangential},
                                     {"mu_static", "1", &Material::mu_static},
                                     {"mu_rolling", "1", &Material::mu_rolling},
                                     {"mu_twisting", "1", &Material::mu_twisting},
                                     {"kn_N_m", "N/m", &Material::kn_N_m},
                                     {"kt_N_m", "N/m", &Material::kt_N_m},
                                     {"shape_beta", "1", &Material::shape_beta}};
  return f;
}

const Fields<PairOverride>& pair_fields() {
  static const Fields<PairOverride> f = {{"cor_normal", "1", nullptr, &PairOverride::cor_normal},
                                         {"cor_tangential", "1", nullptr, &PairOverride::cor_tangential},
                                         {"mu_static", "1", nullptr, &PairOverride::mu_static},
                                         {"mu_rolling", "1", nullptr, &PairOverride::mu_rolling},
                                         {"mu_twisting", "1", nullptr, &PairOverride::mu_twisting},
                                         {"kn_N_m", "N/m", nullptr, &PairOverride::kn_N_m},
                                         {"kt_N_m", "N/m", nullptr, &PairOverride::kt_N_m},
                                         {"shape_beta", "1", nullptr, &PairOverride::shape_beta}};
  return f;
}

const Fields<SettleSettings>& settle_fields() {
  static const Fields<SettleSettings> f = {{"rms_speed_m_s", "m/s", &SettleSettings::rms_speed_m_s},
                                           {"max_speed_m_s", "m/s", &SettleSettings::max_speed_m_s},
                                           {"max_time_s", "s", &SettleSettings::max_time_s},
                                           {"check_interval_s", "s", &SettleSettings::check_interval_s},
                                           {"plateau_window_s", "s", nullptr, &SettleSettings::plateau_window_s},
                                           {"min_roll_vel_m_s", "m/s", &SettleSettings::min_roll_vel_m_s}};
  return f;
}

const Fields<QuenchSettings>& quench_fields() {
  static const Fields<QuenchSettings> f = {{"interval_s", "s", &QuenchSettings::interval_s},
                                           {"time_s", "s", &QuenchSettings::time_s}};
  return f;
}

/// /bed's numbers; its seed, flags and sub-objects are read by hand.
const Fields<BedSettings>& bed_fields() {
  static const Fields<BedSettings> f = {
      {"dt_s", "s", &BedSettings::dt_s},
      {"overfill_factor", "1", &BedSettings::overfill_factor},
      {"packing_fraction", "1", &BedSettings::packing_fraction},
      {"placement_spacing_diameters", "1", nullptr, &BedSettings::placement_spacing_diameters},
      {"settle_gravity_m_s2", "m/s2", &BedSettings::settle_gravity_m_s2},
      {"gravity_ramp_s", "s", &BedSettings::gravity_ramp_s},
      {"relax_time_s", "s", &BedSettings::relax_time_s},
      {"surface_relax_s", "s", nullptr, &BedSettings::surface_relax_s}};
  return f;
}

const Fields<ProjectileSettings>& projectile_fields() {
  using P = ProjectileSettings;
  static const Fields<P> f = {{"diameter_m", "m", &P::diameter_m},
                              {"mass_kg", "kg", &P::mass_kg},
                              {"impact_speed_m_s", "m/s", nullptr, &P::impact_speed_m_s},
                              {"drop_height_m", "m", nullptr, &P::drop_height_m},
                              {"start_gap_m", "m", &P::start_gap_m},
                              {"lateral_offset_max_grain_diameters", "1", &P::lateral_offset_max_grain_diameters},
                              {"vertical_offset_max_grain_diameters", "1", &P::vertical_offset_max_grain_diameters},
                              {"site_draw", "", nullptr, nullptr, nullptr, nullptr, &P::site_draw}};
  return f;
}

const Fields<OutputSettings>& output_fields() {
  using O = OutputSettings;
  static const Fields<O> f = {{"sample_rate_hz", "Hz", &O::sample_rate_hz},
                              {"filter_cutoff_hz", "Hz", &O::filter_cutoff_hz},
                              {"end_threshold_g", "1", &O::end_threshold_g},
                              {"end_speed_fraction", "1", &O::end_speed_fraction},
                              {"snapshot_interval_s", "s", &O::snapshot_interval_s}};
  return f;
}

const Fields<StopSettings>& stop_fields() {
  using S = StopSettings;
  static const Fields<S> f = {
      {"speed_m_s", "m/s", nullptr, &S::speed_m_s},   {"speed_sqrt_gD", "1", &S::speed_sqrt_gD},
      {"hold_time_s", "s", nullptr, &S::hold_time_s}, {"hold_time_sqrt_D_g", "1", &S::hold_time_sqrt_D_g},
      {"max_time_s", "s", nullptr, &S::max_time_s},   {"max_time_sqrt_D_g", "1", &S::max_time_sqrt_D_g}};
  return f;
}

const Fields<TimeStepSettings>& time_step_fields() {
  static const Fields<TimeStepSettings> f = {{"steps_per_contact", "1", &TimeStepSettings::steps_per_contact},
                                             {"dt_max_s", "s", &TimeStepSettings::dt_max_s}};
  return f;
}

const Fields<AtRestSettings>& at_rest_fields() {
  static const Fields<AtRestSettings> f = {{"surface_speed_fraction", "1", &AtRestSettings::surface_speed_fraction},
                                           {"rms_speed_fraction", "1", &AtRestSettings::rms_speed_fraction},
                                           {"surface_radius_D", "1", nullptr, &AtRestSettings::surface_radius_D}};
  return f;
}

const Fields<RollingThresholdSettings>& rolling_threshold_fields() {
  using R = RollingThresholdSettings;
  static const Fields<R> f = {{"min_roll_vel_m_s", "m/s", nullptr, &R::min_roll_vel_m_s},
                              {"min_roll_vel_at_9_81_m_s", "m/s", &R::min_roll_vel_at_9_81_m_s}};
  return f;
}

// ---- reading --------------------------------------------------------------------------------

/// Throws naming `where` when j is not an object or holds a key outside `known`.
void require_known(const json& j, const std::set<std::string>& known, const std::string& where) {
  if (!j.is_object()) throw std::runtime_error(fmt::format("{}: expected an object, found {}", where, j.type_name()));
  for (const auto& [k, v] : j.items())
    if (!known.contains(k))
      throw std::runtime_error(fmt::format("{}/{}: a key the scenario record does not have", where, k));
}

/// The keys of a field table and `extra`.
template <class R>
std::set<std::string> keys_of(const Fields<R>& table, std::initializer_list<const char*> extra = {}) {
  std::set<std::string> known(extra.begin(), extra.end());
  for (const auto& f : table) known.insert(f.key);
  return known;
}

/// The leaf record at `where` (an object of table's keys and no other).
template <class R>
R leaf(const json& j, const Fields<R>& table, const std::string& where) {
  require_known(j, keys_of(table), where);
  return results::record_of_json(j, table, where);
}

template <class T>
T typed(const json& j, const char* key, const std::string& where) {
  try {
    return j.at(key).get<T>();
  } catch (const json::exception& e) {
    throw std::runtime_error(fmt::format("{}/{}: {}", where, key, e.what()));
  }
}

template <class T>
std::optional<T> maybe(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key)) return std::nullopt;
  return typed<T>(j, key, where);
}

}  // namespace

MaterialSet material_set_of(const json& j, const std::string& where) {
  require_known(j, {"grain", "wall", "projectile"}, where);
  MaterialSet m;
  m.grain = leaf(j.at("grain"), material_fields(), where + "/grain");
  m.wall = leaf(j.at("wall"), material_fields(), where + "/wall");
  m.projectile = leaf(j.at("projectile"), material_fields(), where + "/projectile");
  return m;
}

ContactSettings contact_settings_of(const json& j) {
  const std::string where = "/contact";
  require_known(j, {"law", "rolling_model", "composition", "clamp_normal", "pairs"}, where);
  ContactSettings c;
  c.law = typed<std::string>(j, "law", where);
  c.rolling_model = typed<std::string>(j, "rolling_model", where);
  c.composition = typed<std::string>(j, "composition", where);
  c.clamp_normal = typed<bool>(j, "clamp_normal", where);
  for (const auto& [name, o] : j.at("pairs").items()) c.pairs[name] = leaf(o, pair_fields(), where + "/pairs/" + name);
  return c;
}

StopSettings stop_settings_of(const json& j) { return leaf(j, stop_fields(), "/stop"); }

namespace {

BedSettings bed_settings(const json& j) {
  const std::string where = "/bed";
  require_known(j, keys_of(bed_fields(), {"seed", "lid", "settle", "quench", "time_step", "materials"}), where);
  BedSettings b = results::record_of_json(j, bed_fields(), where);
  b.seed = typed<std::uint64_t>(j, "seed", where);
  b.lid = maybe<bool>(j, "lid", where);
  b.settle = leaf(j.at("settle"), settle_fields(), where + "/settle");
  if (j.contains("quench")) b.quench = leaf(j.at("quench"), quench_fields(), where + "/quench");
  if (j.contains("time_step")) {
    const json& t = j.at("time_step");
    require_known(t, {"steps_per_contact", "dt_max_s", "pour"}, where + "/time_step");
    b.time_step = BedTimeStepSettings{typed<double>(t, "steps_per_contact", where + "/time_step"),
                                      typed<double>(t, "dt_max_s", where + "/time_step"),
                                      maybe<bool>(t, "pour", where + "/time_step")};
  }
  if (j.contains("materials")) b.materials = material_set_of(j.at("materials"), where + "/materials");
  return b;
}

ProjectileSettings projectile_settings(const json& j) {
  require_known(j, keys_of(projectile_fields(), {"seed"}), "/projectile");
  ProjectileSettings p = results::record_of_json(j, projectile_fields(), "/projectile");
  p.seed = typed<std::uint64_t>(j, "seed", "/projectile");
  return p;
}

std::optional<TimeStepSettings> time_step_settings(const json& s) {
  if (!s.contains("time_step")) return std::nullopt;
  const json& j = s.at("time_step");
  require_known(j, keys_of(time_step_fields(), {"speed_bound"}), "/time_step");
  TimeStepSettings t = results::record_of_json(j, time_step_fields(), "/time_step");
  t.speed_bound = maybe<std::string>(j, "speed_bound", "/time_step");
  return t;
}

// ---- writing --------------------------------------------------------------------------------

/// The leaf record's JSON, an absent optional number omitted (the table writes it as null; a
/// scenario holds no nulls).
template <class R>
json leaf_json(const R& r, const Fields<R>& table) {
  json j = results::record_json(r, table);
  for (auto it = j.begin(); it != j.end();) it = it->is_null() ? j.erase(it) : std::next(it);
  return j;
}

json material_set_json(const MaterialSet& m) {
  return {{"grain", leaf_json(m.grain, material_fields())},
          {"wall", leaf_json(m.wall, material_fields())},
          {"projectile", leaf_json(m.projectile, material_fields())}};
}

template <class T>
void put(json& j, const char* key, const std::optional<T>& v) {
  if (v) j[key] = *v;
}

json bed_json(const BedSettings& b) {
  json j = leaf_json(b, bed_fields());
  j["seed"] = b.seed;
  put(j, "lid", b.lid);
  j["settle"] = leaf_json(b.settle, settle_fields());
  if (b.quench) j["quench"] = leaf_json(*b.quench, quench_fields());
  if (b.time_step) {
    j["time_step"] = {{"steps_per_contact", b.time_step->steps_per_contact}, {"dt_max_s", b.time_step->dt_max_s}};
    put(j["time_step"], "pour", b.time_step->pour);
  }
  if (b.materials) j["materials"] = material_set_json(*b.materials);
  return j;
}

json contact_json(const ContactSettings& c) {
  json pairs = json::object();
  for (const auto& [name, o] : c.pairs) pairs[name] = leaf_json(o, pair_fields());
  return {{"law", c.law},
          {"rolling_model", c.rolling_model},
          {"composition", c.composition},
          {"clamp_normal", c.clamp_normal},
          {"pairs", pairs}};
}

}  // namespace

Scenario scenario_of(const json& s) {
  require_known(s,
                {"$schema", "name", "description", "defaults_version", "gravity_m_s2", "container", "grains",
                 "materials", "contact", "integrator", "dt_s", "threads", "bed", "projectile", "output", "stop",
                 "time_step", "at_rest", "rolling_threshold"},
                "");
  Scenario r;
  r.schema_uri = maybe<std::string>(s, "$schema", "");
  r.name = typed<std::string>(s, "name", "");
  r.description = typed<std::string>(s, "description", "");
  r.defaults_version = maybe<int>(s, "defaults_version", "");
  r.gravity_m_s2 = typed<double>(s, "gravity_m_s2", "");
  r.container = leaf(s.at("container"), container_fields(), "/container");
  r.grains = leaf(s.at("grains"), grain_fields(), "/grains");
  r.materials = material_set_of(s.at("materials"), "/materials");
  r.contact = contact_settings_of(s.at("contact"));
  r.integrator = typed<std::string>(s, "integrator", "");
  r.dt_s = typed<double>(s, "dt_s", "");
  r.threads = typed<int>(s, "threads", "");
  r.bed = bed_settings(s.at("bed"));
  r.projectile = projectile_settings(s.at("projectile"));
  r.output = leaf(s.at("output"), output_fields(), "/output");
  r.stop = stop_settings_of(s.at("stop"));
  r.time_step = time_step_settings(s);
  r.at_rest = leaf(s.at("at_rest"), at_rest_fields(), "/at_rest");
  r.rolling_threshold = leaf(s.at("rolling_threshold"), rolling_threshold_fields(), "/rolling_threshold");
  return r;
}

json to_json(const Scenario& r) {
  json s;
  put(s, "$schema", r.schema_uri);
  s["name"] = r.name;
  s["description"] = r.description;
  put(s, "defaults_version", r.defaults_version);
  s["gravity_m_s2"] = r.gravity_m_s2;
  s["container"] = leaf_json(r.container, container_fields());
  s["grains"] = leaf_json(r.grains, grain_fields());
  s["materials"] = material_set_json(r.materials);
  s["contact"] = contact_json(r.contact);
  s["integrator"] = r.integrator;
  s["dt_s"] = r.dt_s;
  s["threads"] = r.threads;
  s["bed"] = bed_json(r.bed);
  json projectile = leaf_json(r.projectile, projectile_fields());
  projectile["seed"] = r.projectile.seed;
  s["projectile"] = projectile;
  s["output"] = leaf_json(r.output, output_fields());
  s["stop"] = leaf_json(r.stop, stop_fields());
  if (r.time_step) {
    s["time_step"] = leaf_json(*r.time_step, time_step_fields());
    put(s["time_step"], "speed_bound", r.time_step->speed_bound);
  }
  s["at_rest"] = leaf_json(r.at_rest, at_rest_fields());
  s["rolling_threshold"] = leaf_json(r.rolling_threshold, rolling_threshold_fields());
  return s;
}

}  // namespace gravsweep::pipeline
