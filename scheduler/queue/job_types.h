// The job kinds and states of the queue, typed, each with its one table of names (the names are
// what the database stores: jobs.kind, jobs.state). A kind's folder under the files root and its
// output file extension live in the same table row.
#pragma once
#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace gravsweep::queue {

enum class JobKind { bed, drop, noop };
enum class JobState { waiting, queued, running, failed, done, dead };

struct JobKindInfo {
  JobKind kind;
  const char* name;       ///< stored in jobs.kind
  const char* folder;     ///< outputs under <files root>/<folder>/
  const char* extension;  ///< of the output file, with the dot
  /// A finished job of this kind is a row of the results table (false: an input other jobs use,
  /// such as a prepared bed, whose output is found through its dependents).
  bool results_row;
  /// A job of this kind takes the whole worker pool's threads when no other job is waiting to run
  /// beside it (an input every dependent waits for: nothing else would use the idle threads).
  bool takes_idle_threads;
};

/// The one table of kinds (in enum order).
const JobKindInfo& kind_info(JobKind k);
inline const char* kind_name(JobKind k) { return kind_info(k).name; }
/// The kind named `name`; throws ConfigError listing the valid names.
JobKind parse_kind(std::string_view name);

const char* state_name(JobState s);
/// The state named `name`; throws ConfigError listing the valid names.
JobState parse_state(std::string_view name);

/// Folders of the files root that hold job outputs (the kinds' folders, in kind order).
const std::vector<std::string>& kind_folders();
/// The kinds' folders, then tmp (temporary files of running attempts).
const std::vector<std::string>& output_folders();

inline bool operator==(JobKind k, std::string_view name) { return name == kind_name(k); }
inline bool operator!=(JobKind k, std::string_view name) { return !(k == name); }
inline bool operator==(JobState s, std::string_view name) { return name == state_name(s); }
inline bool operator!=(JobState s, std::string_view name) { return !(s == name); }
inline std::ostream& operator<<(std::ostream& os, JobKind k) { return os << kind_name(k); }
inline std::ostream& operator<<(std::ostream& os, JobState s) { return os << state_name(s); }

/// One job to submit: what a sweep's expansion (scheduler/sweep/spec.h) plans.
struct PlannedJob {
  std::string job_id;
  JobKind kind = JobKind::noop;
  nlohmann::json scenario;        ///< canonical scenario the job runs
  nlohmann::json params;          ///< swept parameter values {column name: value}
  std::vector<std::string> deps;  ///< job ids this job waits for
  int priority = 0;
};

}  // namespace gravsweep::queue
