// The job kinds and states of the queue, typed, each with its one table of names (the names are
// what the database stores: jobs.kind, jobs.state). A kind's folder under the files root and its
// output file extension live in the same table row. The queue knows one kind of its own, noop (a
// job that runs no physics: queue tests and benchmarks); a library that plans and runs jobs
// registers its kinds (register_kind), as scheduler/sweep/impact_kinds.h does for the bed and
// the drop.
#pragma once
#include <nlohmann/json.hpp>

#include <cstddef>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace gravsweep::queue {

/// One field a job kind's runner reports (RunOutput::each_output) and the column of the
/// results table that holds it. The columns of the kinds a sweep plans are added at submit, so a
/// campaign's results table is known before any job finishes; a runner that reports a key its
/// kind does not declare fails its attempt (see check_outputs in queue.h).
struct OutputField {
  std::string key;   ///< metrics key and results column: lower case, digits, '_'; units in the name
  std::string unit;  ///< SI unit; "1" for counts and flags, "" for text
  std::string type;  ///< column type: REAL, INTEGER (counts, flags) or TEXT
  friend bool operator==(const OutputField&, const OutputField&) = default;
};

/// Appends the rows of a field table (results::MetricField, results::RecordField: a key, a unit
/// and sql_type()) to a kind's outputs: the table that writes a record also declares its columns.
template <class Fields>
void append_outputs(std::vector<OutputField>& outputs, const Fields& fields) {
  for (const auto& f : fields) outputs.push_back({f.key, f.unit, f.sql_type()});
}

struct JobKindInfo {
  std::string name;       ///< stored in jobs.kind
  std::string folder;     ///< outputs under <files root>/<folder>/
  std::string extension;  ///< of the output file, with the dot
  /// A finished job of this kind is a row of the results table (false: an input other jobs use,
  /// such as a prepared bed, whose output is found through its dependents).
  bool results_row = true;
  /// A job of this kind takes the whole worker pool's threads when no other job is waiting to run
  /// beside it (an input every dependent waits for: nothing else would use the idle threads).
  bool takes_idle_threads = false;
  /// What its runner reports: a column of the results table each (only for a kind whose finished
  /// job is a results row).
  std::vector<OutputField> outputs;
};

/// A job kind: its row in the table of registered kinds. The default is noop.
class JobKind {
 public:
  constexpr JobKind() = default;
  [[nodiscard]] std::size_t index() const { return index_; }
  friend bool operator==(JobKind a, JobKind b) { return a.index_ == b.index_; }
  friend bool operator!=(JobKind a, JobKind b) { return a.index_ != b.index_; }
  friend bool operator<(JobKind a, JobKind b) { return a.index_ < b.index_; }

 private:
  explicit JobKind(std::size_t index) : index_(index) {}
  std::size_t index_ = 0;
  friend JobKind register_kind(JobKindInfo info);
  friend std::vector<JobKind> registered_kinds();
  friend JobKind parse_kind(std::string_view name);
};

/// Adds a kind to the table (before any campaign is opened: its name enters the schema's check of
/// jobs.kind for new databases). Registering a name again returns its kind when the row is the
/// same; a different row under a known name, a folder another kind uses, or an output whose key is
/// not a plain column name (or given twice) or whose type is not REAL, INTEGER or TEXT throws
/// ConfigError.
JobKind register_kind(JobKindInfo info);
/// The queue's own kind: a job that runs no physics (JobKind{}).
inline JobKind noop_kind() { return JobKind{}; }
/// Every registered kind, in registration order (noop first).
std::vector<JobKind> registered_kinds();

const JobKindInfo& kind_info(JobKind k);
inline const char* kind_name(JobKind k) { return kind_info(k).name.c_str(); }
/// The kind named `name`; throws ConfigError listing the registered names.
JobKind parse_kind(std::string_view name);

enum class JobState { waiting, queued, running, failed, done, dead };

const char* state_name(JobState s);
/// The state named `name`; throws ConfigError listing the valid names.
JobState parse_state(std::string_view name);

/// Folders of the files root that hold job outputs (the registered kinds' folders, in order).
std::vector<std::string> kind_folders();
/// The kinds' folders, then tmp (temporary files of running attempts).
std::vector<std::string> output_folders();

inline bool operator==(JobKind k, std::string_view name) { return name == kind_name(k); }
inline bool operator!=(JobKind k, std::string_view name) { return !(k == name); }
inline bool operator==(JobState s, std::string_view name) { return name == state_name(s); }
inline bool operator!=(JobState s, std::string_view name) { return !(s == name); }
inline std::ostream& operator<<(std::ostream& os, JobKind k) { return os << kind_name(k); }
inline std::ostream& operator<<(std::ostream& os, JobState s) { return os << state_name(s); }

/// One job to submit: what a sweep's expansion (scheduler/sweep/spec.h) plans.
struct PlannedJob {
  std::string job_id;
  JobKind kind;  ///< noop unless set
  /// The scenario the job runs, as jobs.scenario_json stores it: text rather than a JSON tree,
  /// a fraction of the memory when a sweep plans many points (BENCHMARKS.md, "Sweep expansion").
  std::string scenario_json;
  nlohmann::json params;          ///< swept parameter values {column name: value}
  std::vector<std::string> deps;  ///< job ids this job waits for
  int priority = 0;
};

}  // namespace gravsweep::queue
