#include "scheduler/sweep/sweep_kind.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <mutex>
#include <optional>

#include "engine/core/error.h"
#include "engine/core/registry.h"
#include "scheduler/queue/canonical.h"
#include "spec/json_pointer.h"
#include "spec/problems.h"

namespace gravsweep::sweep {

using nlohmann::json;

// ---- the plan of a sweep's points -----------------------------------------------------------

namespace {
/// Problems listed per sweep (each further point with one of them is counted, not listed).
constexpr std::size_t kMaxListedProblems = 20;
}  // namespace

void Plan::add(queue::PlannedJob job) { jobs_.push_back(std::move(job)); }

void Plan::add_with_shared(queue::PlannedJob job, const std::string& shared_id,
                           const std::function<queue::PlannedJob(const queue::PlannedJob&)>& make_shared) {
  auto [it, inserted] = shared_index_.emplace(shared_id, shared_.size());
  if (inserted) {
    shared_.push_back(make_shared(job));
  } else {
    auto& params = shared_[it->second].params;
    for (auto p = job.params.begin(); p != job.params.end(); ++p)
      if (params.contains(p.key()) && params[p.key()] != p.value()) params[p.key()] = nullptr;
  }
  job.deps.push_back(shared_[it->second].job_id);
  jobs_.push_back(std::move(job));
}

void Plan::problem(SpecProblem p, const json& params) {
  const auto same = std::find_if(problems_.begin(), problems_.end(), [&](const SpecProblem& q) {
    return q.pointer == p.pointer && q.expected == p.expected;
  });
  if (same != problems_.end()) {
    ++repeats_[static_cast<std::size_t>(same - problems_.begin())];
  } else if (problems_.size() < kMaxListedProblems) {
    p.found += " at point " + params.dump();
    problems_.push_back(std::move(p));
    repeats_.push_back(0);
  }
}

std::vector<queue::PlannedJob> Plan::finish(const std::string& file) {
  for (std::size_t i = 0; i < problems_.size(); ++i)
    if (repeats_[i] > 0)
      problems_[i].found +=
          fmt::format(" (and {} more point{} with this problem)", repeats_[i], repeats_[i] == 1 ? "" : "s");
  if (!problems_.empty()) throw SpecError::sweep_spec(file, problems_);
  for (auto& s : shared_) {  // a shared job's parameters are those its points agree on
    json kept = json::object();
    for (auto it = s.params.begin(); it != s.params.end(); ++it)
      if (!it.value().is_null()) kept[it.key()] = it.value();
    s.params = std::move(kept);
  }
  std::vector<queue::PlannedJob> out = std::move(shared_);
  out.insert(out.end(), std::make_move_iterator(jobs_.begin()), std::make_move_iterator(jobs_.end()));
  return out;
}

// ---- the registry -----------------------------------------------------------------------------

namespace {

struct Registry {
  std::mutex mutex;
  std::deque<SweepKind> kinds{noop_sweep_kind()};  // deque: references stay valid as kinds are added
};

Registry& registry() {
  static Registry r;
  return r;
}

}  // namespace

void register_sweep_kind(SweepKind kind) {
  Registry& r = registry();
  const std::lock_guard lock(r.mutex);
  if (find_row_or_null(r.kinds, kind.name))
    throw ConfigError(fmt::format("sweep job kind '{}' is registered twice", kind.name));
  r.kinds.push_back(std::move(kind));
}

std::vector<const SweepKind*> sweep_kinds() {
  Registry& r = registry();
  const std::lock_guard lock(r.mutex);
  std::vector<const SweepKind*> out;
  for (const auto& k : r.kinds) out.push_back(&k);
  return out;
}

const SweepKind& sweep_kind(std::string_view name, const std::string& file) {
  Registry& r = registry();
  const std::lock_guard lock(r.mutex);
  if (const SweepKind* k = find_row_or_null(r.kinds, name)) return *k;
  throw SpecError::sweep_spec(file, {{"/job", json(name).dump(), "a registered job kind: " + row_names(r.kinds)}});
}

queue::RunnerTable registered_runners() {
  queue::RunnerTable t;
  for (const SweepKind* k : sweep_kinds())
    for (const auto& [kind, runner] : k->runners) t[kind] = runner;
  return t;
}

// ---- planners ---------------------------------------------------------------------------------

namespace {

/// A point's check, its problems added to `plan`: nothing when the point is invalid.
std::optional<CheckedPoint> checked(const PointCheckFn& check, const json& scenario, const json& params, Plan& plan) {
  try {
    return check(scenario);
  } catch (const SpecError& e) {
    // The base was sound, so these are problems of swept values.
    for (const auto& sp : e.problems()) plan.problem({"/base" + sp.pointer, sp.found, sp.expected}, params);
  } catch (const std::exception& e) {
    // One problem per distinct message: a bad base field fails every point the same way.
    plan.problem({"/base", "the scenario", std::string("a valid scenario: ") + e.what()}, params);
  }
  return std::nullopt;
}

}  // namespace

decltype(SweepKind::plan_point) shared_input_planner(PointCheckFn check, queue::JobKind job_kind,
                                                     queue::JobKind shared_kind) {
  return [check = std::move(check), job_kind, shared_kind](const SweepSpec& spec, const json& scenario,
                                                           queue::PlannedJob job, Plan& plan) {
    auto point = checked(check, scenario, job.params, plan);
    if (!point) return;
    job.kind = job_kind;
    job.job_id = queue::job_id(queue::kind_name(job_kind), point->id_point.is_null() ? scenario : point->id_point);
    job.scenario_json = std::move(point->scenario_json);
    const std::string shared_id = queue::job_id(queue::kind_name(shared_kind), point->bed_key);
    plan.add_with_shared(std::move(job), shared_id, [&](const queue::PlannedJob& first) {
      queue::PlannedJob shared;
      shared.kind = shared_kind;
      shared.job_id = shared_id;
      shared.scenario_json = first.scenario_json;  // any point with this key prepares the same shared job
      shared.params = first.params;
      shared.priority = spec.priority + 1;  // shared inputs first: their points wait for them
      return shared;
    });
  };
}

decltype(SweepKind::check_base) base_checker(PointCheckFn check) {
  return [check = std::move(check)](const SweepSpec& spec) {
    auto swept = [&](const std::string& pointer) {
      for (const auto& g : spec.groups)
        for (const auto& ax : g.axes)
          if (pointer == ax.pointer || pointer.rfind(ax.pointer + "/", 0) == 0 ||
              ax.pointer.rfind(pointer + "/", 0) == 0)
            return true;
      return false;
    };
    std::vector<SpecProblem> problems;
    try {
      (void)check(spec.base);
    } catch (const SpecError& e) {
      for (const auto& p : e.problems())
        if (!swept(p.pointer)) problems.push_back({"/base" + p.pointer, p.found, p.expected});
    } catch (const std::exception&) {
      // Not checkable alone (e.g. a field every axis sets): the points report it.
    }
    return problems;
  };
}

}  // namespace gravsweep::sweep
