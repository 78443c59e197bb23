#include "scheduler/pipeline/impact_runners.h"

#include <fmt/format.h>

#include "engine/core/error.h"
#include "scheduler/pipeline/bed_cache.h"
#include "scheduler/pipeline/impact_job.h"
#include "scheduler/pipeline/scenario_defaults.h"
#include "scheduler/pipeline/scenario_spec.h"
#include "scheduler/queue/stop.h"
#include "scheduler/sweep/impact_kinds.h"

namespace gravsweep::pipeline {

using queue::RunContext;
using queue::RunnerTable;
using queue::RunOutput;

namespace {

/// The job's checkpoints as the worker configured them: saved on SIGTERM (the process's stop
/// flag), not when another worker took the lease over.
Checkpointing checkpointing_of(const RunContext& ctx) {
  Checkpointing ckpt;
  ckpt.path = ctx.checkpoint;
  ckpt.interval_s = ctx.checkpoint_interval_s;
  ckpt.attempt = ctx.claim.attempt;
  ckpt.save_on_stop = &queue::stop_requested();
  ckpt.progress_saved = ctx.progress_saved;
  return ckpt;
}

/// Refuses, before anything is allocated, a job whose scenario needs more memory than `work
/// --max-memory` allows (ConfigError: permanent), whatever its validation mark says.
void check_memory(const RunContext& ctx) {
  if (!(ctx.max_memory_bytes > 0)) return;
  const Scenario s = job_scenario_record(ctx.claim.scenario);
  const double need = job_memory_bytes(s);
  if (need > ctx.max_memory_bytes)
    throw ConfigError(fmt::format(
        "job {}: its bed (/grains/diameter_m {:g} m in /container/diameter_m {:g} m filled to "
        "/container/fill_height_m {:g} m: up to {:.3g} grains) needs about {:.3g} MB, above work --max-memory "
        "{:.3g} MB",
        ctx.claim.job_id, s.grains.diameter_m, s.container.diameter_m, s.container.fill_height_m, bed_grain_bound(s),
        need / 1048576.0, ctx.max_memory_bytes / 1048576.0));
}

}  // namespace

sweep::PointCheckFn impact_point_check() {
  return [](const nlohmann::json& point) {
    const nlohmann::json current = with_current_defaults(point);  // a new spec: today's defaults
    nlohmann::json validated = validate_scenario(current);
    nlohmann::json key = bed_key_of_validated(validated);
    // The point as the job keeps it names its defaults version only where the version changes
    // what it runs: a worker of an older build then runs every other job as before.
    nlohmann::json as_written = id_point(current, validated);
    if (!as_written.contains("defaults_version")) validated.erase("defaults_version");
    std::string stored = StoredScenario::of_this_build(std::move(validated), as_written).to_json().dump();
    return sweep::CheckedPoint{std::move(stored), std::move(key), std::move(as_written)};
  };
}

namespace {

RunOutput run_bed(const RunContext& ctx) {
  check_memory(ctx);
  RunOutput out;
  if (!ctx.bed_cache.empty()) {
    if (auto cached = take_cached_bed(ctx.bed_cache, ctx.claim.job_id, ctx.claim.scenario, ctx.output_tmp)) {
      out.report = *cached;
      return out;
    }
  }
  auto r = run_bed_job(ctx.claim.scenario, ctx.output_tmp, ctx.threads, ctx.progress, ctx.stop, checkpointing_of(ctx));
  if (r.bed_path != ctx.output_tmp && !r.bed_path.empty()) std::filesystem::rename(r.bed_path, ctx.output_tmp);
  if (!ctx.bed_cache.empty()) store_cached_bed(ctx.bed_cache, ctx.claim.job_id, ctx.output_tmp);
  out.report = results::to_json(r.report);
  return out;
}

RunOutput run_drop(const RunContext& ctx) {
  if (ctx.dependency_output.empty())
    throw std::runtime_error(fmt::format("drop job {} has no prepared bed", ctx.claim.job_id));
  check_memory(ctx);
  auto r = run_drop_job(ctx.claim.scenario, ctx.dependency_output, ctx.output_tmp, ctx.threads, ctx.progress, ctx.stop,
                        checkpointing_of(ctx));
  if (r.trace_path != ctx.output_tmp && !r.trace_path.empty()) std::filesystem::rename(r.trace_path, ctx.output_tmp);
  if (!r.snapshot_path.empty()) {
    // Grain snapshots (/output/snapshot_interval_s > 0): <campaign>.files/snapshots/, a folder that
    // `resume` leaves alone (they are for viewing; no job refers to them).
    const auto dir = ctx.output_tmp.parent_path().parent_path() / "snapshots";
    std::filesystem::create_directories(dir);
    for (const auto& f : {r.snapshot_path, r.snapshot_xdmf}) std::filesystem::rename(f, dir / f.filename());
  }
  return r;  // its RunOutput, moved as it is
}

}  // namespace

sweep::SweepKind impact_sweep_kind() {
  sweep::SweepKind k;
  k.name = "impact";
  k.summary = "a drop per point on the engine, waiting for a prepared bed per bed key";
  k.check_base = sweep::base_checker(impact_point_check());
  k.plan_point = sweep::shared_input_planner(impact_point_check(), sweep::drop_kind(), sweep::bed_kind());
  k.runners = {{sweep::bed_kind(), run_bed}, {sweep::drop_kind(), run_drop}};
  return k;
}

}  // namespace gravsweep::pipeline
