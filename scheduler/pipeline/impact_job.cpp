#include "scheduler/pipeline/impact_job.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <utility>

#include "engine/core/error.h"
#include "engine/scenario/bed.h"
#include "engine/scenario/impact.h"
#include "engine/scenario/paper_params.h"
#include "results/io/bed_file.h"
#include "results/io/engine_records.h"
#include "results/io/job_reports.h"
#include "results/io/snapshot_file.h"
#include "results/io/trace_file.h"
#include "results/measurements/campaign.h"
#include "results/processing/trace.h"
#include "scheduler/pipeline/build_version.h"
#include "scheduler/pipeline/scenario_spec.h"
#include "scheduler/queue/canonical.h"
#include "scheduler/sweep/impact_kinds.h"

namespace gravsweep::pipeline {

using nlohmann::json;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void check_stop(const std::atomic<bool>* stop, const char* what) {
  if (stop && stop->load(std::memory_order_relaxed)) throw Interrupted(fmt::format("{} interrupted", what));
}

/// JSON pointer of the first difference between two keys, for messages.
std::string first_difference(const json& a, const json& b) {
  const json patch = json::diff(a, b);
  return patch.empty() ? std::string() : patch[0].value("path", std::string("/"));
}

/// The slowest impact a bed in this state is at rest for under the fractions of /at_rest.
double slowest_impact_at_rest_m_s(const BedRestState& r, const AtRestSettings& c) {
  return std::max(r.max_surface_speed_m_s / c.surface_speed_fraction, r.rms_speed_m_s / c.rms_speed_fraction);
}

/// Refuses a bed whose grains still move too fast for this drop's impact (/at_rest), with the
/// figures; `projectile` is the drop's (its start drawn: the impact axis).
void require_at_rest(const System& sys, const results::BedFacts& bed, const Scenario& s,
                     const ProjectileSpec& projectile, const std::filesystem::path& bed_path) {
  const AtRestSettings& c = s.at_rest;
  const double radius_D = c.surface_radius_D.value_or(0.0);  // 0: the whole surface
  // The whole bed, or the part about the impact axis.
  SurfaceWindow window;
  std::string where, there;
  if (radius_D > 0) {
    window = {projectile.lateral_offset_x_m, projectile.lateral_offset_y_m, radius_D * projectile.diameter_m};
    where =
        fmt::format(" within {:.3g} m of the impact axis (/at_rest/surface_radius_D: {:g})", window.radius_m, radius_D);
    there = " there";
  }
  const BedRestState r = bed_rest_state(sys, bed.surface_height_m, s.grains.diameter_m, window);
  const double v = s.reference_impact_speed_m_s();
  if (r.max_surface_speed_m_s < c.surface_speed_fraction * v && r.rms_speed_m_s < c.rms_speed_fraction * v) return;
  throw ConfigError(fmt::format(
      "bed {} is not at rest for an impact at {:.4g} m/s: its fastest surface grain{} moves at {:.3g} m/s (at "
      "most {:g} of the impact speed allowed, /at_rest/surface_speed_fraction: {:.3g} m/s) and its RMS grain "
      "speed{} is {:.3g} m/s (at most {:g}: {:.3g} m/s); it is at rest for impacts of at least {:.3g} m/s. "
      "Settle the bed longer (/bed/settle) or drop faster",
      bed_path.string(), v, where, r.max_surface_speed_m_s, c.surface_speed_fraction, c.surface_speed_fraction * v,
      there, r.rms_speed_m_s, c.rms_speed_fraction, c.rms_speed_fraction * v, slowest_impact_at_rest_m_s(r, c)));
}

/// Runs `run` continuing ckpt's checkpoint (`resuming`); when the engine refuses that state, the
/// checkpoint is discarded with a warning and the run starts over (the refused state changed nothing).
template <class Run>
auto resume_or_start(JobCheckpointer& ckpt, bool resuming, const Run& run) {
  if (!resuming) return run();
  try {
    return run();
  } catch (const std::invalid_argument& e) {
    ckpt.discard(e.what());
    return run();
  }
}

}  // namespace

