// The whole impact pipeline on a small bed (Sunday et al. 2021 Sect. 2.2-2.3): prepare, save,
// reload, drop, record, measure; bed reuse; interruption; the `run` verb end to end.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <string>
#include <sstream>
#include <vector>
#include <sys/wait.h>

#include "engine/core/error.h"
#include "engine/scenario/paper_params.h"
#include "results/io/bed_file.h"
#include "results/io/job_reports.h"
#include "results/io/trace_file.h"
#include "results/measurements/campaign.h"
#include "scenario_helpers.h"
#include "scheduler/pipeline/impact_job.h"
#include "scheduler/pipeline/scenario_spec.h"

namespace gravsweep {
namespace {

using nlohmann::json;
using pipeline::run_bed_job;
using pipeline::run_drop_job;

class ImpactPipeline : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    phases_ = new std::set<std::string>();
    bed_ = new pipeline::BedJobResult(run_bed_job(
        test::tiny_scenario(), dir_->path / "bed.h5", 1,
        [](const std::string& ph, double f, const std::string&) {
          phases_->insert(ph);
          EXPECT_GE(f, 0.0);
          EXPECT_LE(f, 1.0 + 1e-12);
        },
        nullptr));
    drop_ = new pipeline::DropJobResult(run_drop_job(
        test::tiny_scenario(), dir_->path / "bed.h5", dir_->path / "trace.h5", 1,
        [](const std::string& ph, double, const std::string&) { phases_->insert(ph); }, nullptr));
  }
  static void TearDownTestSuite() {
    delete drop_;
    delete bed_;
    delete phases_;
    delete dir_;
  }
  static test::TempDir* dir_;
  static std::set<std::string>* phases_;
  static pipeline::BedJobResult* bed_;
  static pipeline::DropJobResult* drop_;
};
test::TempDir* ImpactPipeline::dir_ = nullptr;
std::set<std::string>* ImpactPipeline::phases_ = nullptr;
pipeline::BedJobResult* ImpactPipeline::bed_ = nullptr;
pipeline::DropJobResult* ImpactPipeline::drop_ = nullptr;

TEST_F(ImpactPipeline, BedIsPreparedFlattenedAndSaved) {
  const json r = results::to_json(bed_->report);
  ASSERT_TRUE(std::filesystem::exists(bed_->bed_path));
  EXPECT_GT(r["grains_placed"].get<int>(), 150);
  EXPECT_LT(r["grains_kept"].get<int>(), r["grains_placed"].get<int>());  // flattening removed some
  // Flattened at 5 cm (centres); the surface lies within a grain of it.
  EXPECT_NEAR(r["surface_height_m"].get<double>(), 0.05, 0.01);
  // Random packing of spheres: bulk density 0.55-0.66 of 2480 kg/m3 (paper: 1.42-1.45 g/cm3).
  EXPECT_GT(r["bulk_density_kg_m3"].get<double>(), 1200);
  EXPECT_LT(r["bulk_density_kg_m3"].get<double>(), 1700);
  Particles grains;
  results::read_bed(bed_->bed_path, grains);
  EXPECT_EQ(grains.size(), r["grains_kept"].get<std::size_t>());
  for (std::size_t i = 0; i < grains.size(); ++i) ASSERT_LT(grains.position_m[i].z(), 0.05 + 1e-3);
  EXPECT_TRUE(phases_->count("fill") && phases_->count("settle") && phases_->count("flatten"));
}

