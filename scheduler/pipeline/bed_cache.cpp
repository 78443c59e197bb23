#include "scheduler/pipeline/bed_cache.h"

#include <fmt/format.h>
#include <unistd.h>

#include "engine/core/error.h"
#include "scheduler/pipeline/impact_job.h"
#include "scheduler/pipeline/scenario_spec.h"

namespace gravsweep::pipeline {
namespace fs = std::filesystem;
using json = nlohmann::json;

fs::path cached_bed_path(const fs::path& cache, const std::string& bed_job_id) { return cache / (bed_job_id + ".h5"); }

std::optional<json> take_cached_bed(const fs::path& cache, const std::string& bed_job_id, const json& scenario,
                                    const fs::path& bed_out) {
  const fs::path cached = cached_bed_path(cache, bed_job_id);
  std::error_code ec;
  if (!fs::exists(cached, ec)) return std::nullopt;
  if (!fs::exists(bed_checksum_path(cached), ec))
    throw ConfigError(
        fmt::format("bed cache: {} has no checksum file {}: it cannot be verified; delete it or "
                    "restore its checksum file",
                    cached.string(), bed_checksum_path(cached).string()));
  results::BedFacts bed;
  try {
    bed = read_user_bed(cached, nullptr);  // checksum verified here
    require_bed_key(bed, job_scenario(scenario), cached);
  } catch (const ConfigError& e) {
    throw ConfigError(fmt::format("bed cache: {}; delete {} and its checksum file to prepare the bed again", e.what(),
                                  cached.string()));
  }
  const fs::path tmp = bed_out.string() + ".from-cache";
  fs::copy_file(cached, tmp, fs::copy_options::overwrite_existing);
  fs::rename(tmp, bed_out);
  json report = json::object();
  try {
    report = json::parse(bed.report_json);
  } catch (const json::exception&) {
    report = json::object();
  }
  report["from_cache"] = cached.string();
  return report;
}

void store_cached_bed(const fs::path& cache, const std::string& bed_job_id, const fs::path& bed) {
  const fs::path dest = cached_bed_path(cache, bed_job_id);
  std::error_code ec;
  if (fs::exists(dest, ec) && fs::exists(bed_checksum_path(dest), ec)) return;
  fs::create_directories(cache);
  // Another worker may store the same bed at once: each writes its own temporary file.
  const fs::path tmp = cache / fmt::format(".{}.h5.{}.tmp", bed_job_id, ::getpid());
  fs::copy_file(bed, tmp, fs::copy_options::overwrite_existing);
  write_bed_checksum(tmp, dest);  // the checksum first: a bed in the cache always has one
  fs::rename(tmp, dest);
}

}  // namespace gravsweep::pipeline
