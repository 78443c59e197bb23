#include "scheduler/pipeline/scenario_spec.h"

#include <fmt/format.h>

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <string_view>

#include "engine/system/law_registry.h"
#include "engine/integrate/integrators.h"
#include "engine/scenario/paper_params.h"
#include "scheduler/sweep/spec.h"
#include "spec/problems.h"
#include "spec/schemas.h"
#include "spec/sha256.h"
#include "scheduler/pipeline/build_version.h"
#include "scheduler/pipeline/scenario_config.h"
#include "scheduler/pipeline/scenario_defaults.h"

namespace gravsweep::pipeline {

using nlohmann::json;

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

using spec::Checks;

/// Runs the engine's own parameter and time-step checks on a two-body system built from the
/// scenario (smallest grain, projectile, container walls), so errors surface before any work.
/// Runs when the fields the engine reads have no problem so far.
void engine_checks(const json& s, Checks& ck) {
  for (const char* p : {"/grains", "/projectile/diameter_m", "/projectile/mass_kg", "/container/diameter_m",
                        "/materials", "/contact", "/integrator", "/threads"})
    if (!ck.sound(p)) return;
  const double d = s["/grains/diameter_m"_json_pointer];
  const double spread = s["/grains/diameter_spread_m"_json_pointer];
  const double rho = s["/grains/density_kg_m3"_json_pointer];
  const double r_min = 0.5 * (d - spread);
  const ContactSettings contact = contact_settings_of(s.at("contact"));
  auto build = [&](double dt, const json& materials) {
    SystemConfig c = detail::base_config(contact, material_set_of(materials), s.at("integrator").get<std::string>(),
                                         s.at("threads").get<int>());
    c.dt_s = dt;
    System sys(c);
    sys.particles.add(Vec3(0, 0, 1), r_min, sphere_mass_kg(rho, 2 * r_min), kGrainMaterial, SizeClass::grain);
    const double Rp = 0.5 * s["/projectile/diameter_m"_json_pointer].get<double>();
    sys.particles.add(Vec3(0, 0, 3 + Rp), Rp, s["/projectile/mass_kg"_json_pointer], kProjectileMaterial,
                      SizeClass::projectile);
    ContainerSpec cs;
    cs.diameter_m = s["/container/diameter_m"_json_pointer];
    add_container_walls(sys, cs, 5.0, kWallMaterial);
    sys.initialize();
  };
  const char* bed_materials_pointer = s.at("bed").contains("materials") ? "/bed/materials" : "/materials";
  // Each time step is checked with the materials it is used with: the drop's and the bed's.
  const std::pair<const char*, const char*> uses[] = {{"/materials", "/dt_s"}, {bed_materials_pointer, "/bed/dt_s"}};
  for (const auto& [materials_pointer, dt_pointer] : uses) {
    if (!ck.sound(materials_pointer)) continue;
    const json& m = s[json::json_pointer(materials_pointer)];
    try {
      build(1e-12, m);
    } catch (const ConfigError& e) {
      ck.bad(materials_pointer, fmt::format("parameters the engine rejects ({})", e.what()),
             "materials and contact.pairs valid for the contact law");
      continue;
    }
    if (!ck.sound(dt_pointer)) continue;
    const double dt = s[json::json_pointer(dt_pointer)];
    try {
      build(dt, m);
    } catch (const ConfigError& e) {
      ck.bad(dt_pointer, fmt::format("{:g}", dt), fmt::format("a time step the contact law accepts ({})", e.what()));
    }
  }
}

/// engine_checks of scenarios that agree in every field it reads (and in which of them are sound)
/// runs once: it builds an engine System four times, and a sweep's points differ in impact speeds,
/// seeds and offsets, which it does not read (a sweep of 200,000 points built 800,000
/// Systems). The problems it found are kept (up to kEngineCheckMemo scenarios) and given again.
std::atomic<std::size_t> g_engine_check_runs{0};

void engine_checks_once(const json& s, Checks& ck) {
  std::vector<SpecProblem>& problems = ck.problems().list();
  constexpr std::size_t kEngineCheckMemo = 256;
  static const char* const kRead[] = {"/grains",
                                      "/projectile/diameter_m",
                                      "/projectile/mass_kg",
                                      "/container/diameter_m",
                                      "/materials",
                                      "/bed/materials",
                                      "/contact",
                                      "/integrator",
                                      "/threads",
                                      "/dt_s",
                                      "/bed/dt_s"};
  std::string k;
  for (const char* p : kRead) {
    const json::json_pointer jp(p);
    k += ck.sound(p) ? "1" : "0";
    k += s.contains(jp) ? s[jp].dump() : "-";
    k += '\n';
  }
  static std::mutex mutex;
  static std::map<std::string, std::vector<SpecProblem>> memo;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto it = memo.find(k); it != memo.end()) {
      problems.insert(problems.end(), it->second.begin(), it->second.end());
      return;
    }
  }
  const std::size_t before = problems.size();
  engine_checks(s, ck);
  g_engine_check_runs.fetch_add(1, std::memory_order_relaxed);
  const std::lock_guard<std::mutex> lock(mutex);
  if (memo.size() >= kEngineCheckMemo) memo.clear();
  memo.emplace(k, std::vector<SpecProblem>(problems.begin() + static_cast<std::ptrdiff_t>(before), problems.end()));
}

