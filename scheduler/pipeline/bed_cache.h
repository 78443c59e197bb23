// A folder of prepared beds shared between campaigns and machines (`gravsweep work --bed-cache DIR`).
// A bed is named by its bed job id (queue::job_id("bed", bed_key)): <DIR>/<bed job id>.h5 with its
// checksum file <bed job id>.h5.sha256 (bed_checksum_path). A bed job whose bed is in the folder
// copies it instead of preparing it again (a paper-sized bed takes minutes to an hour); a bed job
// that prepared its bed stores it there. The file is verified on the way in (checksum and bed key):
// a cached bed that fails either is an error naming the file, never used silently.
#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace gravsweep::pipeline {

/// <cache>/<bed_job_id>.h5
std::filesystem::path cached_bed_path(const std::filesystem::path& cache, const std::string& bed_job_id);

/// When the cache holds the bed of `scenario` (bed job `bed_job_id`): verifies its checksum file and
/// bed key, copies it to bed_out and returns its preparation report (bed.h5's report, plus
/// "from_cache": the cached file). std::nullopt when the cache has no such file. Throws ConfigError
/// naming the cached file when it has no checksum file, does not match it, or holds another bed key.
std::optional<nlohmann::json> take_cached_bed(const std::filesystem::path& cache, const std::string& bed_job_id,
                                              const nlohmann::json& scenario, const std::filesystem::path& bed_out);

/// Copies a prepared bed into the cache under its job id, with its checksum file (temporary names,
/// then rename: a reader never sees half a bed). Creates the folder. Keeps an existing entry.
void store_cached_bed(const std::filesystem::path& cache, const std::string& bed_job_id,
                      const std::filesystem::path& bed);

}  // namespace gravsweep::pipeline