json bed_key_of_validated(const json& s) {
  json k;
  k["bed_format_version"] = results::kBedFormatVersion;
  k["container"] = s.at("container");
  k["grains"] = s.at("grains");
  k["gravity_m_s2"] = s.at("gravity_m_s2");
  // The bed's own materials (/bed/materials, when given) are the ones it is prepared with: a bed
  // prepared with them has the key of a scenario whose /materials are those, so drops that differ
  // from it only in their materials reuse it (scenario.schema.json, /bed/materials).
  json bed = s.at("bed");
  k["materials"] = bed.contains("materials") ? bed.at("materials") : s.at("materials");
  bed.erase("materials");
  k["contact"] = s.at("contact");
  k["integrator"] = s.at("integrator");
  k["bed"] = bed;
  return k;
}

json bed_key(const json& scenario) { return bed_key_of_validated(validate_scenario(scenario)); }

namespace {

/// Writes the prepared bed and its report (with the checkpoints' counts) to bed_out; removes the
/// checkpoint once the bed is written.
BedJobResult write_prepared_bed(const System& sys, const BedReport& rep, const Scenario& s, const json& validated,
                                const std::filesystem::path& bed_out, double wall_s, JobCheckpointer& ckpt,
                                const std::atomic<bool>* stop) {
  results::BedFacts b = results::bed_facts_of(sys);
  const BedRestState rest = bed_rest_state(sys, rep.surface_height_m, s.grains.diameter_m);
  b.container_diameter_m = s.container.diameter_m;
  b.fill_height_m = s.container.fill_height_m;
  b.surface_height_m = rep.surface_height_m;
  b.gravity_m_s2 = s.gravity_m_s2;
  b.code_version = pipeline::build_version();
  b.bed_key_json = bed_key_of_validated(validated).dump();
  b.scenario_json = validated.dump();
  results::BedSummary r = results::bed_summary_of(sys, rep, rest, slowest_impact_at_rest_m_s(rest, s.at_rest));
  r.wall_time_s = wall_s;
  results::set_checkpoint_counts(r, ckpt.counts());
  b.report_json = results::to_json(r).dump();
  check_stop(stop, "bed preparation");
  results::write_bed(bed_out, sys.particles, b);
  ckpt.finished();
  return BedJobResult{bed_out, r};
}
}  // namespace

BedJobResult run_bed_job(const json& scenario, const std::filesystem::path& bed_out, int threads,
                         const Progress& progress, const std::atomic<bool>* stop, const Checkpointing& checkpointing) {
  const json validated = job_scenario(scenario);
  const Scenario s = scenario_of(validated);
  SystemConfig config = s.bed_config();
  if (threads > 0) config.threads = threads;
  const BedSpec spec = s.bed_spec();
  check_stop(stop, "bed preparation");
  const auto t0 = std::chrono::steady_clock::now();
  std::unique_ptr<System> sys;
  JobCheckpointer ckpt(
      checkpointing, "bed",
      checkpointing.path.empty() ? json() : bed_identity(bed_key_of_validated(validated), config.threads), stop);
  // Sect. 2.2: mix and settle, flatten, relax; the relaxation is reported as part of "flatten".
  const auto prepare = [&] {
    sys = std::make_unique<System>(config);  // a fresh system for each try (a refused resume)
    return prepare_bed(
        *sys, spec,
        [&](BedPhase ph, double f, const std::string& d) {
          check_stop(stop, "bed preparation");
          if (!progress) return;
          if (ph == BedPhase::relax)
            progress("flatten", f, ckpt.detail("relaxing the surface: " + d));
          else
            progress(to_string(ph), f, ckpt.detail(d));
        },
        ckpt.bed_hooks());
  };
  const BedReport rep = resume_or_start(ckpt, ckpt.resume_bed() != nullptr, prepare);
  const double wall_s = seconds_since(t0) + ckpt.prior_wall_time_s();
  return write_prepared_bed(*sys, rep, s, validated, bed_out, wall_s, ckpt, stop);
}

std::filesystem::path bed_checksum_path(const std::filesystem::path& bed) { return bed.string() + ".sha256"; }

void write_bed_checksum(const std::filesystem::path& bed, const std::filesystem::path& named) {
  const auto& as = named.empty() ? bed : named;
  const auto path = bed_checksum_path(as), tmp = std::filesystem::path(path.string() + ".tmp");
  {
    std::ofstream f(tmp);
    f << queue::sha256_file(bed) << "  " << as.filename().string() << "\n";
    if (!f.flush()) throw std::runtime_error(fmt::format("{}: cannot write", tmp.string()));
  }
  std::filesystem::rename(tmp, path);
}

