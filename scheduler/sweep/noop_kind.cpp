// The queue's no-op jobs as a sweep kind ("job": "noop"), for the scheduler's benchmark and tests:
// one job per point; the point's sleep_s, fail_attempts and value are what its runner reads.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "scheduler/queue/canonical.h"
#include "scheduler/sweep/sweep_kind.h"
#include "spec/json_pointer.h"
#include "spec/json_schema.h"

namespace gravsweep::sweep {

using nlohmann::json;

namespace {

/// A whole number from 0 to `most`.
bool is_count(const json& v, double most) {
  return spec::is_exact_integer(v) && v.get<double>() >= 0 && v.get<double>() <= most;
}

/// Problems of a no-op job's scenario at `ptr`: sleep_s, fail_attempts and value are what the
/// no-op runner reads (value: a number, its declared output noop_value); anything else is carried
/// along (an axis may sweep any field).
std::vector<SpecProblem> noop_problems(const json& s, const std::string& ptr) {
  std::vector<SpecProblem> out;
  if (!s.is_object()) return {{ptr, spec::shown_value(s), "an object (the no-op job's scenario)"}};
  if (s.contains("sleep_s") &&
      (!s["sleep_s"].is_number() || !(s["sleep_s"].get<double>() >= 0) || s["sleep_s"].get<double>() > 86400))
    out.push_back({spec::pointer_child(ptr, "sleep_s"), spec::shown_value(s["sleep_s"]),
                   "a number of seconds between 0 and 86400"});
  if (s.contains("fail_attempts") && !is_count(s["fail_attempts"], 100))
    out.push_back({spec::pointer_child(ptr, "fail_attempts"), spec::shown_value(s["fail_attempts"]),
                   "an integer between 0 and 100"});
  if (s.contains("value") && !s["value"].is_number())
    out.push_back({spec::pointer_child(ptr, "value"), spec::shown_value(s["value"]),
                   "a number (echoed as the metric noop_value)"});
  return out;
}

/// Sleeps sleep_s (stopping when asked), fails attempts up to fail_attempts, writes a small JSON
/// output and echoes `value` as the metric noop_value.
queue::RunOutput run_noop(const queue::RunContext& ctx) {
  const json& s = ctx.claim.scenario;
  const double sleep_s = s.value("sleep_s", 0.0);
  const int fail_attempts = s.value("fail_attempts", 0);
  ctx.progress("noop", 0.0, "");
  if (sleep_s > 0) {
    const auto t0 = std::chrono::steady_clock::now();
    for (;;) {
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (el >= sleep_s) break;
      if (ctx.stop && ctx.stop->load()) throw std::runtime_error("noop job stopped");
      ctx.progress("noop", el / sleep_s, fmt::format("{:.2f}/{:.2f} s", el, sleep_s));
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  if (ctx.claim.attempt <= fail_attempts)
    throw std::runtime_error(
        fmt::format("noop job asked to fail on attempt {} (fail_attempts={})", ctx.claim.attempt, fail_attempts));
  // A write error (a full disk, no file descriptor left) fails the attempt with its errno.
  queue::write_file_synced(ctx.output_tmp, json{{"job_id", ctx.claim.job_id}, {"attempt", ctx.claim.attempt}}.dump());
  queue::RunOutput out;
  out.values["noop_value"] = s.contains("value") ? s["value"] : json(0);
  out.values["sleep_s"] = sleep_s;
  return out;
}

}  // namespace

SweepKind noop_sweep_kind() {
  SweepKind k;
  k.name = "noop";
  k.summary = "no-op jobs for the scheduler's benchmark and tests (fields sleep_s, fail_attempts, value)";
  k.check_base = [](const SweepSpec& spec) { return noop_problems(spec.base, "/base"); };
  k.plan_point = [](const SweepSpec&, const json& scenario, queue::PlannedJob job, Plan& plan) {
    for (auto& p : noop_problems(scenario, "/base")) plan.problem(std::move(p), job.params);
    job.kind = queue::noop_kind();
    job.job_id = queue::job_id(queue::kind_name(job.kind), scenario);
    job.scenario_json = queue::canonical_json(scenario);
    plan.add(std::move(job));
  };
  k.runners = {{queue::noop_kind(), run_noop}};
  return k;
}

}  // namespace gravsweep::sweep
