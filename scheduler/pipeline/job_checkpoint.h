// Checkpoints of a drop or bed job (results/io/checkpoint_file.h): the run is saved every
// interval_s of wall time and when a stop is requested (SIGTERM: scancel, a Slurm time limit), and
// the next attempt of the same job continues from the last checkpoint, bit for bit when it runs on
// the same number of threads. A checkpoint that cannot be used (missing, cut short, failing its
// content hash, written for another job, scenario, bed or build) is discarded with a warning
// naming the file, and the run starts over: never a failed job. The checkpoint is removed once
// the job's output (trace, bed) is written.
//
// Why a worker setting (`work --checkpoint-interval`) and not a scenario field: how often to pay
// for durability depends on the machine (time limits, how often nodes die), not on the physics;
// a resumed drop is bit-identical whatever the interval, so the interval must not enter the job
// id or the bed key, which hash the scenario.
#pragma once
#include "results/io/job_reports.h"
#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/scenario/bed.h"
#include "engine/scenario/impact.h"
#include "results/io/checkpoint_file.h"

namespace gravsweep::pipeline {

/// Default wall time between two checkpoints of a campaign's drop or bed (`work
/// --checkpoint-interval`): about 1 % of a drop's time for a paper-sized bed, whose checkpoint
/// takes well under a second.
inline constexpr double kDefaultCheckpointInterval_s = 300;

struct Checkpointing {
  std::filesystem::path path;  ///< this job's checkpoint file; empty: no checkpoints at all
  /// Wall seconds between two checkpoints; also written when a stop is requested. <= 0: none
  /// written (one left by an earlier attempt is still continued from).
  double interval_s = kDefaultCheckpointInterval_s;
  /// The stop request that is worth a checkpoint; null: the job's stop flag. A worker passes the
  /// process's (SIGTERM, stop.h): a job told to stop because another worker took its lease over
  /// just stops, and leaves the checkpoint to the job's owner.
  const std::atomic<bool>* save_on_stop = nullptr;
  /// The job's attempt: from the second on, a missing checkpoint is reported (warn) too.
  int attempt = 1;
  /// Set when a checkpoint beyond where this attempt started is written (null: not reported).
  std::atomic<bool>* progress_saved = nullptr;
  /// Where warnings go (a checkpoint discarded or not written); empty: stderr.
  std::function<void(const std::string&)> warn;
};

/// What drop a checkpoint belongs to: the validated scenario, the SHA-256 of the bed file and
/// the thread count (JobCheckpointer ignores the last when it compares).
nlohmann::json drop_identity(const nlohmann::json& validated_scenario, const std::filesystem::path& bed, int threads);
/// What bed a checkpoint belongs to: the bed key (everything the bed depends on) and the thread count.
nlohmann::json bed_identity(const nlohmann::json& bed_key, int threads);

/// The checkpoints of one job (a drop or a bed): the one to continue from, and the hooks that
/// write new ones.
class JobCheckpointer {
 public:
  /// `kind` is the job's ("drop" or "bed"), `identity` says what job this is (scenario, bed
  /// checksum, threads): a checkpoint of another kind, whose identity differs (threads aside) or
  /// that another build wrote is discarded. Reads the checkpoint at cfg.path if there is one.
  JobCheckpointer(Checkpointing cfg, std::string kind, nlohmann::json identity, const std::atomic<bool>* stop);

  /// The drop or bed to continue, or null (no usable checkpoint).
  [[nodiscard]] const DropState* resume_drop() const { return resume_ ? resume_->drop() : nullptr; }
  [[nodiscard]] const BedState* resume_bed() const { return resume_ ? resume_->bed() : nullptr; }
  /// The engine refused the resume (it threw std::invalid_argument): warns, removes the file and
  /// forgets it; the run starts over.
  void discard(const std::string& why);
  /// The engine's hooks: due() when the interval has passed or a stop was requested; save()
  /// writes the checkpoint, then throws Interrupted if a stop was requested.
  [[nodiscard]] DropCheckpoints drop_hooks();
  [[nodiscard]] BedCheckpoints bed_hooks();
  /// The job's output is written: its checkpoint (and any temporary of it) is removed.
  void finished();

  /// The progress detail with the last checkpoint appended (what `status` shows).
  [[nodiscard]] std::string detail(const std::string& run_detail) const;
  /// Wall time of the earlier attempts up to the checkpoint continued from (0: none).
  [[nodiscard]] double prior_wall_time_s() const;
  /// How the checkpoint served this job (resumes, where the last one started, checkpoints
  /// written), for the job's report.
  [[nodiscard]] results::CheckpointCounts counts() const;

 private:
  Checkpointing cfg_;
  std::string kind_;
  nlohmann::json identity_;
  const std::atomic<bool>* stop_;
  std::unique_ptr<results::CheckpointData> resume_;
  std::chrono::steady_clock::time_point started_, last_write_;
  long long written_ = 0;
  double last_t_s_ = -1;    ///< simulated time (CheckpointData::position_s) of the last checkpoint written
  std::string last_clock_;  ///< UTC time of day it was written
  void warn(const std::string& message) const;
  /// Simulated time of the checkpoint continued from; -1 when the run starts from its beginning.
  [[nodiscard]] double resumed_t_s() const;
  /// What the run starts over from, for the warnings.
  [[nodiscard]] const char* start() const { return kind_ == "drop" ? "its release" : "its first grain"; }
  [[nodiscard]] bool due() const;
  /// drop_hooks and bed_hooks: `resume` is the DropState or BedState to continue (or null), and
  /// `position_s(sys, loop)` the simulated time a checkpoint of that run is at.
  template <class Hooks, class State, class PositionOf>
  Hooks hooks(const State* resume, PositionOf position_s);
  /// Removes temporaries of this checkpoint a writer killed mid-write left (<file>.tmp<pid>).
  void remove_stale_temporaries() const;
  void load();
  /// Writes `c` (the state and loop of the run at simulated time c.position_s) with this job's
  /// identity; then throws Interrupted if a stop was requested.
  void save(results::CheckpointData c);
};

}  // namespace gravsweep::pipeline