namespace {

/// Checks a bed named by the user against its checksum file (see read_user_bed), then reads it by
/// `read`, its errors as ConfigError naming the file.
template <class Read>
results::BedFacts verified_bed(const std::filesystem::path& bed, std::string* unverified, const Read& read) {
  constexpr std::size_t kHexDigits = 64;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(bed, ec))
    throw ConfigError(fmt::format("bed {}: {}", bed.string(),
                                  std::filesystem::exists(bed, ec) ? "not a regular file" : "no such file"));
  const auto sum_path = bed_checksum_path(bed);
  if (std::filesystem::exists(sum_path, ec)) {
    std::ifstream f(sum_path);
    std::string recorded;
    f >> recorded;
    if (recorded.size() != kHexDigits || recorded.find_first_not_of("0123456789abcdef") != std::string::npos)
      throw ConfigError(fmt::format("bed {}: its checksum file {} does not hold a SHA-256 (64 hex digits)",
                                    bed.string(), sum_path.string()));
    const std::string found = queue::sha256_file(bed);
    if (found != recorded)
      throw ConfigError(fmt::format(
          "bed {} does not match its checksum ({}): sha256 {}, recorded {} when it was written; the file "
          "changed since (one flipped bit changes every drop's results): prepare the bed again (omit --bed)",
          bed.string(), sum_path.string(), found, recorded));
  } else if (unverified) {
    *unverified = fmt::format(
        "bed {} has no checksum file {} (written before `run` recorded one, or copied "
        "without it): it cannot be verified",
        bed.string(), sum_path.string());
  }
  try {
    return read(bed);
  } catch (const std::exception& e) {  // HDF5 layer: cut short, random bytes, missing datasets
    throw ConfigError(fmt::format("bed {}: not a readable gravsweep bed file: {}", bed.string(), e.what()));
  }
}

}  // namespace

results::BedFacts read_user_bed(const std::filesystem::path& bed, std::string* unverified) {
  return verified_bed(bed, unverified, [](const std::filesystem::path& b) { return results::read_bed(b); });
}

results::BedFacts load_user_bed(System& sys, const std::filesystem::path& bed, std::string* unverified) {
  return verified_bed(bed, unverified, [&](const std::filesystem::path& b) { return results::load_bed(sys, b); });
}

void require_bed_key(const results::BedFacts& bed, const json& scenario, const std::filesystem::path& bed_path) {
  const json want = bed_key_of_validated(scenario);
  json have;
  try {
    have = json::parse(bed.bed_key_json);
  } catch (const json::exception&) {
    throw ConfigError(fmt::format("bed {}: the bed_key attribute is not valid JSON", bed_path.string()));
  }
  if (have == want) return;
  const json::json_pointer at(first_difference(have, want));
  throw ConfigError(
      fmt::format("bed {} was prepared for another scenario: its bed key differs at {} (found {}, the scenario "
                  "needs {}); prepare a bed for this scenario (omit --bed)",
                  bed_path.string(), at.to_string(), have.contains(at) ? have[at].dump() : "nothing",
                  want.contains(at) ? want[at].dump() : "nothing"));
}

namespace {

/// The drop's grain snapshots (/output/snapshot_interval_s > 0; none otherwise): the grains keep
/// the order of bed.h5, the projectile comes last. `snaps` receives the writer.
DropSnapshots snapshot_hooks(const Scenario& s, const std::vector<double>& grain_radius_m,
                             const std::filesystem::path& trace_out, std::unique_ptr<results::SnapshotWriter>& snaps) {
  DropSnapshots ds;
  const double interval_s = s.output.snapshot_interval_s;
  if (!(interval_s > 0)) return ds;
  snaps = std::make_unique<results::SnapshotWriter>(results::snapshot_path_for(trace_out), grain_radius_m,
                                                    0.5 * s.projectile.diameter_m, interval_s, build_version());
  ds.interval_s = interval_s;
  ds.write = [w = snaps.get()](const System& sy, ParticleIndex ip, double t_s) {
    w->append(results::snapshot_of(sy, ip, t_s));
  };
  return ds;
}

/// The drop's record as a trace (its samples' columns taken over, `dr.samples` left empty), with
/// the facts a reader of the trace needs (scenario, bed key and file, code version), each written
/// where the trial it is measured as reads it.
results::TraceData trace_of(DropResult& dr, const Scenario& s, const json& validated, const results::BedFacts& bed,
                            const std::filesystem::path& bed_in) {
  results::TraceData td = results::take_trace_columns(dr, s.output.sample_rate_hz);
  results::Trial& trial = td.info;
  trial.gravity_m_s2 = s.gravity_m_s2;
  trial.fill_height_m = bed.surface_height_m;  // the measured surface: the depth's zero
  trial.projectile_diameter_m = s.projectile.diameter_m;
  trial.projectile_mass_kg = s.projectile.mass_kg;
  trial.grain_diameter_m = s.grains.diameter_m;
  trial.code_version = pipeline::build_version();
  td.dt_s = s.dt_s;
  td.scenario_json = validated.dump();
  td.bed_key_json = bed_key_of_validated(validated).dump();
  td.bed_file = std::filesystem::absolute(bed_in).string();
  return td;
}

/// Sect. 2.3 through the one processing entry (results::process_trial), on the trace record in
/// place (it is the trial: its processed trace and metrics are written into it): the scenario's
/// /output settings, as a campaign reading this trace back measures it (the trial's impact speed,
/// which processing uses only for a trace without its own velocity, is the release speed here and
/// the measured vc there). False, and `error` why, when the trace cannot be measured.
bool measure(results::TraceData& td, const std::filesystem::path& trace_out, std::string& error) {
  try {
    results::prepare_dem_trial(td, {"", "", trace_out});
    results::process_trial(td);
    return true;
  } catch (const std::exception& e) {
    error = e.what();
    return false;
  }
}

}  // namespace

