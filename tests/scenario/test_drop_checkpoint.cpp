// Checkpoint and restart of a drop (scheduler/pipeline/job_checkpoint.h,
// results/io/checkpoint_file.h): a drop interrupted at several points and continued from its
// checkpoints records the trace of an uninterrupted drop value for value; a checkpoint cut short,
// with a flipped byte or of another scenario is discarded with a warning naming the file, and the
// drop starts over and gives the same result; the file round trip is exact.
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "results/io/bed_file.h"
#include "results/io/checkpoint_file.h"
#include "results/io/trace_file.h"
#include "scenario_helpers.h"
#include "scheduler/pipeline/impact_job.h"
#include "scheduler/pipeline/scenario_spec.h"
#include "tests/common/same_trace.h"

namespace gravsweep {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::kNeverDue_s;

class DropCheckpoint : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir("gravsweep-ckpt");
    pipeline::run_bed_job(test::tiny_scenario(), bed(), 1, {}, nullptr);
    pipeline::run_drop_job(test::tiny_scenario(), bed(), reference(), 1, {}, nullptr);
  }
  static void TearDownTestSuite() { delete dir_; }
  static fs::path bed() { return dir_->path / "bed.h5"; }
  static fs::path reference() { return dir_->path / "reference.h5"; }
  static test::TempDir* dir_;
  void SetUp() override { fs::remove(ckpt_); }

  fs::path ckpt_ = dir_->path / "checkpoints" / "job.ckpt.h5";
  std::vector<std::string> warnings_;
  json scenario_ = test::tiny_scenario();  ///< the drop every attempt() runs

  pipeline::Checkpointing checkpointing() {
    pipeline::Checkpointing c;
    c.path = ckpt_;
    c.interval_s = kNeverDue_s;
    c.warn = [this](const std::string& w) { warnings_.push_back(w); };
    return c;
  }

  /// One attempt of the drop job, asked to stop once its progress passes `stop_at` (of the time
  /// cap; > 1: never). Returns true when it ran to the end.
  bool attempt(const fs::path& trace, double stop_at, json* metrics = nullptr) {
    std::atomic<bool> stop{false};
    const auto progress = [&](const std::string&, double f, const std::string&) {
      if (f >= stop_at && f < 1) stop.store(true);  // 1: the drop has ended
    };
    try {
      const auto r = pipeline::run_drop_job(scenario_, bed(), trace, 1, progress, &stop, checkpointing());
      if (metrics) *metrics = r.outputs_json();
      return true;
    } catch (const pipeline::Interrupted& e) {
      EXPECT_NE(std::string(e.what()).find(ckpt_.string()), std::string::npos) << e.what();
      return false;
    }
  }

  /// An interrupted first attempt: leaves a checkpoint.
  void interrupted_once(double stop_at = 0.05) {
    ASSERT_FALSE(attempt(dir_->path / "never.h5", stop_at));
    ASSERT_TRUE(fs::exists(ckpt_));
    ASSERT_FALSE(fs::exists(dir_->path / "never.h5"));
  }
  /// The drop at the adaptive step `time_step` (/time_step), run uninterrupted (NAME_reference.h5)
  /// and interrupted twice then resumed (NAME_resumed.h5); the test compares them.
  struct AdaptiveRuns {
    long uninterrupted_steps = 0, fixed_steps = 0;  ///< fixed: the same drop at the fixed step
    json resumed;                                   ///< the resumed drop's metrics
    fs::path reference, resumed_trace;
  };
  AdaptiveRuns run_adaptive_interrupted(const json& time_step, const std::string& name);
};
test::TempDir* DropCheckpoint::dir_ = nullptr;

/// Every column of two traces (tests/common/same_trace.h), and the drop's end and metrics.
void expect_same_trace(const fs::path& a_path, const fs::path& b_path) {
  ASSERT_NO_FATAL_FAILURE(test::expect_same_trace_columns(a_path, b_path));
  const results::TraceData a = results::read_trace(a_path), b = results::read_trace(b_path);
  EXPECT_EQ(a.stopped, b.stopped);
  const json ma = json::parse(a.metrics_json), mb = json::parse(b.metrics_json);
  for (const char* k : {"zstop_m", "tstop_s", "vc_m_s", "apeak_m_s2", "steps", "first_contact_s", "rest_time_s"})
    EXPECT_EQ(ma.at(k), mb.at(k)) << k;
}

DropCheckpoint::AdaptiveRuns DropCheckpoint::run_adaptive_interrupted(const json& time_step, const std::string& name) {
  scenario_["time_step"] = time_step;
  AdaptiveRuns r;
  r.reference = dir_->path / (name + "_reference.h5");
  r.resumed_trace = dir_->path / (name + "_resumed.h5");
  json uninterrupted;
  EXPECT_TRUE(attempt(r.reference, 2.0, &uninterrupted));
  r.uninterrupted_steps = uninterrupted.value("steps", 0L);
  r.fixed_steps = json::parse(results::read_trace(reference()).metrics_json)["steps"].get<long>();
  interrupted_once(0.04);
  EXPECT_FALSE(attempt(dir_->path / "never.h5", 0.12));
  EXPECT_TRUE(attempt(r.resumed_trace, 2.0, &r.resumed));
  EXPECT_TRUE(warnings_.empty()) << warnings_.front();
  return r;
}

