// Job-level API of one impact (Sunday et al. 2021 Sect. 2.2-2.3): prepare a bed and save it
// (bed.h5), drop the projectile into a saved bed, record the trace (trace.h5) and compute the
// paper's metrics. Used by `gravsweep run` and by the queue's worker processes. Beds are shared
// between drops whose bed_key() is equal (the paper's repeats: same bed, other speeds/offsets).
#pragma once
#include <atomic>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "engine/system/system.h"
#include "results/io/bed_file.h"
#include "results/io/job_reports.h"
#include "scheduler/pipeline/job_checkpoint.h"
#include "scheduler/queue/run_output.h"
#include "spec/json_schema.h"

namespace gravsweep::pipeline {

/// progress(phase, fraction of the phase in [0, 1], detail); phases: fill, settle, flatten, drop.
using Progress = std::function<void(const std::string& phase, double fraction, const std::string& detail)>;

/// The `stop` flag was raised; the job left no output file behind.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct BedJobResult {
  std::filesystem::path bed_path;
  results::BedSummary report;  ///< the preparation's report, as bed.h5's `report` holds it
};

/// The drop's outputs as its runner reports them (record: a sweep::DropOutputs, the drop's own
/// record: the paper's metrics vc_m_s, apeak_m_s2, zstop_m, tstop_s, rebound, ..., the trace and
/// the engine's result, from which the DEM's figures, wall_time_s, ... are read) with the files it
/// wrote.
struct DropJobResult : queue::RunOutput {
  std::filesystem::path trace_path;
  /// Grain snapshots (/output/snapshot_interval_s > 0): the .h5 and its .xdmf index, else empty.
  std::filesystem::path snapshot_path, snapshot_xdmf;
  std::size_t snapshots = 0, snapshot_bytes = 0;  ///< count, state bytes per snapshot
};

/// Validates `scenario` unless this build validated it at submit (job_scenario; throws SpecError,
/// a ConfigError, with the JSON pointer on bad input), prepares the bed and writes it to bed_out (HDF5), written under
/// a temporary name then renamed. threads <= 0: the scenario's "threads", else OpenMP's default.
/// With checkpointing.path set, it continues the preparation saved there if that checkpoint is
/// usable, saves it there as job_checkpoint.h says, and removes it once the bed is written.
BedJobResult run_bed_job(const nlohmann::json& scenario, const std::filesystem::path& bed_out, int threads,
                         const Progress& progress, const std::atomic<bool>* stop,
                         const Checkpointing& checkpointing = {});

/// Validates `scenario` unless this build validated it at submit (job_scenario), loads the bed (its
/// key must equal the validated scenario's, bed_key_of_validated), drops the projectile, writes the trace
/// (HDF5, temporary name then rename) and returns the outputs: the paper's vc, apeak, zstop, tstop,
/// rebound, plus the DEM's figures and wall time. A collision the metrics cannot resolve (e.g. no
/// contact before the time cap) is not an error: the outputs carry "metrics_error" with the
/// reason, and null values.
/// With /output/snapshot_interval_s > 0 it also writes results::snapshot_path_for(trace_out) and its XDMF.
/// With checkpointing.path set, it continues the drop saved there if that checkpoint is usable,
/// saves the drop there as job_checkpoint.h says, and removes it once the trace is written.
DropJobResult run_drop_job(const nlohmann::json& scenario, const std::filesystem::path& bed_in,
                           const std::filesystem::path& trace_out, int threads, const Progress& progress,
                           const std::atomic<bool>* stop, const Checkpointing& checkpointing = {});

/// Canonical key of the bed a scenario needs (container, grains, fill, gravity, materials, contact
/// law, preparation settings and seed): drops with equal keys share a bed. Validates the scenario.
nlohmann::json bed_key(const nlohmann::json& scenario);
/// The same for a scenario validate_scenario (or job_scenario) returned, without validating it again.
nlohmann::json bed_key_of_validated(const nlohmann::json& validated);

/// `<bed>.sha256`, beside a bed that `gravsweep run` prepared: the bed file's SHA-256, the checksum
/// a campaign records for its beds (queue::sha256_file), as sha256sum writes it ("<hex>  <name>").
std::filesystem::path bed_checksum_path(const std::filesystem::path& bed);
/// Writes bed_checksum_path(named) (temporary name, then rename) with the SHA-256 of `bed`;
/// `named` empty: bed_checksum_path(bed).
void write_bed_checksum(const std::filesystem::path& bed, const std::filesystem::path& named = {});

/// A bed named on the command line (`run --bed`, `bench --bed`) or found in the bed cache, read and
/// verified, its facts returned: throws ConfigError naming the file (exit 2) when it is missing,
/// not a gravsweep bed, cut short or corrupt, or does not match its checksum file. A bed without a
/// checksum file (written before gravsweep recorded one, or copied without it) is read unverified
/// and `*unverified` says why.
results::BedFacts read_user_bed(const std::filesystem::path& bed, std::string* unverified);
/// The same, the bed loaded into `sys` (results::load_bed: a System holding no particle yet).
results::BedFacts load_user_bed(System& sys, const std::filesystem::path& bed, std::string* unverified);

/// Throws ConfigError naming `bed_path` and the first differing field (JSON pointer) when the bed
/// was prepared for another bed key than `scenario`'s (as validate_scenario() returns it).
void require_bed_key(const results::BedFacts& bed, const nlohmann::json& scenario,
                     const std::filesystem::path& bed_path);

}  // namespace gravsweep::pipeline