DropJobResult run_drop_job(const json& scenario, const std::filesystem::path& bed_in,
                           const std::filesystem::path& trace_out, int threads, const Progress& progress,
                           const std::atomic<bool>* stop, const Checkpointing& checkpointing) {
  const json validated = job_scenario(scenario);
  const Scenario s = scenario_of(validated);
  SystemConfig config = s.drop_config();
  if (threads > 0) config.threads = threads;
  // The bed in a fresh system: bit-exact state, no contact history (as after any restart).
  System sys(config);
  const results::BedFacts bed = results::load_bed(sys, bed_in);
  const std::size_t bed_grains = sys.particles.size();
  require_bed_key(bed, validated, bed_in);
  check_stop(stop, "drop");
  const auto t0 = std::chrono::steady_clock::now();
  const ProjectileSpec projectile = s.projectile_spec();
  require_at_rest(sys, bed, s, projectile, bed_in);

  std::unique_ptr<results::SnapshotWriter> snaps;
  const DropSnapshots ds = snapshot_hooks(s, sys.particles.radius_m, trace_out, snaps);
  JobCheckpointer ckpt(checkpointing, "drop",
                       checkpointing.path.empty() ? json() : drop_identity(validated, bed_in, sys.threads()), stop);
  const auto drop = [&] {
    return drop_projectile(
        sys, bed.surface_height_m, projectile, s.drop_stop(), s.output.sample_rate_hz,
        [&](double f, const std::string& d) {
          check_stop(stop, "drop");
          if (progress) progress("drop", f, ckpt.detail(d));
        },
        ds, ckpt.drop_hooks(), s.drop_time_step());
  };
  DropResult dr = resume_or_start(ckpt, ckpt.resume_drop() != nullptr, drop);
  const double wall_s = seconds_since(t0) + ckpt.prior_wall_time_s();

  // The run's outputs are its records themselves, moved into what the runner returns (no copy
  // into JSON or into a record of figures): the trace with its metrics, the engine's result.
  auto outputs = std::make_shared<sweep::DropOutputs>();
  results::DropRecord& rec = *outputs;
  rec.trace = trace_of(dr, s, validated, bed, bed_in);
  rec.result = std::move(dr);
  rec.measured = measure(rec.trace, trace_out, rec.metrics_error);
  rec.bed_grains = static_cast<long long>(bed_grains);
  rec.lateral_offset_m = std::hypot(projectile.lateral_offset_x_m, projectile.lateral_offset_y_m);
  rec.threads = sys.threads();
  rec.wall_time_s = wall_s;
  rec.checkpoints = ckpt.counts();
  check_stop(stop, "drop");
  DropJobResult out;
  out.trace_path = trace_out;
  out.record = outputs;
  rec.trace.metrics_json = out.outputs_json().dump();  // the trace's text, written from the record
  if (snaps) {
    out.snapshots = snaps->count();
    out.snapshot_bytes = snaps->bytes_per_snapshot();
    out.snapshot_path = results::snapshot_path_for(trace_out);
    out.snapshot_xdmf = snaps->finish();
  }
  results::write_trace(trace_out, rec.trace);
  ckpt.finished();
  return out;
}

}  // namespace gravsweep::pipeline