/// Grains of grain diameter d in a container Dc filled to H: random close packing (0.64) of the
/// fill, twice over for the lattice poured above it.
double grain_bound(double d, double Dc, double H) {
  return 2 * 0.64 * (0.25 * M_PI * Dc * Dc * H) / (M_PI / 6 * d * d * d);
}

/// Refuses a bed that cannot fit this machine's memory, and time steps too small to finish, before
/// any work. Grains: random close packing (0.64) of the fill, twice over for
/// the lattice poured above the fill height; ~2 kB per grain (state, Verlet pairs with contact
/// history, per-thread force buffers).
void check_size_and_steps(Checks& ck) {
  constexpr double kMinDt_s = 1e-9, kMaxSteps = 1e10;
  for (const char* p : {"/dt_s", "/bed/dt_s"})
    ck.run([&] {
      if (!(ck.num(p) >= kMinDt_s))
        ck.bad(p, fmt::format("{:g}", ck.num(p)),
               fmt::format("a time step of at least {:g} s (smaller steps never finish)", kMinDt_s));
    });
  ck.run([&] {
    const double d = ck.num("/grains/diameter_m"), Dc = ck.num("/container/diameter_m");
    const double H = ck.num("/container/fill_height_m");
    const double grains = grain_bound(d, Dc, H);
    const double need = grains * kBytesPerGrain, have = sweep::machine_memory_bytes();
    if (have > 0 && need > 0.8 * have)
      ck.bad("/container/fill_height_m",
             fmt::format("{:g} m of {:g} m grains in a {:g} m container: about {:.3g} grains, {:.3g} GB", H, d, Dc,
                         grains, need / 1e9),
             fmt::format("a bed that fits this machine's memory ({:.3g} GB; at most about {:.3g} grains)", have / 1e9,
                         0.8 * have / kBytesPerGrain));
  });
  for (const auto& [cap, floor] : {std::pair{"/time_step/dt_max_s", "/dt_s"}, {"/bed/time_step/dt_max_s", "/bed/dt_s"}})
    ck.run([&] {  // an adaptive step's cap is at least the fixed step it grows from
      if (ck.sound(cap) && !(ck.num(cap) >= ck.num(floor)))
        ck.bad(cap, fmt::format("{:g}", ck.num(cap)), fmt::format("at least {} ({:g} s)", floor, ck.num(floor)));
    });
  ck.run([&] {  // the creep-floor window: longer than a check, shorter than the cap it would shorten
    if (!ck.sound("/bed/settle/plateau_window_s")) return;
    const double w = ck.num("/bed/settle/plateau_window_s");
    const double check = ck.num("/bed/settle/check_interval_s"), cap = ck.num("/bed/settle/max_time_s");
    if (!(w >= check && w < cap))
      ck.bad("/bed/settle/plateau_window_s",
             fmt::format("a window of at least check_interval_s ({:g} s) and below max_time_s ({:g} s)", check, cap));
  });
  ck.run([&] {
    const double g = ck.num("/gravity_m_s2"), D = ck.num("/projectile/diameter_m");
    const double max_time_s = stop_settings_of(ck.at("/stop")).drop_stop(g, D).max_time_s;
    const double steps = max_time_s / ck.num("/dt_s");
    if (steps > kMaxSteps)
      ck.bad("/dt_s", fmt::format("{:g}", ck.num("/dt_s")),
             fmt::format("a time step giving at most {:g} steps over the stop's time cap ({:g} s)", kMaxSteps,
                         max_time_s));
  });
}