TEST_F(ImpactPipeline, DropIsRecordedAndMeasured) {
  const json m = drop_->outputs_json();
  ASSERT_FALSE(m.contains("metrics_error")) << m.dump(2);
  const auto tr = results::read_trace(drop_->trace_path);
  ASSERT_GT(tr.size(), 100u);
  EXPECT_NEAR(tr.info.sample_rate_hz, 1e4, 1e-6);
  // Starts 5 mm above the first grain under the projectile (not above the mean
  // surface, which a proud grain may stand above), in free fall: accel_up reads -g.
  const double touch_m = m["first_touch_height_above_surface_m"].get<double>();
  EXPECT_GT(touch_m, -0.01);
  EXPECT_LT(touch_m, 0.01);
  EXPECT_NEAR(tr.raw.depth_m.front(), -(touch_m + 0.005), 1e-9);
  EXPECT_NEAR(tr.raw.accel_up_m_s2[1], -9.81, 1e-6);
  EXPECT_EQ(tr.contacts.front(), 0);
  // The paper's metrics: vc is the requested 1 m/s (the start gap is measured from the grain
  // the projectile touches first; sampling at 10 kHz moves it by g / 10 kHz at most).
  EXPECT_NEAR(m["vc_m_s"].get<double>(), 1.0, 2e-3);
  EXPECT_NEAR(m["t_start_s"].get<double>(), m["first_contact_s"].get<double>(), 1e-3);
  // The projectile penetrates and stays inside the bed. (On a bed this small the paper's end of
  // collision, a < 0.1 g after the filter, may come at a pause after the first grain shock, so
  // zstop only has to lie between the start and the deepest point.)
  EXPECT_GT(m["max_depth_m"].get<double>(), 0.005);
  EXPECT_LT(m["max_depth_m"].get<double>(), 0.05);
  EXPECT_GT(m["final_depth_below_surface_m"].get<double>(), 0.005);
  EXPECT_GT(m["zstop_m"].get<double>(), -0.01);
  // zstop is measured from the collision start, the engine's max_depth_m from the bed's mean
  // surface: zstop_surface_m (zstop + the start's depth) is the engine's figure.
  EXPECT_LE(m["zstop_surface_m"].get<double>(), m["max_depth_m"].get<double>() + 1e-9);
  EXPECT_NEAR(m["zstop_surface_m"].get<double>() - m["zstop_m"].get<double>(), m["start_depth_m"].get<double>(), 1e-12);
  EXPECT_GT(m["tstop_s"].get<double>(), 0.0);
  // On this small bed the first (paper-defined) collision lasts ~3 ms, shorter than the 500 Hz
  // filter's edge width, so apeak is not meaningful here; it must still be a finite number.
  EXPECT_TRUE(std::isfinite(m["apeak_m_s2"].get<double>()));
  EXPECT_GT(m["apeak_m_s2"].get<double>(), -9.81);
  EXPECT_TRUE(m["stopped"].get<bool>());
  EXPECT_GT(m["duration_to_rest_s"].get<double>(), 0.0);
  // The DEM's final depth is the trace's last depth below the surface; the processed record's
  // final_depth_m (from the collision start) stays beside it, not replaced by it.
  EXPECT_NEAR(m["final_depth_below_surface_m"].get<double>(), tr.raw.depth_m.back(), 1e-15);
  EXPECT_NEAR(m["final_depth_m"].get<double>(), tr.raw.depth_m.back() - m["start_depth_m"].get<double>(), 1e-9);
  EXPECT_GT(m["wall_time_s"].get<double>(), 0.0);
  EXPECT_TRUE(phases_->count("drop"));
  // Energy went into the grains.
  double ke_max = 0;
  for (double e : tr.grain_kinetic_energy_J) ke_max = std::max(ke_max, e);
  EXPECT_GT(ke_max, 1e-5);
}