// Three interruptions (stop requests at 3 %, 8 % and 13 % of the time cap: 9, 24 and 39 ms, during
// the collision; each followed by a checkpoint), three resumes, then the end: the trace is the
// uninterrupted one.
TEST_F(DropCheckpoint, ResumedThreeTimesTheTraceIsTheUninterruptedOne) {
  ASSERT_NO_FATAL_FAILURE(interrupted_once(0.03));
  const double t1 = results::read_checkpoint(ckpt_).drop()->loop.result.samples.t_s.back();
  EXPECT_FALSE(attempt(dir_->path / "never.h5", 0.08));
  const double t2 = results::read_checkpoint(ckpt_).drop()->loop.result.samples.t_s.back();
  EXPECT_FALSE(attempt(dir_->path / "never.h5", 0.13));
  const double t3 = results::read_checkpoint(ckpt_).drop()->loop.result.samples.t_s.back();
  EXPECT_LT(t1, t2);
  EXPECT_LT(t2, t3);
  json m;
  ASSERT_TRUE(attempt(dir_->path / "resumed.h5", 2.0, &m));
  EXPECT_TRUE(warnings_.empty()) << warnings_.front();
  EXPECT_FALSE(fs::exists(ckpt_)) << "the checkpoint outlived the recorded drop";
  EXPECT_EQ(m["checkpoint_resumes"], 3);
  EXPECT_EQ(m["resumed_at_s"].get<double>(), t3);
  EXPECT_NO_FATAL_FAILURE(expect_same_trace(reference(), dir_->path / "resumed.h5"));
}

// The same at the adaptive step of /time_step (engine/scenario/time_step.h): the step is chosen
// again before each sample interval from the state, so a drop resumed at a sample continues with
// the step an uninterrupted one takes there. The step must really grow: fewer steps than fixed.
TEST_F(DropCheckpoint, AtTheAdaptiveStepTheResumedTraceIsTheUninterruptedOne) {
  const AdaptiveRuns r = run_adaptive_interrupted({{"steps_per_contact", 10}, {"dt_max_s", 4e-5}}, "adaptive");
  EXPECT_LT(r.uninterrupted_steps, r.fixed_steps * 3 / 4)
      << "the adaptive step never grew past the fixed step: this test would not test it";
  EXPECT_EQ(r.resumed["checkpoint_resumes"], 2);
  EXPECT_NO_FATAL_FAILURE(expect_same_trace(r.reference, r.resumed_trace));
}

// The same with the normal-approach bound (/time_step/speed_bound): the bound reads the neighbour
// list and its positions at the last build, both in the checkpoint, so the resumed drop takes the
// same steps.
TEST_F(DropCheckpoint, AtTheNormalApproachStepTheResumedTraceIsTheUninterruptedOne) {
  const AdaptiveRuns r = run_adaptive_interrupted(
      {{"steps_per_contact", 10}, {"dt_max_s", 4e-5}, {"speed_bound", "normal_approach"}}, "approach");
  EXPECT_LT(r.uninterrupted_steps, r.fixed_steps * 3 / 4)
      << "the adaptive step never grew past the fixed step: this test would not test it";
  EXPECT_EQ(r.resumed["checkpoint_resumes"], 2);
  EXPECT_NO_FATAL_FAILURE(expect_same_trace(r.reference, r.resumed_trace));
}

// The file holds the drop exactly: every array and counter read back equals what was written.
TEST_F(DropCheckpoint, FileRoundTripIsExact) {
  ASSERT_NO_FATAL_FAILURE(interrupted_once());
  const results::CheckpointData c = results::read_checkpoint(ckpt_);
  const fs::path copy = dir_->path / "copy.ckpt.h5";
  results::write_checkpoint(copy, c);
  const results::CheckpointData d = results::read_checkpoint(copy);
  ASSERT_NE(c.drop(), nullptr);
  ASSERT_NE(d.drop(), nullptr);
  const SystemState &a = c.drop()->system, &b = d.drop()->system;
  EXPECT_EQ(a.particles.position_m, b.particles.position_m);
  EXPECT_EQ(a.particles.force_N, b.particles.force_N);
  EXPECT_EQ(a.particles.size_class, b.particles.size_class);
  EXPECT_EQ(a.list_neighbor, b.list_neighbor);
  EXPECT_EQ(a.list_work_offset, b.list_work_offset);
  EXPECT_EQ(a.position_at_build_m, b.position_at_build_m);
  ASSERT_EQ(a.pair_history.size(), b.pair_history.size());
  int active = 0;
  for (std::size_t k = 0; k < a.pair_history.size(); ++k) {
    EXPECT_EQ(a.pair_history[k].shear_m, b.pair_history[k].shear_m);
    EXPECT_EQ(a.pair_history[k].duration_s, b.pair_history[k].duration_s);
    EXPECT_EQ(a.pair_history[k].active, b.pair_history[k].active);
    active += a.pair_history[k].active;
  }
  EXPECT_GT(active, 100) << "a settled bed has touching pairs";
  EXPECT_FALSE(a.wall_candidates.empty());
  EXPECT_EQ(a.wall_candidates, b.wall_candidates);
  EXPECT_EQ(a.time_s, b.time_s);
  EXPECT_EQ(a.step, b.step);
  EXPECT_TRUE(a.domain.has_value() == b.domain.has_value());
  EXPECT_EQ(c.drop()->loop.samples_done, d.drop()->loop.samples_done);
  EXPECT_EQ(c.drop()->loop.result.samples.size(), d.drop()->loop.result.samples.size());
  EXPECT_TRUE(c.drop()->loop.result.samples.consistent());
  EXPECT_EQ(c.drop()->loop.result.samples.position_m, d.drop()->loop.result.samples.position_m);
  EXPECT_EQ(c.drop()->loop.result.samples.contacts, d.drop()->loop.result.samples.contacts);
  EXPECT_EQ(c.identity_json, d.identity_json);
  EXPECT_GT(c.wall_time_s, 0);
}