/// Names resolved by the engine's registries.
void check_names(Checks& ck) {
  auto one_of = [&](const char* p, const std::vector<std::string>& names, const char* what) {
    ck.run([&] {
      if (std::find(names.begin(), names.end(), ck.at(p).get<std::string>()) == names.end())
        ck.bad(p, fmt::format("one of the {} {}", what, join(names)));
    });
  };
  one_of("/contact/law", contact_law_names(), "contact laws");
  one_of("/contact/rolling_model", rolling_model_names(), "rolling models");
  std::vector<std::string> integrators;
  for (const auto& e : integrator_table()) integrators.emplace_back(e.name);
  one_of("/integrator", integrators, "integrators");
}

/// Grains, container and projectile fit together; the start of the drop is reachable.
void check_geometry(Checks& ck) {
  ck.run([&] {
    const double d = ck.num("/grains/diameter_m");
    if (!(ck.num("/grains/diameter_spread_m") < 0.5 * d))
      ck.bad("/grains/diameter_spread_m", fmt::format("a spread below half the grain diameter ({:g} m)", 0.5 * d));
  });
  ck.run([&] {
    const double d = ck.num("/grains/diameter_m");
    if (!(ck.num("/container/diameter_m") > 4 * d))
      ck.bad("/container/diameter_m", fmt::format("more than 4 grain diameters ({:g} m)", 4 * d));
  });
  ck.run([&] {
    const double d = ck.num("/grains/diameter_m");
    if (!(ck.num("/container/fill_height_m") >= 2 * d))
      ck.bad("/container/fill_height_m", fmt::format("at least 2 grain diameters ({:g} m)", 2 * d));
  });
  ck.run([&] {
    const double d = ck.num("/grains/diameter_m"), Dc = ck.num("/container/diameter_m");
    const double Dp = ck.num("/projectile/diameter_m");
    if (!(Dp + 2 * d < Dc)) {
      ck.bad("/projectile/diameter_m",
             fmt::format("a projectile narrower than the container minus two grains ({:g} m)", Dc - 2 * d));
      return;
    }
    const double lateral = ck.num("/projectile/lateral_offset_max_grain_diameters") * d;
    if (!(lateral + 0.5 * Dp + d < 0.5 * Dc))
      ck.bad("/projectile/lateral_offset_max_grain_diameters",
             fmt::format("an offset that keeps the projectile one grain from the side wall (at most {:g})",
                         (0.5 * Dc - 0.5 * Dp - d) / d));
  });
  ck.run([&] {
    const json& p = ck.at("/projectile");
    const bool has_speed = p.contains("impact_speed_m_s"), has_height = p.contains("drop_height_m");
    if (has_speed && has_height)
      ck.bad("/projectile/drop_height_m", "no drop height when impact_speed_m_s is given (give exactly one)");
    if (!has_speed && !has_height)
      ck.bad("/projectile/impact_speed_m_s", "an impact speed or a drop_height_m (give exactly one)");
    if (!has_speed || has_height) return;
    const double g = ck.num("/gravity_m_s2"), d = ck.num("/grains/diameter_m");
    const double v = ck.num("/projectile/impact_speed_m_s");
    const double gap = ck.num("/projectile/start_gap_m");
    const double vert = ck.num("/projectile/vertical_offset_max_grain_diameters") * d;
    if (!(v * v > 2 * g * gap))
      ck.bad("/projectile/start_gap_m",
             fmt::format("a gap below {:g} m: free fall over a larger gap already exceeds {} m/s", v * v / (2 * g), v));
    else if (!(v * v > 2 * g * (gap + vert)))
      ck.bad("/projectile/vertical_offset_max_grain_diameters",
             fmt::format("at most {:g}: free fall over a larger start height already exceeds {} m/s",
                         (v * v / (2 * g) - gap) / d, v));
  });
}