// The drop's trace record is the trial it is measured as: processing wrote the processed trace and
// the metrics into the record itself, from the record's own columns, and those metrics are the
// drop's outputs (no MeasuredTrial made of a copy of the trace, no Metrics kept beside it). A
// campaign reading the trace file back measures the same trial.
TEST_F(ImpactPipeline, TheDropsTraceRecordIsTheTrialItIsMeasuredAs) {
  const auto* rec = dynamic_cast<const results::DropRecord*>(drop_->record.get());
  ASSERT_NE(rec, nullptr);
  ASSERT_TRUE(rec->measured) << rec->metrics_error;
  const results::TraceData& td = rec->trace;
  EXPECT_EQ(rec->metrics(), &td.processed.metrics);
  EXPECT_EQ(td.processed.t_s, td.raw.t_s);
  EXPECT_EQ(td.info.source, results::TraceSource::dem);
  EXPECT_EQ(td.info.gravity_m_s2, 9.81);
  EXPECT_EQ(td.options.gravity_m_s2, td.info.gravity_m_s2);
  EXPECT_EQ(td.options.fill_height_m, td.info.fill_height_m);  // the measured surface
  EXPECT_EQ(drop_->outputs_json()["zstop_m"], td.processed.metrics.zstop_m);
  results::MeasuredTrial back = results::read_dem_trial({"back", "", drop_->trace_path});
  results::process_trial(back);
  EXPECT_EQ(back.info.fill_height_m, td.info.fill_height_m);
  EXPECT_EQ(back.info.projectile_mass_kg, td.info.projectile_mass_kg);
  EXPECT_EQ(back.raw.accel_up_m_s2, td.raw.accel_up_m_s2);
  EXPECT_EQ(back.processed.metrics.zstop_m, td.processed.metrics.zstop_m);
  EXPECT_EQ(back.processed.metrics.apeak_m_s2, td.processed.metrics.apeak_m_s2);
  EXPECT_EQ(back.processed.metrics.tstop_s, td.processed.metrics.tstop_s);
}

TEST_F(ImpactPipeline, BedReuseEqualsPreparingTheBedAgain) {
  // Same seed, prepared again: the bed is bit-identical ...
  const auto again = run_bed_job(test::tiny_scenario(), dir_->path / "bed2.h5", 1, {}, nullptr);
  Particles a, b;
  const results::BedFacts fa = results::read_bed(bed_->bed_path, a), fb = results::read_bed(again.bed_path, b);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a.position_m == b.position_m);
  EXPECT_TRUE(a.velocity_m_s == b.velocity_m_s);
  EXPECT_EQ(a.radius_m, b.radius_m);
  EXPECT_EQ(fa.surface_height_m, fb.surface_height_m);
  // ... and so is a drop into it, compared with the drop into the reused first bed.
  const auto d2 = run_drop_job(test::tiny_scenario(), again.bed_path, dir_->path / "trace2.h5", 1, {}, nullptr);
  const auto t1 = results::read_trace(drop_->trace_path), t2 = results::read_trace(d2.trace_path);
  EXPECT_EQ(t1.raw.depth_m, t2.raw.depth_m);
  EXPECT_EQ(t1.raw.accel_up_m_s2, t2.raw.accel_up_m_s2);
  EXPECT_EQ(drop_->outputs_json()["zstop_m"], d2.outputs_json()["zstop_m"]);
  EXPECT_EQ(drop_->outputs_json()["apeak_m_s2"], d2.outputs_json()["apeak_m_s2"]);
  // Another seed gives another bed.
  json other = test::tiny_scenario();
  other["bed"]["seed"] = 8;
  EXPECT_NE(pipeline::bed_key(other), pipeline::bed_key(test::tiny_scenario()));
  // A lid during the pour is another bed; without the key the bed key is as before it existed.
  json lidded = test::tiny_scenario();
  lidded["bed"]["lid"] = true;
  EXPECT_NE(pipeline::bed_key(lidded), pipeline::bed_key(test::tiny_scenario()));
  EXPECT_FALSE(pipeline::bed_key(test::tiny_scenario()).at("bed").contains("lid"));
  EXPECT_TRUE(pipeline::bed_key(lidded).at("bed").at("lid").get<bool>());
}

