// The whole impact pipeline on a small bed (Sunday et al. 2021 Sect. 2.2-2.3): prepare, save,
// reload, drop, record, measure; bed reuse; interruption; the `run` verb end to end.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "engine/core/error.h"
#include "results/io/bed_file.h"
#include "results/io/trace_file.h"
#include "scenario_helpers.h"
#include "scheduler/pipeline/impact_job.h"

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
        test::tiny_scenario(), dir_->path / "bed.h5", 2,
        [](const std::string& ph, double f, const std::string&) {
          phases_->insert(ph);
          EXPECT_GE(f, 0.0);
          EXPECT_LE(f, 1.0 + 1e-12);
        },
        nullptr));
    drop_ = new pipeline::DropJobResult(run_drop_job(
        test::tiny_scenario(), dir_->path / "bed.h5", dir_->path / "trace.h5", 2,
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
  const json& r = bed_->report;
  ASSERT_TRUE(std::filesystem::exists(bed_->bed_path));
  EXPECT_GT(r["grains_placed"].get<int>(), 150);
  EXPECT_LT(r["grains_kept"].get<int>(), r["grains_placed"].get<int>());  // flattening removed some
  // Flattened at 4 cm (centres); the surface lies within a grain of it.
  EXPECT_NEAR(r["surface_height_m"].get<double>(), 0.04, 0.01);
  // Random packing of spheres: bulk density 0.55-0.66 of 2480 kg/m3 (paper: 1.42-1.45 g/cm3).
  EXPECT_GT(r["bulk_density_kg_m3"].get<double>(), 1200);
  EXPECT_LT(r["bulk_density_kg_m3"].get<double>(), 1700);
  const auto bed = results::read_bed(bed_->bed_path);
  EXPECT_EQ(bed.size(), r["grains_kept"].get<std::size_t>());
  for (std::size_t i = 0; i < bed.size(); ++i) ASSERT_LT(bed.position_m[3 * i + 2], 0.04 + 1e-3);
  EXPECT_TRUE(phases_->count("fill") && phases_->count("settle") && phases_->count("flatten"));
}

TEST_F(ImpactPipeline, DropIsRecordedAndMeasured) {
  const json& m = drop_->metrics;
  ASSERT_FALSE(m.contains("metrics_error")) << m.dump(2);
  const auto tr = results::read_trace(drop_->trace_path);
  ASSERT_GT(tr.size(), 100u);
  EXPECT_NEAR(tr.sample_rate_hz, 1e4, 1e-6);
  // Starts 5 mm above the surface, in free fall: accel_up reads -g.
  EXPECT_NEAR(tr.depth_m.front(), -0.005, 1e-9);
  EXPECT_NEAR(tr.accel_up_m_s2[1], -9.81, 1e-6);
  EXPECT_EQ(tr.contacts.front(), 0);
  // The paper's metrics: vc close to the requested 0.5 m/s (the surface is rough at the grain scale).
  EXPECT_NEAR(m["vc_m_s"].get<double>(), 0.5, 0.05);
  EXPECT_GT(m["zstop_m"].get<double>(), 0.0);
  EXPECT_LT(m["zstop_m"].get<double>(), 0.04);
  EXPECT_GT(m["tstop_s"].get<double>(), 1e-3);
  EXPECT_GT(m["apeak_m_s2"].get<double>(), 0.0);
  EXPECT_GT(m["wall_time_s"].get<double>(), 0.0);
  EXPECT_TRUE(phases_->count("drop"));
  // Energy went into the grains.
  double ke_max = 0;
  for (double e : tr.grain_kinetic_energy_J) ke_max = std::max(ke_max, e);
  EXPECT_GT(ke_max, 1e-5);
}

TEST_F(ImpactPipeline, BedReuseEqualsPreparingTheBedAgain) {
  // Same seed, prepared again: the bed is bit-identical ...
  const auto again = run_bed_job(test::tiny_scenario(), dir_->path / "bed2.h5", 2, {}, nullptr);
  const auto a = results::read_bed(bed_->bed_path), b = results::read_bed(again.bed_path);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.position_m, b.position_m);
  EXPECT_EQ(a.velocity_m_s, b.velocity_m_s);
  EXPECT_EQ(a.radius_m, b.radius_m);
  EXPECT_EQ(a.surface_height_m, b.surface_height_m);
  // ... and so is a drop into it, compared with the drop into the reused first bed.
  const auto d2 = run_drop_job(test::tiny_scenario(), again.bed_path, dir_->path / "trace2.h5", 2, {}, nullptr);
  const auto t1 = results::read_trace(drop_->trace_path), t2 = results::read_trace(d2.trace_path);
  EXPECT_EQ(t1.depth_m, t2.depth_m);
  EXPECT_EQ(t1.accel_up_m_s2, t2.accel_up_m_s2);
  EXPECT_EQ(drop_->metrics["zstop_m"], d2.metrics["zstop_m"]);
  EXPECT_EQ(drop_->metrics["apeak_m_s2"], d2.metrics["apeak_m_s2"]);
  // Another seed gives another bed.
  json other = test::tiny_scenario();
  other["bed"]["seed"] = 8;
  EXPECT_NE(pipeline::bed_key(other), pipeline::bed_key(test::tiny_scenario()));
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

TEST_F(ImpactPipeline, StopFlagInterruptsWithoutLeavingFiles) {
  std::atomic<bool> stop{false};
  int calls = 0;
  EXPECT_THROW(run_drop_job(test::tiny_scenario(), bed_->bed_path, dir_->path / "stopped.h5", 1,
                            [&](const std::string&, double, const std::string&) {
                              if (++calls == 2) stop = true;
                            },
                            &stop),
               pipeline::Interrupted);
  EXPECT_FALSE(std::filesystem::exists(dir_->path / "stopped.h5"));
  for (const auto& e : std::filesystem::directory_iterator(dir_->path))
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
}

}  // namespace
}  // namespace gravsweep