/// The output rate fits the time step, the filter the output rate.
void check_output(Checks& ck) {
  ck.run([&] {
    const double dt = ck.num("/dt_s");
    if (!(ck.num("/output/sample_rate_hz") * dt <= 1.0))
      ck.bad("/output/sample_rate_hz", fmt::format("at most 1/dt_s = {:g} Hz", 1.0 / dt));
  });
  ck.run([&] {
    const double rate = ck.num("/output/sample_rate_hz");
    if (!(ck.num("/output/filter_cutoff_hz") < 0.5 * rate))
      ck.bad("/output/filter_cutoff_hz", fmt::format("below the Nyquist frequency {:g} Hz", 0.5 * rate));
  });
}

}  // namespace

std::size_t engine_check_runs() { return g_engine_check_runs.load(std::memory_order_relaxed); }

json validate_scenario(const json& scenario, const std::string& source) {
  json s = scenario;
  spec::Problems problems;
  spec::validator(spec::Schema::scenario).collect(s, problems.list());  // types, ranges, unknown and missing fields
  fill_versioned_defaults(s);  // the defaults of the scenario's version that depend on other fields
  Checks ck(s, problems);      // then the rules across fields, on the sound fields
  check_names(ck);
  check_geometry(ck);
  check_size_and_steps(ck);
  check_output(ck);
  engine_checks_once(s, ck);  // the engine's own checks (materials, pair values, dt bound)
  if (!problems.empty()) throw SpecError(source, std::move(problems.list()));
  return s;
}

const std::string& validated_by() {
  static const std::string mark = fmt::format(
      "{} schema:{}", build_version(), spec::sha256_hex(spec::schema_text(spec::Schema::scenario)).substr(0, 12));
  return mark;
}

bool validation_is_named() {
  static const bool named =
      !is_dirty_build(build_version()) && std::string_view(build_version()).find("+unknown") == std::string_view::npos;
  return named;
}

StoredScenario StoredScenario::of_this_build(json validated, json as_written) {
  return {std::move(validated), pipeline::validated_by(), std::move(as_written)};
}

StoredScenario StoredScenario::parse(const json& stored) {
  StoredScenario out{stored, std::nullopt, std::nullopt};
  if (!stored.is_object()) return out;  // validate_scenario says what it expected
  if (const auto it = stored.find(kValidatedByKey); it != stored.end()) {
    if (!it->is_string())
      throw SpecError("stored scenario",
                      {{std::string("/") + kValidatedByKey, it->dump(), "a build's validation mark"}});
    out.validated_by = it->get<std::string>();
    out.validated.erase(kValidatedByKey);
  }
  if (const auto it = stored.find(kAsWrittenKey); it != stored.end()) {
    out.as_written = *it;
    out.validated.erase(kAsWrittenKey);
  }
  return out;
}

json StoredScenario::to_json() const {
  json s = validated;
  if (validated_by) s[kValidatedByKey] = *validated_by;
  if (as_written) s[kAsWrittenKey] = *as_written;
  return s;
}

json job_scenario(const json& stored) {
  const StoredScenario st = StoredScenario::parse(stored);
  if (!st.validated_by) return validate_scenario(st.validated);  // unmarked: stored before marks
  const bool trusted = *st.validated_by == validated_by() && validation_is_named();
  if (!trusted && st.as_written) return validate_scenario(*st.as_written);
  // Trusted or marked by a build that stored no point as written: the stored scenario, checked
  // again (validating a validated scenario returns it unchanged).
  return validate_scenario(st.validated);
}

Scenario job_scenario_record(const json& stored) { return scenario_of(job_scenario(stored)); }

json load_scenario(const std::filesystem::path& path) {
  return validate_scenario(with_current_defaults(spec::read_spec_file(path, spec::Schema::scenario)), path.string());
}

double bed_grain_bound(const Scenario& s) {
  return grain_bound(s.grains.diameter_m, s.container.diameter_m, s.container.fill_height_m);
}

double job_memory_bytes(const Scenario& s) { return bed_grain_bound(s) * kBytesPerGrain; }

}  // namespace gravsweep::pipeline