TEST_F(ImpactPipeline, DropsOfOtherSpeedsShareTheBedButNotOtherGravity) {
  json faster = test::tiny_scenario();
  faster["projectile"]["impact_speed_m_s"] = 0.8;
  faster["projectile"]["seed"] = 4;
  EXPECT_EQ(pipeline::bed_key(faster), pipeline::bed_key(test::tiny_scenario()));
  json low_g = test::tiny_scenario();
  low_g["gravity_m_s2"] = 1.0;
  EXPECT_NE(pipeline::bed_key(low_g), pipeline::bed_key(test::tiny_scenario()));
  try {
    run_drop_job(low_g, bed_->bed_path, dir_->path / "never.h5", 2, {}, nullptr);
    FAIL() << "a bed of another gravity was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/gravity_m_s2"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir_->path / "never.h5"));
}

// Part 5b of the reproduction (REPRODUCTION.md): drops with a stiffer spring on the bed prepared
// with the softer one. /bed/materials names the bed's materials; the drop uses /materials.
TEST_F(ImpactPipeline, ABedPreparedWithItsOwnMaterialsServesDropsWithOtherMaterials) {
  constexpr double kStiffE_Pa = 2.8e9;  // 4x the default 700 MPa (Table 1)
  json stiff = test::tiny_scenario();
  stiff["dt_s"] = 5e-6;  // the 4x stiffer Hertz contact needs a smaller step than tiny's 10 us
  for (const char* body : {"grain", "wall", "projectile"}) stiff["materials"][body]["young_modulus_Pa"] = kStiffE_Pa;
  stiff["bed"]["materials"] = json::object();  // the defaults: the bed of tiny_scenario()
  EXPECT_EQ(pipeline::bed_key(stiff), pipeline::bed_key(test::tiny_scenario()));
  const pipeline::Scenario p = pipeline::scenario_of(pipeline::validate_scenario(stiff));
  EXPECT_DOUBLE_EQ(p.bed_config().materials.at(kGrainMaterial).young_modulus_Pa, 7e8);
  EXPECT_DOUBLE_EQ(p.drop_config().materials.at(kGrainMaterial).young_modulus_Pa, kStiffE_Pa);
  EXPECT_DOUBLE_EQ(p.drop_config().materials.at(kProjectileMaterial).young_modulus_Pa, kStiffE_Pa);

  // Without /bed/materials the stiff scenario names another bed, and the prepared one is refused.
  json stiff_own_bed = stiff;
  stiff_own_bed["bed"].erase("materials");
  stiff_own_bed["bed"]["dt_s"] = 5e-6;  // its preparation step is now checked with the stiff materials
  EXPECT_NE(pipeline::bed_key(stiff_own_bed), pipeline::bed_key(test::tiny_scenario()));
  try {
    run_drop_job(stiff_own_bed, bed_->bed_path, dir_->path / "never_stiff.h5", 1, {}, nullptr);
    ADD_FAILURE() << "a bed of other materials was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("was prepared for another scenario: its bed key differs at /"),
              std::string::npos)
        << e.what();
  }

  // The drop runs on the soft bed with the stiff contacts: the bed's elastic energy released by
  // the stiffer spring (the grains' kinetic energy before the projectile touches them) is small
  // beside the projectile's kinetic energy, and the depth stays close.
  const auto d = run_drop_job(stiff, bed_->bed_path, dir_->path / "stiff.h5", 1, {}, nullptr);
  const auto tr = results::read_trace(d.trace_path);
  const double first_contact_s = d.outputs_json().at("first_contact_s");
  double released_J = 0;
  std::size_t before = 0;
  for (std::size_t k = 0; k < tr.raw.t_s.size() && tr.raw.t_s[k] < first_contact_s; ++k, ++before)
    released_J = std::max(released_J, tr.grain_kinetic_energy_J[k]);
  ASSERT_GE(before, 3u);  // samples between release and contact (5 mm default gap at 1 m/s: ~5 ms)
  const double impact_ke_J = 0.5 * 0.25 * 1.0 * 1.0;  // tiny_scenario: 0.25 kg at 1 m/s
  std::printf("grain KE before contact: at most %.2e J (impact %.3f J)\n", released_J, impact_ke_J);
  EXPECT_LT(released_J, 0.01 * impact_ke_J);
  EXPECT_DOUBLE_EQ(tr.dt_s, 5e-6);
  EXPECT_TRUE(json::parse(tr.scenario_json)["bed"].contains("materials"));
  const double z_soft = drop_->outputs_json().at("zstop_m"), z_stiff = d.outputs_json().at("zstop_m");
  EXPECT_NEAR(z_stiff, z_soft, 0.3 * z_soft) << "soft " << z_soft << " m, stiff " << z_stiff << " m";
}

