// A sweep's job kind (the "job" of a sweep spec) in one registration: how a point becomes queue
// jobs (its planner, with the point's check) and how those jobs run (their runners, whose metrics
// are the results rows). scheduler/pipeline/job_kinds.cpp holds the table of the kinds that run
// physics (impact); a new kind is one file and one row there (tests/scheduler/test_job_kind.cpp
// registers its own).
#pragma once
#include <cstddef>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scheduler/queue/job_types.h"
#include "scheduler/queue/worker.h"
#include "scheduler/sweep/spec.h"

namespace gravsweep::sweep {

/// The jobs a sweep's points plan, and their problems (at most a few per field and reason, each
/// with how many more points share it), collected by expand().
class Plan {
 public:
  /// A job of one point.
  void add(queue::PlannedJob job);
  /// A job of one point that waits for the job `shared_id` several points share: made from the
  /// first point's job by `make_shared`; swept values that differ between its points are not its
  /// parameters.
  void add_with_shared(queue::PlannedJob job, const std::string& shared_id,
                       const std::function<queue::PlannedJob(const queue::PlannedJob& first)>& make_shared);
  /// A problem of the point with swept values `params` (merged with the same pointer and reason).
  void problem(SpecProblem p, const nlohmann::json& params);
  /// The shared jobs first (in order of first use), then the points' jobs in product order; throws
  /// SpecError naming `file` when any point had a problem.
  std::vector<queue::PlannedJob> finish(const std::string& file);

 private:
  std::vector<queue::PlannedJob> shared_, jobs_;
  std::map<std::string, std::size_t> shared_index_;
  std::vector<SpecProblem> problems_;
  std::vector<std::size_t> repeats_;
};

struct SweepKind {
  std::string name;     ///< the sweep spec's "job"
  std::string summary;  ///< one line for `submit --help` and errors
  /// Problems of the base scenario reported once, under /base, before the points (empty: none).
  std::function<std::vector<SpecProblem>(const SweepSpec&)> check_base;
  /// Plans point `scenario` (the base with the point's swept values; `job` carries them as params,
  /// and the sweep's priority) into `plan`.
  std::function<void(const SweepSpec&, const nlohmann::json& scenario, queue::PlannedJob job, Plan& plan)> plan_point;
  /// The queue kinds it plans, each with its runner (a runner's metrics become its results row).
  std::vector<std::pair<queue::JobKind, queue::Runner>> runners;
};

/// Adds a kind (a name already registered throws ConfigError).
void register_sweep_kind(SweepKind kind);
/// The kind named `name`; throws SpecError at /job naming `file` and the registered names.
const SweepKind& sweep_kind(std::string_view name, const std::string& file = "sweep spec");
/// The registered kinds, in registration order.
std::vector<const SweepKind*> sweep_kinds();
/// The runners of every registered kind (what a worker runs).
queue::RunnerTable registered_runners();

/// The planner of a kind whose point is one job (kind `job_kind`) waiting for a job shared by
/// the points with equal keys (kind `shared_kind`): `check` validates the point once and gives its
/// stored scenario, its key and what its id is computed from (CheckedPoint). The impact kind's
/// shape (a drop per point, a bed per key).
decltype(SweepKind::plan_point) shared_input_planner(PointCheckFn check, queue::JobKind job_kind,
                                                     queue::JobKind shared_kind);
/// The base problems of such a kind: the point check on the base alone, reported under /base for
/// the fields no axis sets (a swept field is checked at each point instead).
decltype(SweepKind::check_base) base_checker(PointCheckFn check);

/// The queue's no-op jobs as a sweep kind ("noop": one job per point; fields sleep_s,
/// fail_attempts, value; for the scheduler's benchmark and tests), in noop_kind.cpp. The registry
/// starts with it: the queue's tests and benchmark need no pipeline.
SweepKind noop_sweep_kind();

}  // namespace gravsweep::sweep
