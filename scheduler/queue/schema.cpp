// The queue's tables (see README.md, "Tables"), the files root of a campaign and the clock.
#include <fmt/format.h>

#include <chrono>

#include "engine/core/error.h"

#include "scheduler/queue/campaign.h"
#include "scheduler/queue/dialect.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue {

namespace {

/// Every queue table and index (README.md, "Tables"), in the words of the backend's SchemaTypes;
/// the results table's fixed columns from their table (detail::fixed_result_columns).
constexpr const char* kSchemaTemplate = R"SQL(
CREATE TABLE IF NOT EXISTS queue_meta(key TEXT PRIMARY KEY, value TEXT NOT NULL) {strict};
CREATE TABLE IF NOT EXISTS sweeps(
  sweep_id TEXT PRIMARY KEY,
  job_kind TEXT NOT NULL,
  spec_json TEXT NOT NULL,
  spec_sha256 TEXT NOT NULL,
  submitted_at {real} NOT NULL,
  updated_at {real} NOT NULL,
  submits {integer} NOT NULL DEFAULT 1
) {strict};
CREATE TABLE IF NOT EXISTS jobs(
  seq {key},
  job_id TEXT NOT NULL UNIQUE,
  kind TEXT NOT NULL CHECK(kind IN ({kinds})),  -- the kinds registered when the database was made
  sweep_id TEXT NOT NULL REFERENCES sweeps(sweep_id),
  state TEXT NOT NULL CHECK(state IN ('waiting','queued','running','failed','done','dead')),
  priority {integer} NOT NULL DEFAULT 0,
  deps_pending {integer} NOT NULL DEFAULT 0,
  not_before {real} NOT NULL DEFAULT 0,
  attempts {integer} NOT NULL DEFAULT 0,
  max_attempts {integer} NOT NULL,
  releases {integer} NOT NULL DEFAULT 0,  -- attempts given back (interrupted), not counted in attempts
  stalled_releases {integer} NOT NULL DEFAULT 0,  -- the last releases in a row that saved no progress
  lease_owner TEXT,
  lease_token {integer} NOT NULL DEFAULT 0,
  lease_expires {real},
  heartbeat_at {real},
  progress {real},
  phase TEXT,
  detail TEXT,
  params_json TEXT NOT NULL,
  scenario_json TEXT NOT NULL,
  output_path TEXT,
  output_sha256 TEXT,
  output_bytes {integer},
  last_error TEXT,
  blocked_by TEXT,  -- a dead job that never ran because this dependency is dead (NULL otherwise)
  created_at {real} NOT NULL,
  started_at {real},
  finished_at {real}
) {strict};
CREATE INDEX IF NOT EXISTS jobs_claim ON jobs(state, priority DESC, seq);
CREATE INDEX IF NOT EXISTS jobs_lease ON jobs(state, lease_expires);
CREATE INDEX IF NOT EXISTS jobs_backoff ON jobs(state, not_before);
CREATE INDEX IF NOT EXISTS jobs_sweep_state ON jobs(sweep_id, kind, state);
CREATE TABLE IF NOT EXISTS job_deps(
  job_id TEXT NOT NULL REFERENCES jobs(job_id),
  dep_id TEXT NOT NULL REFERENCES jobs(job_id),
  PRIMARY KEY(job_id, dep_id)
) {strict_without_rowid};
CREATE INDEX IF NOT EXISTS job_deps_dep ON job_deps(dep_id);
CREATE TABLE IF NOT EXISTS sweep_jobs(
  sweep_id TEXT NOT NULL REFERENCES sweeps(sweep_id),
  job_id TEXT NOT NULL REFERENCES jobs(job_id),
  shared {integer} NOT NULL DEFAULT 0,  -- 1: the job was created by another sweep (jobs.sweep_id)
  PRIMARY KEY(sweep_id, job_id)
) {strict_without_rowid};
CREATE INDEX IF NOT EXISTS sweep_jobs_job ON sweep_jobs(job_id);
CREATE INDEX IF NOT EXISTS sweep_jobs_shared ON sweep_jobs(shared) WHERE shared=1;
CREATE TABLE IF NOT EXISTS attempts(
  attempt_id {key},
  job_id TEXT NOT NULL REFERENCES jobs(job_id),
  attempt {integer} NOT NULL,
  lease_token {integer} NOT NULL,
  kind TEXT NOT NULL,
  worker TEXT NOT NULL,
  host TEXT NOT NULL,
  pid {integer} NOT NULL,
  threads {integer} NOT NULL,
  code_version TEXT NOT NULL,
  started_at {real} NOT NULL,
  ended_at {real},
  runtime_s {real},
  outcome TEXT NOT NULL CHECK(outcome IN ('running','done','failed','dead','lost','released')),
  exit_code {integer},
  error TEXT,
  output_path TEXT,
  report_json TEXT
) {strict};
CREATE INDEX IF NOT EXISTS attempts_job ON attempts(job_id, outcome);
CREATE INDEX IF NOT EXISTS attempts_runtime ON attempts(kind, outcome, runtime_s);
{results}
CREATE TABLE IF NOT EXISTS results_columns(
  name TEXT PRIMARY KEY,
  role TEXT NOT NULL CHECK(role IN ('param','metric')),
  sql_type TEXT NOT NULL,
  position {integer} NOT NULL
) {strict};
)SQL";