TEST_F(ImpactPipeline, StopFlagInterruptsWithoutLeavingFiles) {
  std::atomic<bool> stop{false};
  int calls = 0;
  EXPECT_THROW(run_drop_job(
                   test::tiny_scenario(), bed_->bed_path, dir_->path / "stopped.h5", 1,
                   [&](const std::string&, double, const std::string&) {
                     if (++calls == 2) stop = true;
                   },
                   &stop),
               pipeline::Interrupted);
  EXPECT_FALSE(std::filesystem::exists(dir_->path / "stopped.h5"));
  for (const auto& e : std::filesystem::directory_iterator(dir_->path))
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
}

struct Cli {
  int code;
  std::string out, err;
};

/// Runs the built `gravsweep` with `args`, capturing stdout, stderr and the exit code.
Cli gravsweep_cli(const test::TempDir& dir, const std::string& args) {
  const auto out = dir.path / "cli.out", err = dir.path / "cli.err";
  const std::string cmd = std::string(GRAVSWEEP_BINARY) + " " + args + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(cmd.c_str());
  auto slurp = [](const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  return Cli{WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

TEST(RunVerb, WritesBedTraceAndMetricsThenReusesTheBed) {
  test::TempDir dir;
  const auto spec = dir.path / "tiny.json";
  std::ofstream(spec) << test::tiny_scenario().dump(2);
  const auto out = dir.path / "run1";
  const Cli r = gravsweep_cli(dir, "run " + spec.string() + " --out " + out.string() + " --threads 1 --quiet");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_TRUE(std::filesystem::exists(out / "bed.h5"));
  EXPECT_TRUE(std::filesystem::exists(out / "trace.h5"));
  ASSERT_TRUE(std::filesystem::exists(out / "metrics.json"));
  EXPECT_NE(r.out.find("zstop_cm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("apeak_m_s2"), std::string::npos) << r.out;
  const json m = json::parse(std::ifstream(out / "metrics.json"));
  EXPECT_TRUE(m["zstop_m"].is_number());
  EXPECT_TRUE(m["bed_report"]["grains_kept"].is_number());
  // The bed line says how settling ended, against the scenario's own criteria (tiny_scenario:
  // rms 1e-4 m/s, fastest 5e-3 m/s): met, or which one the time cap left unmet.
  const auto bed_line = r.out.substr(r.out.find("bed: "), r.out.find('\n', r.out.find("bed: ")) - r.out.find("bed: "));
  if (m["bed_report"]["settled"].get<bool>()) {
    EXPECT_NE(bed_line.find("settled to the criteria (rms "), std::string::npos) << bed_line;
  } else {
    EXPECT_NE(bed_line.find("settling stopped by the time cap /bed/settle/max_time_s"), std::string::npos) << bed_line;
  }
  const double rms = m["bed_report"]["rms_speed_m_s"].get<double>(),
               fastest = m["bed_report"]["max_speed_m_s"].get<double>();
  EXPECT_NE(bed_line.find(rms > 1e-4 ? "rms" : "<= 0.0001"), std::string::npos) << bed_line;
  EXPECT_NE(bed_line.find(fastest > 5e-3 ? "fastest grain" : "<= 0.005"), std::string::npos) << bed_line;
  if (rms > 1e-4) {
    EXPECT_NE(bed_line.find("above its 0.0001"), std::string::npos) << bed_line;
  }
  if (fastest > 5e-3) {
    EXPECT_NE(bed_line.find("above its 0.005"), std::string::npos) << bed_line;
  }

  // Another speed on the same bed: no new bed, the given one is used.
  json faster = test::tiny_scenario();
  faster["projectile"]["impact_speed_m_s"] = 1.3;
  const auto spec2 = dir.path / "faster.json";
  std::ofstream(spec2) << faster.dump(2);
  const auto out2 = dir.path / "run2";
  const Cli r2 = gravsweep_cli(dir, "run " + spec2.string() + " --out " + out2.string() + " --bed " +
                                        (out / "bed.h5").string() + " --threads 1 --quiet");
  ASSERT_EQ(r2.code, 0) << r2.out << r2.err;
  EXPECT_FALSE(std::filesystem::exists(out2 / "bed.h5"));
  const json m2 = json::parse(std::ifstream(out2 / "metrics.json"));
  EXPECT_EQ(m2["bed_file"].get<std::string>(), std::filesystem::absolute(out / "bed.h5").string());
  EXPECT_NEAR(m2["vc_m_s"].get<double>(), 1.3, 0.08);
}

// With /bed/settle/plateau_window_s a bed whose criteria are out of reach stops at the
// creep floor, long before the 2 s caps, and the bed line and report say so.
TEST(RunVerb, ABedOutOfReachOfItsCriteriaStopsAtTheCreepFloorAndSaysSo) {
  test::TempDir dir;
  json s = test::tiny_scenario();
  s["bed"]["settle"] = {
      {"rms_speed_m_s", 1e-8}, {"max_speed_m_s", 5e-3}, {"max_time_s", 2.0}, {"plateau_window_s", 0.03}};
  const auto spec = dir.path / "floor.json";
  std::ofstream(spec) << s.dump(2);
  const auto out = dir.path / "run";
  const Cli r = gravsweep_cli(dir, "run " + spec.string() + " --out " + out.string() + " --threads 1 --quiet");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  const json rep = json::parse(std::ifstream(out / "metrics.json"))["bed_report"];
  EXPECT_EQ(rep["settle_end"], "plateau") << rep.dump();
  EXPECT_EQ(rep["relax_end"], "plateau") << rep.dump();
  EXPECT_FALSE(rep["settled"].get<bool>());
  EXPECT_LT(rep["settle_time_s"].get<double>(), 1.0);
  EXPECT_LT(rep["relax_time_s"].get<double>(), 1.0);
  EXPECT_NE(r.out.find("settling stopped at the creep floor (the RMS speed fell by less than 10 % in "
                       "/bed/settle/plateau_window_s = 0.03 s) (rms "),
            std::string::npos)
      << r.out;
}

TEST(RunVerb, BadSpecExitsWithCode2AndThePointerBeforeAnyWork) {
  test::TempDir dir;
  json bad = test::tiny_scenario();
  bad["projectile"]["impact_speed_m_s"] = -1.0;
  const auto spec = dir.path / "bad.json";
  std::ofstream(spec) << bad.dump(2);
  const Cli r = gravsweep_cli(dir, "run " + spec.string() + " --out " + (dir.path / "out").string());
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/projectile/impact_speed_m_s"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("-1"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path / "out" / "bed.h5"));
  // A bed prepared for another scenario is refused too (exit 2).
  std::ofstream(dir.path / "nobed.h5") << "x";
  const auto good = dir.path / "good.json";
  std::ofstream(good) << test::tiny_scenario().dump(2);
  const Cli r2 = gravsweep_cli(dir, "run " + good.string() + " --out " + (dir.path / "o2").string() + " --bed " +
                                        (dir.path / "nobed.h5").string() + " --quiet");
  EXPECT_NE(r2.code, 0);
  EXPECT_NE(r2.err.find("nobed.h5"), std::string::npos) << r2.err;
}

TEST(RunVerb, HelpTeachesWithAnExample) {
  test::TempDir dir;
  const Cli r = gravsweep_cli(dir, "run --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("Example"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--bed"), std::string::npos) << r.out;
}

/// The lines of a verb's output (a CSV table: header first).
std::vector<std::string> lines_of(const std::string& out) {
  std::vector<std::string> lines;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// `gravsweep pile` on a small heap (600 grains, 8 cm base; measured 7 and 17 degrees): a CSV row
// per mu_r with the angle, steeper with rolling friction, and a bad option refused with exit code 2.
TEST(PileVerb, PrintsTheAngleForEachRollingFrictionAndRefusesBadOptions) {
  test::TempDir dir;
  const Cli r = gravsweep_cli(dir, "pile --mu-r 0,0.09 --grains 600 --base-radius 0.08 --format csv --quiet");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  const auto lines = lines_of(r.out);
  ASSERT_GE(lines.size(), 3u) << r.out;
  const std::string &header = lines[0], &row0 = lines[1], &row1 = lines[2];
  EXPECT_EQ(header.rfind("set,mu_rolling,shape_beta,mu_static,repose_angle_deg,", 0), 0u) << r.out;
  const std::string flat_key = "chrono,0,-,0.16,", steep_key = "chrono,0.09,-,0.16,";
  EXPECT_EQ(row0.rfind(flat_key, 0), 0u) << r.out;
  EXPECT_EQ(row1.rfind(steep_key, 0), 0u) << r.out;
  const double flat = std::stod(row0.substr(flat_key.size()));
  const double steep = std::stod(row1.substr(steep_key.size()));
  EXPECT_GT(steep, flat + 4.0) << r.out;
  EXPECT_LT(steep, 45.0) << r.out;
  const Cli bad = gravsweep_cli(dir, "pile --mu-s -1");
  EXPECT_EQ(bad.code, 2) << bad.out << bad.err;
  EXPECT_NE(bad.err.find("--mu-s"), std::string::npos) << bad.err;
  const Cli beta_chrono = gravsweep_cli(dir, "pile --beta 0.1");
  EXPECT_EQ(beta_chrono.code, 2) << beta_chrono.out << beta_chrono.err;
  EXPECT_NE(beta_chrono.err.find("--set pkdgrav only"), std::string::npos) << beta_chrono.err;
  const Cli bad_set = gravsweep_cli(dir, "pile --set lammps");
  EXPECT_EQ(bad_set.code, 2) << bad_set.out << bad_set.err;
  EXPECT_NE(bad_set.err.find("--set"), std::string::npos) << bad_set.err;
}

// `gravsweep pile --set pkdgrav` takes Table 1's pkdgrav grains (mu_s 1.0, 1 cm beads, Hooke +
// Zhang) with the beta given; the small heap measured 13 degrees at beta 0.05 (the full 2,000-grain
// heap 23.2, Table 2: 22.1; REPRODUCTION.md, part 5). The set itself: pkdgrav_table1_config.
TEST(PileVerb, ThePkdgravSetPilesWithItsOwnFrictionAndBeta) {
  const SystemConfig set = pkdgrav_table1_config(1.05, 0.1);
  EXPECT_EQ(set.contact_law, "hooke");
  EXPECT_EQ(set.rolling_model, "zhang");
  EXPECT_EQ(set.materials[kGrainMaterial].mu_static, 1.0);
  EXPECT_EQ(set.materials[kGrainMaterial].shape_beta, 0.1);
  EXPECT_EQ(set.materials[kGrainMaterial].kn_N_m, 7.48e5);
  test::TempDir dir;
  const Cli r =
      gravsweep_cli(dir, "pile --set pkdgrav --beta 0.1 --grains 600 --base-radius 0.08 --format csv --quiet");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  const auto lines = lines_of(r.out);
  ASSERT_GE(lines.size(), 2u) << r.out;
  const std::string& row = lines[1];
  const std::string key = "pkdgrav,1.05,0.1,1,";
  ASSERT_EQ(row.rfind(key, 0), 0u) << r.out;
  const double angle = std::stod(row.substr(key.size()));
  EXPECT_GT(angle, 5.0) << r.out;
  EXPECT_LT(angle, 35.0) << r.out;
}

}  // namespace
}  // namespace gravsweep