/// Overwrites the checkpoint: cut to half its size, or one byte flipped inside the stored
/// position of particle 0 (found by its bytes), or replaced by text.
enum class Damage { truncated, flipped_byte, not_hdf5 };

void damage(const fs::path& f, Damage how) {
  if (how == Damage::truncated) {
    fs::resize_file(f, fs::file_size(f) / 2);
    return;
  }
  if (how == Damage::not_hdf5) {
    std::ofstream(f, std::ios::trunc) << "not a checkpoint\n";
    return;
  }
  const double x = results::read_checkpoint(f).drop()->system.particles.position_m[0].x();
  std::ifstream in(f, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  char pattern[sizeof x];
  std::memcpy(pattern, &x, sizeof x);
  const auto at = bytes.find(std::string(pattern, sizeof x));
  ASSERT_NE(at, std::string::npos) << "particle 0's x not found in " << f;
  bytes[at + 3] = static_cast<char>(bytes[at + 3] ^ 0x10);
  std::ofstream(f, std::ios::binary | std::ios::trunc) << bytes;
}

class DamagedCheckpoint : public DropCheckpoint, public ::testing::WithParamInterface<Damage> {};

// The damaged checkpoint is discarded with a warning naming it; the drop starts over, completes
// and records the uninterrupted trace.
TEST_P(DamagedCheckpoint, IsDiscardedWithAWarningAndTheDropStartsOver) {
  ASSERT_NO_FATAL_FAILURE(interrupted_once());
  ASSERT_NO_FATAL_FAILURE(damage(ckpt_, GetParam()));
  EXPECT_THROW(results::read_checkpoint(ckpt_), results::CheckpointError);
  json m;
  ASSERT_TRUE(attempt(dir_->path / "restarted.h5", 2.0, &m));
  ASSERT_EQ(warnings_.size(), 1u);
  EXPECT_NE(warnings_[0].find(ckpt_.string()), std::string::npos) << warnings_[0];
  EXPECT_NE(warnings_[0].find("starts over"), std::string::npos) << warnings_[0];
  EXPECT_EQ(m["checkpoint_resumes"], 0);
  EXPECT_FALSE(fs::exists(ckpt_));
  EXPECT_NO_FATAL_FAILURE(expect_same_trace(reference(), dir_->path / "restarted.h5"));
}

INSTANTIATE_TEST_SUITE_P(Damages, DamagedCheckpoint,
                         ::testing::Values(Damage::truncated, Damage::flipped_byte, Damage::not_hdf5),
                         [](const ::testing::TestParamInfo<Damage>& i) {
                           return std::string(i.param == Damage::truncated      ? "Truncated"
                                              : i.param == Damage::flipped_byte ? "FlippedByte"
                                                                                : "NotHdf5");
                         });

// A checkpoint of another drop of the same bed (another impact speed) is not continued.
TEST_F(DropCheckpoint, ACheckpointOfAnotherScenarioIsDiscarded) {
  ASSERT_NO_FATAL_FAILURE(interrupted_once());
  json other = test::tiny_scenario();
  other["projectile"]["impact_speed_m_s"] = 1.2;
  std::atomic<bool> stop{false};  // stopped at its first progress report: enough to see the warning
  const auto progress = [&](const std::string&, double, const std::string&) { stop.store(true); };
  EXPECT_THROW(pipeline::run_drop_job(other, bed(), dir_->path / "never.h5", 1, progress, &stop, checkpointing()),
               pipeline::Interrupted);
  ASSERT_EQ(warnings_.size(), 1u);
  EXPECT_NE(warnings_[0].find("another drop"), std::string::npos) << warnings_[0];
  EXPECT_NE(warnings_[0].find("/scenario/projectile"), std::string::npos) << warnings_[0];
}

}  // namespace
}  // namespace gravsweep