/// The registered job kinds as an SQL list: 'noop', 'bed', ...
std::string kind_list_sql() {
  std::string list;
  for (JobKind k : registered_kinds()) list += fmt::format("{}'{}'", list.empty() ? "" : ",", kind_name(k));
  return list;
}

std::string schema_sql(const Dialect& d) {
  const SchemaTypes t = d.schema_types();
  return fmt::format(kSchemaTemplate, fmt::arg("kinds", kind_list_sql()), fmt::arg("key", t.key),
                     fmt::arg("integer", t.integer), fmt::arg("real", t.real), fmt::arg("strict", t.strict),
                     fmt::arg("strict_without_rowid", t.strict_without_rowid),
                     fmt::arg("results", detail::results_table_sql(d)));
}

}  // namespace

double now_s() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

void ensure_schema(Database& db) {
  {
    Transaction tx(db);
    db.exec(schema_sql(dialect_of(db)));
    Statement get(db, "SELECT value FROM queue_meta WHERE key='schema_version'");
    if (!get.step()) {
      Statement put(db, "INSERT INTO queue_meta(key, value) VALUES('schema_version', ?)");
      put.bind(1, std::to_string(kSchemaVersion));
      put.run();
    }
    tx.commit();
  }
  check_campaign(db);
  migrate_paths(db);
  add_missing_columns(db);
}

void add_missing_columns(Database& db) {
  Transaction tx(db);
  const Dialect& d = dialect_of(db);
  if (!d.has_column(db, "jobs", "blocked_by")) {
    db.exec("ALTER TABLE jobs ADD COLUMN blocked_by TEXT");
    // Campaigns written before the column marked a blocked job only in its message (once, here).
    db.exec(
        "UPDATE jobs SET blocked_by=substr(last_error, 12, length(last_error)-19) "
        "WHERE state='dead' AND last_error LIKE 'dependency % is dead'");
  }
  if (!d.has_column(db, "jobs", "releases"))
    db.exec(fmt::format("ALTER TABLE jobs ADD COLUMN releases {} NOT NULL DEFAULT 0", d.schema_types().integer));
  if (!d.has_column(db, "jobs", "stalled_releases")) {
    db.exec(
        fmt::format("ALTER TABLE jobs ADD COLUMN stalled_releases {} NOT NULL DEFAULT 0", d.schema_types().integer));
    db.exec("UPDATE jobs SET stalled_releases=releases");  // earlier campaigns knew no progress
  }
  // Jobs an older build submitted got their metric columns at completion: their kinds' declared
  // columns are added here, before a worker of this build completes one of them.
  detail::declare_output_columns_of_jobs(db);
  tx.commit();
}

const Dialect& dialect_of(const Database& db) {
  return db.backend() == db::Backend::postgres ? postgres_dialect() : sqlite_dialect();
}

double clock_s(Database& db) { return dialect_of(db).now_s(db); }

CampaignPaths::CampaignPaths(const fs::path& db_path, const fs::path& files_root) {
  if (!files_root.empty()) {
    root = fs::absolute(files_root);
    return;
  }
  if (db::is_postgres_url(db_path.string()))
    throw ConfigError(
        fmt::format("--files: a PostgreSQL campaign ({}) needs its files root given, the folder every "
                    "worker node mounts at the same path (e.g. --files /shared/campaign)",
                    db_path.string()));
  // The database file itself, through any symbolic link to it (weakly: it may not exist yet).
  std::error_code ec;
  fs::path abs = fs::weakly_canonical(fs::absolute(db_path), ec);
  if (ec) abs = fs::absolute(db_path);
  root = abs.parent_path() / (abs.stem().string() + ".files");
}

std::string CampaignPaths::output_rel(JobKind kind, const std::string& job_id, int attempt) const {
  const JobKindInfo& k = kind_info(kind);
  return (fs::path(k.folder) / fmt::format("{}.a{}{}", job_id, attempt, k.extension)).string();
}

fs::path CampaignPaths::abs(const std::string& rel) const {
  const fs::path p(files_rel(rel));
  return p.is_absolute() ? p : root / p;
}

}  // namespace gravsweep::queue
