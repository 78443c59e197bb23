// The job queue on SQLite (see scheduler/queue/README.md; the reasons: docs/queue.md): jobs with
// content-addressed ids, dependencies (drop jobs wait for their bed job), claims in BEGIN IMMEDIATE
// with UPDATE ... RETURNING, leases renewed by heartbeats that carry progress, completion fenced by
// the lease token, retries with exponential backoff, a `dead` state after max_attempts, one
// attempts row per try, and a results table with one column per swept parameter and per output
// a job kind declares (both added at submit).
//
// Job states: waiting (dependencies not done) -> queued -> running -> done
//                                                         \-> failed (backoff) -> running ...
//                                                         \-> dead (budget spent / permanent error)
// Every function opens and commits its own short transaction; none is held while a job runs.
#pragma once
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "db/database.h"
#include "scheduler/queue/job_types.h"
#include "scheduler/queue/run_output.h"

namespace gravsweep::queue {

inline constexpr int kSchemaVersion = 2;  ///< 2: stored paths relative to the files root

/// Wall-clock seconds since the Unix epoch, on this host.
double now_s();
/// Seconds since the Unix epoch on the clock the campaign's leases use: the database server's for
/// PostgreSQL, this host's for SQLite (scheduler/queue/dialect.h).
double clock_s(db::Database& db);

/// Creates the queue tables if missing (idempotent); checks the schema version and migrates a
/// version-1 campaign. Only `submit` (through open_campaign(create)) and tests call it: other verbs
/// open with open_campaign (scheduler/queue/campaign.h), which never creates a schema.
void ensure_schema(db::Database& db);

/// Where a campaign keeps its files, {beds,traces,noop,tmp,quarantine}/ under the files root:
/// `files_root` when given, else <db dir>/<db stem>.files/ beside an SQLite file (the file itself:
/// a symbolic link to it is followed, so that a verb given the link never makes a second
/// <link stem>.files/ that claims the campaign). A PostgreSQL
/// campaign needs it given (ConfigError otherwise): the folder every worker node mounts at the
/// same path.
struct CampaignPaths {
  std::filesystem::path root;  ///< paths in the database are relative to this (schema version 2)
  explicit CampaignPaths(const std::filesystem::path& db_path, const std::filesystem::path& files_root = {});
  [[nodiscard]] std::filesystem::path tmp() const { return root / "tmp"; }
  /// Path, relative to the files root, of the output of attempt `attempt` of job `job_id` of `kind`.
  [[nodiscard]] std::string output_rel(JobKind kind, const std::string& job_id, int attempt) const;
  /// The file of a stored path (version-1 forms `<stem>.files/...` are read as relative to root).
  [[nodiscard]] std::filesystem::path abs(const std::string& rel) const;
};

// ---- submit ---------------------------------------------------------------------------------
struct SubmitReport {
  std::string sweep;
  std::size_t planned = 0;                       ///< jobs in the expanded spec
  std::size_t added = 0;                         ///< new jobs written
  std::size_t present = 0;                       ///< already in the campaign (same content hash)
  std::map<JobKind, std::size_t> added_by_kind;  ///< new jobs of each kind
  bool sweep_new = false;
};

/// A sweep as the queue stores it (sweeps table, results columns). A read spec is one
/// (sweep::SweepSpec derives from it: load_spec writes these fields once, and submit stores them).
struct SweepRecord {
  std::string name;                 ///< unique within a campaign
  std::string job_kind = "impact";  ///< the sweep kind's name (sweep/sweep_kind.h: "impact", "noop", ...)
  /// The spec as written (no defaults filled), its base inlined and canonical, as canonical JSON
  /// text (canonical.h): the sweeps row stores it as it is, with its SHA-256.
  std::string spec_json;
  int max_attempts = 3;
  /// Each swept parameter's results column and every value it takes (the column's SQL type fits them all).
  std::vector<std::pair<std::string, std::vector<nlohmann::json>>> columns;
};

/// Writes the sweep and its jobs in one transaction: INSERT ... ON CONFLICT DO NOTHING, so a
/// second submit of the same spec adds nothing and an extended axis adds only the new points.
SubmitReport submit(db::Database& db, const SweepRecord& sweep, const std::vector<PlannedJob>& jobs);

// ---- workers --------------------------------------------------------------------------------
struct WorkerIdentity {
  std::string owner;  ///< unique per worker process: host:pid:start
  std::string host;
  int pid = 0;
  std::string code_version;
  int threads = 1;
};
WorkerIdentity make_identity(const std::string& code_version, int threads);

struct Claim {
  std::string job_id, sweep_id;
  JobKind kind;  ///< noop unless set
  nlohmann::json scenario, params;
  int attempt = 0;               ///< 1-based attempt number of this claim
  std::int64_t token = 0;        ///< fencing token
  std::int64_t attempt_row = 0;  ///< attempts.attempt_id
  std::string output_rel;        ///< where this attempt's output must end up
  /// The output this job reads of the job it depends on (a drop: its bed), its job id and its
  /// recorded checksum, verified before use; empty for a job without a dependency.
  std::string dep_output_rel;
  std::string dep_job_id;
  std::string dep_sha256;
  std::string dep_kind;  ///< the dependency's job kind, as messages name it
  double claimed_at = 0;
};

/// Files of attempts whose lease expired, found by claim()/resume(): the caller deletes them after
/// the transaction committed.
struct Reclaimed {
  std::vector<std::string> output_rels;   ///< planned outputs of lost attempts
  std::vector<std::string> job_prefixes;  ///< "<job>.a<k>" for temp files in tmp/
  int lost = 0;                           ///< expired leases found
  int dead = 0;                           ///< of which went dead (budget spent)
};

/// Claims one runnable job: first an expired lease (its attempt is closed as `lost`), then the
/// highest-priority queued job, then a failed job whose backoff has passed. nullopt when none.
std::optional<Claim> claim(db::Database& db, const WorkerIdentity& who, const CampaignPaths& paths, double lease_s,
                           Reclaimed* reclaimed = nullptr);

/// Renews the lease and records progress; false when the lease is no longer ours (stop the job).
bool heartbeat(db::Database& db, const Claim& c, double lease_s, double fraction, const std::string& phase,
               const std::string& detail);

/// A finished attempt: the runner's output with where its file was stored.
struct Completion : RunOutput {
  std::string output_rel;
  std::string sha256;
  std::int64_t bytes = 0;
};
/// Marks the job done (fenced), records output path and checksum, closes the attempt, writes the
/// results row and releases the dependents, all in one transaction. false = fenced out.
bool complete(db::Database& db, const Claim& c, const Completion& done);

/// Records a failed attempt: `failed` with backoff (base * 2^(attempt-1), capped, with jitter)
/// while attempts remain, else `dead`; permanent errors go `dead` at once. Returns the new state,
/// or "" when fenced out.
std::string fail(db::Database& db, const Claim& c, const std::string& error, int exit_code, bool permanent,
                 double backoff_base_s = 2.0, double backoff_cap_s = 300.0);

/// The dependency's output a job was about to use (a drop's bed) does not match its recorded
/// checksum: the job's attempt fails with `reason`, the job waits again, and the dependency (if
/// still done with that checksum) is queued to be made again, its other unstarted dependents
/// waiting for it. false = fenced out.
bool dependency_mismatch(db::Database& db, const Claim& c, const std::string& reason);

/// Releases in a row without progress a job may have before it is stopped (dead, with the
/// reason): a job interrupted at every attempt before it saved anything (a time limit shorter than
/// the job, and than its checkpoint interval) would otherwise loop forever, uncounted.
inline constexpr int kDefaultMaxReleases = 5;

/// Gives the job back (interrupted worker): the attempt is not counted against the retry budget
/// but the release is counted (jobs.releases). `saved_progress`: the attempt left state the next
/// one continues from (a drop's checkpoint beyond where it started); such a release resets
/// jobs.stalled_releases, any other adds one. The job is queued again, or dead with the reason
/// once `max_releases` releases in a row saved nothing. Returns the new state ("queued" or
/// "dead"), "" when fenced out.
std::string release(db::Database& db, const Claim& c, const std::string& why, int max_releases = kDefaultMaxReleases,
                    bool saved_progress = false);

/// Gives the job back after an environmental failure (the files root's disk full): queued again,
/// the attempt closed as released with `why`, counted neither against the retry budget nor as a
/// release (the job did nothing wrong). false = fenced out.
bool give_back(db::Database& db, const Claim& c, const std::string& why);

/// True while some job may still become runnable (queued, waiting, failed, running).
bool work_remains(db::Database& db);

/// Threads for the claimed job: `pool_threads` (all the threads the workers hold) for a job whose
/// kind takes idle threads (JobKindInfo::takes_idle_threads, a bed) when it runs alone, i.e. no
/// other job is running, queued or waiting to retry (the other workers would idle until it is done:
/// its dependents wait for it); `threads` otherwise.
int threads_for_claim(db::Database& db, const Claim& c, int threads, int pool_threads);

// ---- resume -----------------------------------------------------------------------------------
struct ResumeOptions {
  bool retry_dead = false;  ///< also requeue dead jobs with `extra_attempts` more tries
  int extra_attempts = 1;
  bool remove_orphans = true;  ///< quarantine campaign files no job or live attempt refers to
  bool dry_run = false;
};
struct ResumeReport {
  int expired_requeued = 0, expired_dead = 0, failed_requeued = 0, dead_requeued = 0;
  std::vector<std::string> orphans;   ///< paths (relative to the files root) moved to quarantine (found: dry run)
  std::vector<std::string> restored;  ///< quarantined, then found referenced, and put back
  std::size_t purged = 0;             ///< files of earlier quarantines removed
};
/// Requeues expired leases and failed jobs (and dead ones if asked), then moves orphaned files to
/// `<root>/quarantine/` after removing what earlier resumes quarantined (see campaign.h). Refuses
/// (ConfigError) when most files done jobs refer to are missing.
ResumeReport resume(db::Database& db, const CampaignPaths& paths, const ResumeOptions& o);

/// Deletes files of lost attempts (ignores missing files).
void remove_lost_files(const CampaignPaths& paths, const Reclaimed& r);

// ---- status ---------------------------------------------------------------------------------
struct StateCounts {
  std::string sweep, kind;
  std::int64_t waiting = 0, queued = 0, running = 0, failed = 0, done = 0, dead = 0;
  [[nodiscard]] std::int64_t total() const { return waiting + queued + running + failed + done + dead; }
};
struct RunningJob {
  std::string job_id, kind, owner, phase, detail;
  double progress = 0, started_at = 0, heartbeat_at = 0, lease_expires = 0;
  int attempt = 0;
  bool stale = false;
};
struct KindRuntime {
  std::string kind;
  std::int64_t finished = 0;
  double median_s = 0;
  std::int64_t remaining = 0;
};
/// A worker seen holding a lease: its jobs now and its latest heartbeat.
struct WorkerSeen {
  std::string owner;
  std::int64_t jobs = 0;
  double last_heartbeat_at = 0;
  bool stale = false;  ///< every lease it holds has expired
};
struct Status {
  std::vector<StateCounts> per_sweep;
  std::vector<RunningJob> running;
  std::vector<WorkerSeen> workers;  ///< every lease owner, running jobs not cut at max_running
  std::vector<KindRuntime> runtimes;
  std::int64_t stale_leases = 0;
  std::int64_t blocked = 0;              ///< dead because a dependency is dead (jobs.blocked_by)
  std::int64_t released_attempts = 0;    ///< attempts given back (interrupted), not counted in attempts
  std::int64_t released_jobs = 0;        ///< unfinished jobs with at least one released attempt
  std::int64_t stopped_by_releases = 0;  ///< dead: released max_releases times in a row without progress
  std::int64_t active_workers = 0;
  double eta_s = -1;  ///< < 0: unknown (no finished job of some remaining kind)
  std::vector<std::pair<std::string, std::string>> recent_errors;  ///< (job_id, error) of dead jobs
  /// (job_id, why) of the attempts that found their dependency's output changed (dependency_mismatch):
  /// the dependency was made again (a drop's bed rebuilt).
  std::vector<std::pair<std::string, std::string>> dependency_mismatches;
};
Status status(db::Database& db, std::size_t max_running = 20);
/// `status --format json` (and the /api/status of `serve`): the Status as one JSON object.
nlohmann::json status_json(const Status& s);

/// A failed job waiting for its retry, or a dead one, with the reason.
struct TroubledJob {
  std::string job_id, sweep, kind, state, error, blocked_by;
  int attempts = 0, max_attempts = 0;
  double finished_at = 0;  ///< 0: never finished (a failed job: the time of its last attempt's end)
};
struct TroubledPage {
  std::int64_t total = 0;  ///< failed and dead jobs in all
  std::vector<TroubledJob> jobs;
};
/// The failed and dead jobs, latest first, `limit` of them from `offset`.
TroubledPage troubled_jobs(db::Database& db, std::int64_t offset, std::int64_t limit);

/// One attempt of a job as the attempts table keeps it: a job's log (jobs run inside their
/// worker's process and write no log of their own).
struct AttemptRecord {
  int attempt = 0;
  std::string worker, host, code_version, outcome, error;
  int threads = 0;
  double started_at = 0, ended_at = 0, runtime_s = 0;  ///< ended_at, runtime_s 0: not ended
};
/// The job's attempts, latest first, at most `limit`.
std::vector<AttemptRecord> job_attempts(db::Database& db, const std::string& job_id, std::int64_t limit);
/// The output (files-root relative) of the job's latest done attempt; empty: none.
std::string done_output_path(db::Database& db, const std::string& job_id);

// ---- results ----------------------------------------------------------------------------------
/// A runner reported a metric its kind does not declare (JobKindInfo::outputs), or a value that
/// does not fit the declared type. A mistake of the program, not of the job: the attempt fails
/// for good (a retry would report the same key), and no column is made for it. A silently added
/// column is how a renamed key used to split a campaign's values over two columns unnoticed.
class OutputError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};
/// Checks a runner's outputs (RunOutput::each_output: its values, {key: value} flat, and its
/// record's) against the outputs `kind` declares: every key declared and reported once, every
/// value null or of the declared type (REAL: a number; INTEGER: an integer or a flag; TEXT: a
/// string). Throws OutputError naming the kind and the key. A declared key a runner leaves out is
/// NULL in its row.
void check_outputs(JobKind kind, const RunOutput& out);

/// Column names of the results table, in display order (fixed, parameters, metrics).
std::vector<std::string> result_columns(db::Database& db);
/// The names of the results columns that hold numbers (fixed INTEGER/REAL ones, and the swept
/// parameters and metrics stored as INTEGER or REAL).
std::set<std::string> numeric_result_columns(db::Database& db);
/// The columns a results table shows by default: job_id, every swept parameter, and those of
/// `headline_metrics` the campaign has (the job kinds' own choice; the queue knows no metric).
std::vector<std::string> summary_result_columns(db::Database& db, const std::vector<std::string>& headline_metrics);

}  // namespace gravsweep::queue
