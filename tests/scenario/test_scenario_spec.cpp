// The scenario spec: defaults from the paper, and bad specs refused before any work with the JSON
// pointer of the bad field, the value found and what was expected.
#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <sstream>

#include "engine/scenario/paper_params.h"
#include "scenario_helpers.h"
#include "scheduler/pipeline/impact_job.h"
#include "scheduler/pipeline/scenario_spec.h"
#include "spec/schemas.h"

namespace gravsweep {
namespace {

using nlohmann::json;
using pipeline::SpecError;
using pipeline::validate_scenario;

/// Expects validation to fail at `pointer`; returns the message.
std::string refused_at(const json& spec, const std::string& pointer) {
  try {
    validate_scenario(spec, "spec.json");
  } catch (const SpecError& e) {
    EXPECT_EQ(e.pointer(), pointer) << e.what();
    EXPECT_NE(std::string(e.what()).find("spec.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(pointer), std::string::npos) << e.what();
    EXPECT_FALSE(e.expected().empty());
    return e.what();
  }
  ADD_FAILURE() << "accepted a spec that should fail at " << pointer;
  return {};
}

json minimal() { return json{{"projectile", {{"impact_speed_m_s", 1.0}}}}; }

TEST(ScenarioSpec, DefaultsAreThePapersChronoSetup) {
  const json s = validate_scenario(minimal());
  EXPECT_DOUBLE_EQ(s["gravity_m_s2"].get<double>(), 9.81);
  EXPECT_DOUBLE_EQ(s["/container/diameter_m"_json_pointer].get<double>(), 0.315);
  EXPECT_DOUBLE_EQ(s["/container/fill_height_m"_json_pointer].get<double>(), 0.10);
  EXPECT_DOUBLE_EQ(s["/grains/diameter_spread_m"_json_pointer].get<double>(), 5e-4);
  EXPECT_DOUBLE_EQ(s["/materials/grain/young_modulus_Pa"_json_pointer].get<double>(), 7e8);
  EXPECT_DOUBLE_EQ(s["/materials/grain/mu_rolling"_json_pointer].get<double>(), 0.09);
  EXPECT_DOUBLE_EQ(s["/materials/wall/cor_normal"_json_pointer].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(s["/contact/pairs/grain-wall/mu_static"_json_pointer].get<double>(), 0.45);
  EXPECT_DOUBLE_EQ(s["dt_s"].get<double>(), 1e-6);
  EXPECT_DOUBLE_EQ(s["/output/sample_rate_hz"_json_pointer].get<double>(), 1e4);
  EXPECT_DOUBLE_EQ(s["/stop/speed_sqrt_gD"_json_pointer].get<double>(), 1e-3);
  EXPECT_DOUBLE_EQ(s["/bed/settle/rms_speed_m_s"_json_pointer].get<double>(), 1e-5);
  // The engine parameters equal Table 1's Chrono set of engine/scenario/paper_params.h.
  const SystemConfig drop = pipeline::scenario_of(s).drop_config();
  const SystemConfig ref = chrono_table1_config();
  ASSERT_EQ(drop.materials.size(), ref.materials.size());
  for (std::size_t i = 0; i < ref.materials.size(); ++i) {
    EXPECT_EQ(drop.materials[i].cor_normal, ref.materials[i].cor_normal) << i;
    EXPECT_EQ(drop.materials[i].mu_static, ref.materials[i].mu_static) << i;
    EXPECT_EQ(drop.materials[i].mu_rolling, ref.materials[i].mu_rolling) << i;
    EXPECT_EQ(drop.materials[i].young_modulus_Pa, ref.materials[i].young_modulus_Pa) << i;
  }
  EXPECT_EQ(drop.pair_overrides.size(), ref.pair_overrides.size());
  EXPECT_EQ(drop.contact_law, "hertz");
  EXPECT_EQ(drop.rolling_model, "sunday");
}

// An enum name the schema did not check (a scenario read unvalidated into the record) is refused
// with its pointer, never mapped silently to another value (it became explicit_pair before).
TEST(ScenarioSpec, UnknownCompositionNameIsRefusedNotDefaulted) {
  json s = validate_scenario(minimal());
  s["/contact/composition"_json_pointer] = "chrono-min";
  try {
    (void)pipeline::scenario_of(s).drop_config();
    ADD_FAILURE() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/contact/composition: found \"chrono-min\""), std::string::npos) << e.what();
  }
  s["/contact/composition"_json_pointer] = "chrono_min";
  EXPECT_EQ(pipeline::scenario_of(s).drop_config().composition, Composition::chrono_min);
}

TEST(ScenarioSpec, OffsetsAreDrawnWithinTheirBoundsFromTheSeed) {
  json s = minimal();
  s["projectile"]["lateral_offset_max_grain_diameters"] = 2;
  s["projectile"]["vertical_offset_max_grain_diameters"] = 2;
  const auto projectile = [](const json& spec) {
    return pipeline::scenario_of(validate_scenario(spec)).projectile_spec();
  };
  const ProjectileSpec a = projectile(s);
  const ProjectileSpec b = projectile(s);
  EXPECT_EQ(a.lateral_offset_x_m, b.lateral_offset_x_m);
  EXPECT_LE(std::hypot(a.lateral_offset_x_m, a.lateral_offset_y_m), 0.02);
  EXPECT_GE(a.vertical_offset_m, 0.0);
  EXPECT_LE(a.vertical_offset_m, 0.02);
  s["projectile"]["seed"] = 2;
  const ProjectileSpec c = projectile(s);
  EXPECT_NE(a.lateral_offset_x_m, c.lateral_offset_x_m);
}

// Repeats are independent: the site is drawn from the seed and the sweep point, so the same seed
// at another speed or gravity hits another site (before, seeds 1-3 hit the same three sites at
// every speed and both gravity levels), while the same point always hits the same one.
TEST(ScenarioSpec, TheSameSeedAtAnotherSpeedOrGravityHitsAnotherSite) {
  json s = minimal();
  s["projectile"]["vertical_offset_max_grain_diameters"] = 0.5;
  auto site = [](const json& spec) {
    const ProjectileSpec p = pipeline::scenario_of(validate_scenario(spec)).projectile_spec();
    return std::array<double, 3>{p.lateral_offset_x_m, p.lateral_offset_y_m, p.vertical_offset_m};
  };
  const auto a = site(s);
  EXPECT_EQ(a, site(s));
  json faster = s, lower = s, threads = s;
  faster["projectile"]["impact_speed_m_s"] = 0.8;
  lower["gravity_m_s2"] = 0.1;
  threads["threads"] = 2;  // engine settings never move the site
  for (int k = 0; k < 3; ++k) {
    EXPECT_NE(a[k], site(faster)[k]) << k;
    EXPECT_NE(a[k], site(lower)[k]) << k;
  }
  EXPECT_EQ(a, site(threads));
  // site_draw "seed": the seed alone, as the committed reproduction parts were drawn.
  s["projectile"]["site_draw"] = "seed";
  faster["projectile"]["site_draw"] = "seed";
  EXPECT_EQ(site(s), site(faster));
}

// The stop criterion is in the drop's own scales unless given absolute: at 9.81 m/s2 and 10 cm the
// paper's 1 mm/s, 5 ms and 1 s; at 0.001 m/s2 a hundred times slower and longer.
TEST(ScenarioSpec, TheStopScalesWithGravityUnlessGivenAbsolute) {
  const auto at = [](double g, const json& stop) {
    json s = minimal();
    s["gravity_m_s2"] = g;
    s["projectile"]["impact_speed_m_s"] = 0.05;
    s["projectile"]["start_gap_m"] = 1e-4;
    s["stop"] = stop;
    return pipeline::scenario_of(validate_scenario(s));
  };
  const pipeline::Scenario earth = at(9.81, json::object());
  EXPECT_NEAR(earth.drop_stop().speed_m_s, 1e-3, 1e-5);
  EXPECT_NEAR(earth.drop_stop().hold_time_s, 5e-3, 1e-4);
  EXPECT_NEAR(earth.drop_stop().max_time_s, 1.0, 0.01);
  EXPECT_DOUBLE_EQ(earth.drop_config().options.min_roll_vel_m_s, 1e-4);  // Chrono's value at 1 g
  const pipeline::Scenario low = at(0.000981, json::object());
  EXPECT_NEAR(low.drop_stop().speed_m_s, 1e-3 / 100, 1e-7);
  EXPECT_NEAR(low.drop_stop().max_time_s, 100 * earth.drop_stop().max_time_s, 1e-9);
  EXPECT_NEAR(low.drop_config().options.min_roll_vel_m_s, 1e-6, 1e-12);
  const pipeline::Scenario fixed = at(0.001, json{{"speed_m_s", 2e-3}, {"max_time_s", 3.0}});
  EXPECT_DOUBLE_EQ(fixed.drop_stop().speed_m_s, 2e-3);
  EXPECT_DOUBLE_EQ(fixed.drop_stop().max_time_s, 3.0);
  // A validated scenario (both forms present) validates again to the same drop: absolute wins.
  json twice = minimal();
  twice["stop"] = json{{"speed_m_s", 2e-3}};
  const json once = validate_scenario(twice);
  EXPECT_EQ(validate_scenario(once), once);
  EXPECT_DOUBLE_EQ(pipeline::scenario_of(validate_scenario(once)).drop_stop().speed_m_s, 2e-3);
}

TEST(ScenarioSpec, UnknownFieldsAreRefusedWithTheirPointer) {
  json s = minimal();
  s["projectile"]["speed_m_s"] = 1.0;
  const std::string msg = refused_at(s, "/projectile/speed_m_s");
  EXPECT_NE(msg.find("impact_speed_m_s"), std::string::npos) << msg;  // lists the known fields
  json t = minimal();
  t["contact"]["pairs"]["grain/wall"] = json::object();
  refused_at(t, "/contact/pairs/grain~1wall");  // RFC 6901 escaping
}

TEST(ScenarioSpec, WrongTypesAndRangesAreRefused) {
  json s = minimal();
  s["gravity_m_s2"] = "9.81";
  const std::string msg = refused_at(s, "/gravity_m_s2");
  EXPECT_NE(msg.find("\"9.81\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("number"), std::string::npos) << msg;
  s = minimal();
  s["materials"]["grain"]["cor_normal"] = 1.5;
  EXPECT_NE(refused_at(s, "/materials/grain/cor_normal").find("<= 1"), std::string::npos);
  s = minimal();
  s["dt_s"] = -1e-6;
  refused_at(s, "/dt_s");
  s = minimal();
  s["bed"]["seed"] = 1.5;
  refused_at(s, "/bed/seed");
  s = minimal();
  s["contact"]["composition"] = "average";
  refused_at(s, "/contact/composition");
  s = minimal();
  s["contact"]["law"] = "hertzian";
  EXPECT_NE(refused_at(s, "/contact/law").find("hooke"), std::string::npos);
  s = minimal();
  s["integrator"] = "rk4";
  refused_at(s, "/integrator");
}

TEST(ScenarioSpec, CrossFieldRulesAreRefusedAtTheRightField) {
  json s = minimal();
  s["projectile"]["drop_height_m"] = 0.05;
  EXPECT_NO_FATAL_FAILURE(refused_at(s, "/projectile/drop_height_m"));  // both speed and height
  s = json{{"projectile", json::object()}};
  EXPECT_NO_FATAL_FAILURE(refused_at(s, "/projectile/impact_speed_m_s"));  // neither
  s = minimal();
  s["grains"]["diameter_spread_m"] = 0.006;
  EXPECT_NO_FATAL_FAILURE(refused_at(s, "/grains/diameter_spread_m"));
  s = minimal();
  s["projectile"]["impact_speed_m_s"] = 0.2;  // 5 mm of free fall at 1 g already gives 0.31 m/s
  EXPECT_NO_FATAL_FAILURE(refused_at(s, "/projectile/start_gap_m"));
  s = minimal();
  s["projectile"]["vertical_offset_max_grain_diameters"] = 10;
  EXPECT_NO_FATAL_FAILURE(refused_at(s, "/projectile/vertical_offset_max_grain_diameters"));
  s = minimal();
  s["projectile"]["lateral_offset_max_grain_diameters"] = 20;
  EXPECT_NO_FATAL_FAILURE(refused_at(s, "/projectile/lateral_offset_max_grain_diameters"));
  s = minimal();
  s["output"]["sample_rate_hz"] = 2e6;  // above 1/dt
  EXPECT_NO_FATAL_FAILURE(refused_at(s, "/output/sample_rate_hz"));
  s = minimal();
  s["container"]["diameter_m"] = 0.03;
  EXPECT_NO_FATAL_FAILURE(refused_at(s, "/container/diameter_m"));
}

TEST(ScenarioSpec, EveryProblemIsListedNotOnlyTheFirst) {
  json s = minimal();
  s["projectile"]["mass_kg"] = "heavy";         // schema: a number
  s["grains"] = {{"diameter_spread_m", 0.02}};  // rule: below half the grain diameter
  s["output"] = {{"sample_rate_hz", 1e7}};      // rule: at most 1/dt_s
  s["dt_s"] = "small";                          // schema: a number (the rate check then skips)
  try {
    validate_scenario(s, "spec.json");
    FAIL() << "accepted";
  } catch (const SpecError& e) {
    std::vector<std::string> ptrs;
    for (const auto& p : e.problems()) ptrs.push_back(p.pointer);
    EXPECT_EQ(ptrs, (std::vector<std::string>{"/dt_s", "/projectile/mass_kg", "/grains/diameter_spread_m"}))
        << e.what();
    EXPECT_EQ(e.pointer(), "/dt_s");
    EXPECT_NE(std::string(e.what()).find("spec.json: 3 problems"), std::string::npos) << e.what();
  }
}

TEST(ScenarioSpec, TimeStepsAboveTheStabilityBoundAreRefused) {
  json s = minimal();
  s["dt_s"] = 5e-5;  // Hertz bound: 0.3 x Rayleigh time ~ 15 us for 1 cm glass beads at 700 MPa
  EXPECT_NE(refused_at(s, "/dt_s").find("stability"), std::string::npos);
  s = minimal();
  s["bed"]["dt_s"] = 5e-5;
  refused_at(s, "/bed/dt_s");
}

TEST(ScenarioSpec, ThePlateauWindowLiesBetweenACheckAndTheCap) {
  json s = minimal();
  s["bed"]["settle"]["plateau_window_s"] = 0.0;
  refused_at(s, "/bed/settle/plateau_window_s");  // absent is off; 0 would be a second spelling
  s["bed"]["settle"]["plateau_window_s"] = 1e-4;  // below the 1 ms check interval
  refused_at(s, "/bed/settle/plateau_window_s");
  s["bed"]["settle"]["plateau_window_s"] = 2.0;  // the default cap: it could never end a phase
  refused_at(s, "/bed/settle/plateau_window_s");
  s["bed"]["settle"]["plateau_window_s"] = 0.1;
  EXPECT_NO_THROW(validate_scenario(s));
}

TEST(ScenarioSpec, TheBedsOwnMaterialsAreCheckedWithTheBedsTimeStep) {
  json s = minimal();
  s["bed"]["materials"]["grain"]["cor_normal"] = 1.5;
  s["dt_s"] = 5e-5;  // still checked (the drop's materials are sound), so both problems are listed
  try {
    validate_scenario(s, "spec.json");
    ADD_FAILURE() << "accepted";
  } catch (const SpecError& e) {
    EXPECT_NE(std::string(e.what()).find("/bed/materials/grain/cor_normal"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("/dt_s"), std::string::npos) << e.what();
  }
  s = minimal();
  s["bed"]["materials"]["grain"]["young_modulus_Pa"] = 7e10;  // 100x stiffer: bound ~1.5 us
  refused_at(s, "/bed/dt_s");  // the default 5 us preparation step, checked with the bed's materials
  s["bed"]["dt_s"] = 1e-6;
  const json ok = validate_scenario(s);
  EXPECT_DOUBLE_EQ(ok["/bed/materials/grain/young_modulus_Pa"_json_pointer].get<double>(), 7e10);
  EXPECT_DOUBLE_EQ(ok["/bed/materials/wall/cor_normal"_json_pointer].get<double>(), 0.5);  // defaults fill in
  EXPECT_FALSE(validate_scenario(minimal())["bed"].contains("materials"));  // absent stays absent: bed keys stay
}

TEST(ScenarioSpec, TheCompiledSchemaIsTheRepositorysSchema) {
  std::ifstream in(std::string(GRAVSWEEP_SOURCE_DIR) + "/schemas/scenario.schema.json");
  ASSERT_TRUE(in.good());
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(json::parse(ss.str()), json::parse(spec::schema_text(spec::Schema::scenario)));
}

TEST(ScenarioSpec, ExamplesAreValid) {
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(std::string(GRAVSWEEP_SOURCE_DIR) + "/examples")) {
    // Scenario examples are examples/impact_*.json (others there are sweep specs).
    if (e.path().extension() != ".json" || e.path().filename().string().rfind("impact_", 0) != 0) continue;
    EXPECT_NO_THROW(pipeline::load_scenario(e.path())) << e.path();
    ++n;
  }
  EXPECT_GE(n, 2);
}

// Examples that say they share a bed do: impact_1g_dt5us.json reuses impact_1g.json's bed (--bed),
// and part 5b's drops land on part 5's cached bed (REPRODUCTION.md) through /bed/materials.
TEST(ScenarioSpec, ExamplesThatShareABedHaveOneBedKey) {
  const std::string ex = std::string(GRAVSWEEP_SOURCE_DIR) + "/examples/";
  EXPECT_EQ(pipeline::bed_key(pipeline::load_scenario(ex + "impact_1g.json")),
            pipeline::bed_key(pipeline::load_scenario(ex + "impact_1g_dt5us.json")));
  auto base = [&](const std::string& sweep) {
    return json::parse(std::ifstream(ex + "reproduction/" + sweep)).at("base");
  };
  const json part5 = base("part5_pkdgrav_1g.json"), part5b = base("part5b_pkdgrav_stiff_1g.json");
  EXPECT_EQ(pipeline::bed_key(part5b), pipeline::bed_key(part5));
  EXPECT_NE(part5b.at("materials"), part5.at("materials"));  // the drops' springs differ
}

TEST(ScenarioSpec, JsonSyntaxErrorsNameFileLineAndColumn) {
  test::TempDir dir;
  const auto path = dir.path / "broken.json";
  std::ofstream(path) << "{\n  \"gravity_m_s2\": 9.81,\n  \"dt_s\": ,\n}\n";
  try {
    pipeline::load_scenario(path);
    FAIL() << "broken JSON accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.json:3:"), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(ScenarioSpec, AnAdaptiveStepsCapBelowTheFixedStepIsRefusedAtValidation) {
  json s = minimal();
  s["time_step"] = {{"steps_per_contact", 20}, {"dt_max_s", 5e-7}};  // the default dt_s is 1 us
  refused_at(s, "/time_step/dt_max_s");
  s = minimal();
  s["bed"]["time_step"] = {{"steps_per_contact", 20}, {"dt_max_s", 2e-6}};  // the bed's default is 5 us
  refused_at(s, "/bed/time_step/dt_max_s");
  s["bed"]["time_step"]["dt_max_s"] = 5e-5;
  EXPECT_NO_THROW(validate_scenario(s));
}

// /time_step/speed_bound is optional and has no default: absent, the validated scenario holds none
// (so the job ids of existing sweeps stay) and the drop takes twice the fastest particle's speed;
// named, the drop takes that bound; an unknown name is refused at its pointer.
TEST(ScenarioSpec, TheAdaptiveStepsSpeedBoundIsOptionalAndNamed) {
  json s = minimal();
  s["time_step"] = {{"steps_per_contact", 20}, {"dt_max_s", 5e-5}};
  const json plain = validate_scenario(s);
  EXPECT_FALSE(plain["time_step"].contains("speed_bound")) << plain["time_step"];
  EXPECT_EQ(pipeline::scenario_of(plain).drop_time_step().speed_bound, AdaptiveStep::SpeedBound::fastest_particle);
  s["time_step"]["speed_bound"] = "normal_approach";
  EXPECT_EQ(pipeline::scenario_of(validate_scenario(s)).drop_time_step().speed_bound,
            AdaptiveStep::SpeedBound::normal_approach);
  s["time_step"]["speed_bound"] = "fastest";
  const std::string msg = refused_at(s, "/time_step/speed_bound");
  EXPECT_NE(msg.find("normal_approach"), std::string::npos) << msg;
}

// A sweep point is validated at submit: its jobs store the validated scenario marked with this
// build's validation and the point as written, and the worker's job_scenario checks the validated
// one again (unchanged by it). A job marked by another build is validated again from the point as
// written (that build's own rules and defaults); an unmarked one (older campaigns) is the point.
TEST(ScenarioSpec, AScenarioValidatedAtSubmitIsCheckedAgainByTheWorker) {
  const json written = minimal();
  const json validated = validate_scenario(written);
  const json stored = pipeline::StoredScenario::of_this_build(validated, written).to_json();
  EXPECT_EQ(stored.at(pipeline::StoredScenario::kValidatedByKey), pipeline::validated_by());
  EXPECT_EQ(stored.at(pipeline::StoredScenario::kAsWrittenKey), written);
  EXPECT_EQ(pipeline::job_scenario(stored), validated);  // the two keys removed, nothing else changed
  // A stored value broken after submit (the database is a trust boundary) is refused whatever the
  // mark says, naming its field: a permanent failure, not a retry. A string where a number
  // belongs, likewise (it failed with the JSON library's message, naming no field, retried three
  // times). A build with uncommitted changes trusts no mark (others share its name) and validates
  // the point as written, which is intact.
  json broken = stored;
  broken["dt_s"] = -1;
  json typo = stored;
  typo["gravity_m_s2"] = "NaN";
  if (pipeline::validation_is_named()) {
    try {
      (void)pipeline::job_scenario(broken);
      ADD_FAILURE() << "a broken stored value passed the mark";
    } catch (const SpecError& e) {
      EXPECT_EQ(e.pointer(), "/dt_s") << e.what();
    }
    try {
      (void)pipeline::job_scenario(typo);
      ADD_FAILURE() << "a string gravity passed the mark";
    } catch (const SpecError& e) {
      EXPECT_EQ(e.pointer(), "/gravity_m_s2") << e.what();
    }
  } else {
    EXPECT_EQ(pipeline::job_scenario(broken), validated);
    EXPECT_EQ(pipeline::job_scenario(typo), validated);
  }
  // Another build's mark: the point as written is validated, not the stored defaults.
  broken[pipeline::StoredScenario::kValidatedByKey] = "0.0.0+another schema:000000000000";
  EXPECT_EQ(pipeline::job_scenario(broken), validated);
  broken[pipeline::StoredScenario::kAsWrittenKey]["dt_s"] = -1;
  EXPECT_THROW((void)pipeline::job_scenario(broken), SpecError);
  // Another build's mark without a point as written (builds that stored only the mark): the stored
  // scenario is validated again, without the mark; a bad stored value is a SpecError, not a
  // missing-key error.
  json mark_only = stored;
  mark_only[pipeline::StoredScenario::kValidatedByKey] = "0.0.0+another schema:000000000000";
  mark_only.erase(pipeline::StoredScenario::kAsWrittenKey);
  EXPECT_EQ(pipeline::job_scenario(mark_only), validated);
  mark_only["dt_s"] = -1;
  EXPECT_THROW((void)pipeline::job_scenario(mark_only), SpecError);
  // Unmarked: the stored text is the point as written.
  EXPECT_EQ(pipeline::job_scenario(written), validated);
  json bad = written;
  bad["dt_s"] = -1;
  EXPECT_THROW((void)pipeline::job_scenario(bad), SpecError);
}

}  // namespace gravsweep
