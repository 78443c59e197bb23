// Checkpoint and restart of a bed job (scheduler/pipeline/job_checkpoint.h, kind "bed"): a bed
// preparation stopped while the pour settles and again while the surface relaxes continues from
// its checkpoint file and writes the grains of an uninterrupted preparation value for value; a
// drop's checkpoint found at a bed job's path is discarded with a warning naming the file.
#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <vector>

#include "results/io/bed_file.h"
#include "results/io/job_reports.h"
#include "results/io/checkpoint_file.h"
#include "scenario_helpers.h"
#include "scheduler/pipeline/impact_job.h"

namespace gravsweep {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::kNeverDue_s;

class BedJobCheckpoint : public ::testing::Test {
 protected:
  void SetUp() override { pipeline::run_bed_job(test::tiny_scenario(), reference(), 1, {}, nullptr); }
  test::TempDir dir_{"gravsweep-bed-ckpt"};
  fs::path reference() const { return dir_.path / "reference.h5"; }
  fs::path ckpt() const { return dir_.path / "checkpoints" / "bed.ckpt.h5"; }
  std::vector<std::string> warnings_;

  pipeline::Checkpointing checkpointing() {
    pipeline::Checkpointing c;
    c.path = ckpt();
    c.interval_s = kNeverDue_s;
    c.warn = [this](const std::string& w) { warnings_.push_back(w); };
    return c;
  }

  /// One attempt of the bed job, asked to stop at its first progress report of `phase` past
  /// `fraction` (empty: never). Returns the report when it ran to the end.
  std::optional<json> attempt(const fs::path& out, const std::string& phase, double fraction) {
    std::atomic<bool> stop{false};
    const auto progress = [&](const std::string& ph, double f, const std::string&) {
      if (ph == phase && f >= fraction) stop.store(true);
    };
    try {
      return results::to_json(
          pipeline::run_bed_job(test::tiny_scenario(), out, 1, progress, &stop, checkpointing()).report);
    } catch (const pipeline::Interrupted& e) {
      EXPECT_NE(std::string(e.what()).find(ckpt().string()), std::string::npos) << e.what();
      return std::nullopt;
    }
  }
};

TEST_F(BedJobCheckpoint, StoppedTwiceTheBedIsTheUninterruptedOne) {
  EXPECT_FALSE(attempt(dir_.path / "never.h5", "settle", 0.2));
  ASSERT_TRUE(fs::exists(ckpt()));
  const results::CheckpointData first = results::read_checkpoint(ckpt());
  ASSERT_NE(first.bed(), nullptr) << "a bed job's checkpoint is of kind bed";
  EXPECT_EQ(first.bed()->loop.stage, BedStage::settle);
  EXPECT_FALSE(attempt(dir_.path / "never.h5", "flatten", 0.0));
  const results::CheckpointData second = results::read_checkpoint(ckpt());
  EXPECT_EQ(second.bed()->loop.stage, BedStage::relax);
  EXPECT_GT(second.position_s, first.position_s);
  EXPECT_EQ(second.resumes, 1);
  const auto report = attempt(dir_.path / "resumed.h5", "", 2.0);
  ASSERT_TRUE(report.has_value());
  EXPECT_TRUE(warnings_.empty()) << warnings_.front();
  EXPECT_FALSE(fs::exists(ckpt())) << "the checkpoint is removed once the bed is written";
  EXPECT_EQ(report->at("checkpoint_resumes"), 2);
  EXPECT_EQ(report->at("resumed_at_s"), second.position_s);
  Particles a, b;
  const results::BedFacts fa = results::read_bed(reference(), a), fb = results::read_bed(dir_.path / "resumed.h5", b);
  EXPECT_TRUE(a.position_m == b.position_m);
  EXPECT_TRUE(a.velocity_m_s == b.velocity_m_s);
  EXPECT_TRUE(a.omega_rad_s == b.omega_rad_s);
  EXPECT_EQ(fa.surface_height_m, fb.surface_height_m);
  EXPECT_EQ(fa.time_s, fb.time_s);
}

TEST_F(BedJobCheckpoint, ADropCheckpointAtABedJobsPathIsDiscarded) {
  EXPECT_FALSE(attempt(dir_.path / "never.h5", "settle", 0.2));
  results::CheckpointData c = results::read_checkpoint(ckpt());
  c.state = DropState{c.bed()->system, {}};
  results::write_checkpoint(ckpt(), c);
  const auto report = attempt(dir_.path / "restarted.h5", "", 2.0);
  ASSERT_TRUE(report.has_value());
  ASSERT_EQ(warnings_.size(), 1u);
  EXPECT_NE(warnings_[0].find(ckpt().string()), std::string::npos) << warnings_[0];
  EXPECT_NE(warnings_[0].find("a drop checkpoint, this job is a bed"), std::string::npos) << warnings_[0];
  EXPECT_EQ(report->at("checkpoint_resumes"), 0);
  Particles a, b;
  results::read_bed(reference(), a);
  results::read_bed(dir_.path / "restarted.h5", b);
  EXPECT_TRUE(a.position_m == b.position_m);
}

}  // namespace
}  // namespace gravsweep
