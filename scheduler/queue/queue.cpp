#include "scheduler/queue/queue.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "scheduler/queue/campaign.h"
#include "scheduler/sweep/canonical.h"

namespace gravsweep::queue {

using db::Database;
using db::Statement;
using db::Transaction;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

constexpr const char* kSchemaSql = R"SQL(
CREATE TABLE IF NOT EXISTS queue_meta(key TEXT PRIMARY KEY, value TEXT NOT NULL) STRICT;
CREATE TABLE IF NOT EXISTS sweeps(
  sweep_id TEXT PRIMARY KEY,
  job_kind TEXT NOT NULL,
  spec_json TEXT NOT NULL,
  spec_sha256 TEXT NOT NULL,
  submitted_at REAL NOT NULL,
  updated_at REAL NOT NULL,
  submits INTEGER NOT NULL DEFAULT 1
) STRICT;
CREATE TABLE IF NOT EXISTS jobs(
  seq INTEGER PRIMARY KEY,
  job_id TEXT NOT NULL UNIQUE,
  kind TEXT NOT NULL CHECK(kind IN ('bed','drop','noop')),
  sweep_id TEXT NOT NULL REFERENCES sweeps(sweep_id),
  state TEXT NOT NULL CHECK(state IN ('waiting','queued','running','failed','done','dead')),
  priority INTEGER NOT NULL DEFAULT 0,
  deps_pending INTEGER NOT NULL DEFAULT 0,
  not_before REAL NOT NULL DEFAULT 0,
  attempts INTEGER NOT NULL DEFAULT 0,
  max_attempts INTEGER NOT NULL,
  lease_owner TEXT,
  lease_token INTEGER NOT NULL DEFAULT 0,
  lease_expires REAL,
  heartbeat_at REAL,
  progress REAL,
  phase TEXT,
  detail TEXT,
  params_json TEXT NOT NULL,
  scenario_json TEXT NOT NULL,
  output_path TEXT,
  output_sha256 TEXT,
  output_bytes INTEGER,
  last_error TEXT,
  created_at REAL NOT NULL,
  started_at REAL,
  finished_at REAL
) STRICT;
CREATE INDEX IF NOT EXISTS jobs_claim ON jobs(state, priority DESC, seq);
CREATE INDEX IF NOT EXISTS jobs_lease ON jobs(state, lease_expires);
CREATE INDEX IF NOT EXISTS jobs_backoff ON jobs(state, not_before);
CREATE INDEX IF NOT EXISTS jobs_sweep_state ON jobs(sweep_id, kind, state);
CREATE TABLE IF NOT EXISTS job_deps(
  job_id TEXT NOT NULL REFERENCES jobs(job_id),
  dep_id TEXT NOT NULL REFERENCES jobs(job_id),
  PRIMARY KEY(job_id, dep_id)
) STRICT, WITHOUT ROWID;
CREATE INDEX IF NOT EXISTS job_deps_dep ON job_deps(dep_id);
CREATE TABLE IF NOT EXISTS sweep_jobs(
  sweep_id TEXT NOT NULL REFERENCES sweeps(sweep_id),
  job_id TEXT NOT NULL REFERENCES jobs(job_id),
  shared INTEGER NOT NULL DEFAULT 0,  -- 1: the job was created by another sweep (jobs.sweep_id)
  PRIMARY KEY(sweep_id, job_id)
) STRICT, WITHOUT ROWID;
CREATE INDEX IF NOT EXISTS sweep_jobs_job ON sweep_jobs(job_id);
CREATE INDEX IF NOT EXISTS sweep_jobs_shared ON sweep_jobs(shared) WHERE shared=1;
CREATE TABLE IF NOT EXISTS attempts(
  attempt_id INTEGER PRIMARY KEY,
  job_id TEXT NOT NULL REFERENCES jobs(job_id),
  attempt INTEGER NOT NULL,
  lease_token INTEGER NOT NULL,
  kind TEXT NOT NULL,
  worker TEXT NOT NULL,
  host TEXT NOT NULL,
  pid INTEGER NOT NULL,
  threads INTEGER NOT NULL,
  code_version TEXT NOT NULL,
  started_at REAL NOT NULL,
  ended_at REAL,
  runtime_s REAL,
  outcome TEXT NOT NULL CHECK(outcome IN ('running','done','failed','dead','lost','released')),
  exit_code INTEGER,
  error TEXT,
  output_path TEXT,
  report_json TEXT
) STRICT;
CREATE INDEX IF NOT EXISTS attempts_job ON attempts(job_id, outcome);
CREATE INDEX IF NOT EXISTS attempts_runtime ON attempts(kind, outcome, runtime_s);
CREATE TABLE IF NOT EXISTS results(
  job_id TEXT PRIMARY KEY REFERENCES jobs(job_id),
  sweep TEXT NOT NULL,
  kind TEXT NOT NULL,
  bed_job_id TEXT,
  attempt INTEGER NOT NULL,
  trace_path TEXT,
  trace_sha256 TEXT,
  trace_bytes INTEGER,
  runtime_s REAL,
  finished_at REAL,
  code_version TEXT
) STRICT;
CREATE TABLE IF NOT EXISTS results_columns(
  name TEXT PRIMARY KEY,
  role TEXT NOT NULL CHECK(role IN ('param','metric')),
  sql_type TEXT NOT NULL,
  position INTEGER NOT NULL
) STRICT;
)SQL";

const std::vector<std::string> kFixedResultColumns = {"job_id",       "sweep",        "kind",        "bed_job_id",
                                                      "attempt",      "trace_path",   "trace_sha256", "trace_bytes",
                                                      "runtime_s",    "finished_at",  "code_version"};

std::string quote_ident(const std::string& name) { return "\"" + name + "\""; }

std::string sql_type_of(const json& v) {
  if (v.is_boolean() || v.is_number_integer() || v.is_number_unsigned()) return "INTEGER";
  if (v.is_number()) return "REAL";
  if (v.is_string()) return "TEXT";
  return "ANY";
}

void bind_json_value(Statement& st, int idx, const json& v) {
  if (v.is_null()) st.bind_null(idx);
  else if (v.is_boolean()) st.bind(idx, static_cast<std::int64_t>(v.get<bool>() ? 1 : 0));
  else if (v.is_number_integer() || v.is_number_unsigned()) st.bind(idx, v.get<std::int64_t>());
  else if (v.is_number()) st.bind(idx, v.get<double>());
  else if (v.is_string()) st.bind(idx, v.get<std::string>());
  else st.bind(idx, sweep::canonical_json(v));
}

/// Existing extra columns of results: name -> role.
std::map<std::string, std::string> result_extra_columns(Database& db) {
  std::map<std::string, std::string> out;
  Statement st(db, "SELECT name, role FROM results_columns");
  while (st.step()) out[st.get_text(0)] = st.get_text(1);
  return out;
}

/// Adds a results column (inside the caller's transaction).
void add_result_column(Database& db, const std::string& name, const std::string& role, const std::string& type) {
  db.exec(fmt::format("ALTER TABLE results ADD COLUMN {} {}", quote_ident(name), type));
  Statement st(db, "INSERT INTO results_columns(name, role, sql_type, position) "
                   "VALUES(?, ?, ?, (SELECT coalesce(max(position), 0) + 1 FROM results_columns))");
  st.bind(1, name).bind(2, role).bind(3, type);
  st.run();
}

std::string sanitize_metric(const std::string& key) {
  std::string out;
  for (char c : key) {
    const auto u = static_cast<unsigned char>(c);
    out.push_back(std::isalnum(u) ? static_cast<char>(std::tolower(u)) : '_');
  }
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "m_" + out;
  return out;
}

void flatten(const json& j, const std::string& prefix, std::vector<std::pair<std::string, json>>& out) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it)
      flatten(it.value(), prefix.empty() ? it.key() : prefix + "_" + it.key(), out);
  } else if (j.is_array()) {
    out.emplace_back(prefix, json(sweep::canonical_json(j)));
  } else {
    out.emplace_back(prefix, j);
  }
}

/// Marks dependents of a dead job dead too (they can never run), recursively.
void cascade_dead(Database& db, const std::string& job_id, double now) {
  std::vector<std::string> stack{job_id};
  Statement st(db, "UPDATE jobs SET state='dead', last_error=?, finished_at=? WHERE state='waiting' AND job_id IN "
                   "(SELECT job_id FROM job_deps WHERE dep_id=?) RETURNING job_id");
  while (!stack.empty()) {
    const std::string id = stack.back();
    stack.pop_back();
    st.reset();
    st.bind(1, fmt::format("dependency {} is dead", id)).bind(2, now).bind(3, id);
    while (st.step()) stack.push_back(st.get_text(0));
  }
}

}  // namespace

double now_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

void ensure_schema(Database& db) {
  {
    Transaction tx(db);
    db.exec(kSchemaSql);
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
}

CampaignPaths::CampaignPaths(const fs::path& db_path) {
  const fs::path abs = fs::absolute(db_path);
  db_dir = abs.parent_path();
  root = db_dir / (abs.stem().string() + ".files");
}

std::string CampaignPaths::output_rel(const std::string& kind, const std::string& job_id, int attempt) const {
  const std::string dir = kind == "bed" ? "beds" : kind == "drop" ? "traces" : "noop";
  const std::string ext = kind == "noop" ? ".json" : ".h5";
  return (fs::path(dir) / fmt::format("{}.a{}{}", job_id, attempt, ext)).string();
}

fs::path CampaignPaths::abs(const std::string& rel) const {
  const fs::path p(files_rel(rel));
  return p.is_absolute() ? p : root / p;
}

// ---- submit -----------------------------------------------------------------------------------

SubmitReport submit(Database& db, const sweep::SweepSpec& spec, const std::vector<sweep::PlannedJob>& jobs) {
  SubmitReport rep;
  rep.sweep = spec.name;
  rep.planned = jobs.size();
  const double now = now_s();
  const std::string spec_text = sweep::canonical_json(spec.source);
  Transaction tx(db);
  {
    Statement exists(db, "SELECT 1 FROM sweeps WHERE sweep_id=?");
    exists.bind(1, spec.name);
    rep.sweep_new = !exists.step();
  }
  {
    Statement st(db,
                 "INSERT INTO sweeps(sweep_id, job_kind, spec_json, spec_sha256, submitted_at, updated_at) "
                 "VALUES(?1, ?2, ?3, ?4, ?5, ?5) ON CONFLICT(sweep_id) DO UPDATE SET spec_json=excluded.spec_json, "
                 "spec_sha256=excluded.spec_sha256, updated_at=excluded.updated_at, submits=submits+1");
    st.bind(1, spec.name).bind(2, spec.job_kind).bind(3, spec_text).bind(4, sweep::sha256_hex(spec_text)).bind(5, now);
    st.run();
  }
  // One results column per swept parameter.
  auto cols = result_extra_columns(db);
  for (const auto& g : spec.groups) {
    for (const auto& a : g.axes) {
      if (cols.count(a.name)) continue;
      add_result_column(db, a.name, "param", sql_type_of(a.values.front()));
      cols[a.name] = "param";
    }
  }
  Statement ins(db,
                "INSERT INTO jobs(job_id, kind, sweep_id, state, priority, deps_pending, max_attempts, params_json, "
                "scenario_json, created_at) VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10) "
                "ON CONFLICT(job_id) DO NOTHING");
  Statement dep(db, "INSERT INTO job_deps(job_id, dep_id) VALUES(?, ?) ON CONFLICT DO NOTHING");
  Statement pending(db,
                    "UPDATE jobs SET deps_pending=(SELECT count(*) FROM job_deps d JOIN jobs j ON j.job_id=d.dep_id "
                    "WHERE d.job_id=?1 AND j.state!='done'), state=CASE WHEN (SELECT count(*) FROM job_deps d JOIN "
                    "jobs j ON j.job_id=d.dep_id WHERE d.job_id=?1 AND j.state='dead') > 0 THEN 'dead' WHEN "
                    "(SELECT count(*) FROM job_deps d JOIN jobs j ON j.job_id=d.dep_id WHERE d.job_id=?1 AND "
                    "j.state!='done') > 0 THEN 'waiting' ELSE 'queued' END WHERE job_id=?1");
  Statement member(db,
                   "INSERT INTO sweep_jobs(sweep_id, job_id, shared) VALUES(?1, ?2, (SELECT sweep_id != ?1 FROM jobs "
                   "WHERE job_id=?2)) ON CONFLICT DO NOTHING");
  for (const auto& j : jobs) {
    ins.reset();
    ins.bind(1, j.job_id).bind(2, j.kind).bind(3, spec.name).bind(4, j.deps.empty() ? "queued" : "waiting");
    ins.bind(5, j.priority).bind(6, static_cast<std::int64_t>(j.deps.size())).bind(7, spec.max_attempts);
    ins.bind(8, sweep::canonical_json(j.params)).bind(9, sweep::canonical_json(j.scenario)).bind(10, now);
    ins.run();
    const bool added = db.changes() == 1;
    if (added) {
      ++rep.added;
      if (j.kind == "bed") ++rep.beds_added;
      else ++rep.drops_added;
      if (!j.deps.empty()) {
        for (const auto& d : j.deps) {
          dep.reset();
          dep.bind(1, j.job_id).bind(2, d);
          dep.run();
        }
        pending.reset();
        pending.bind(1, j.job_id);
        pending.run();
      }
    } else {
      ++rep.present;
    }
    member.reset();
    member.bind(1, spec.name).bind(2, j.job_id);
    member.run();
  }
  tx.commit();
  return rep;
}

// ---- workers ----------------------------------------------------------------------------------

WorkerIdentity make_identity(const std::string& code_version, int threads) {
  WorkerIdentity w;
  char host[256] = {0};
  gethostname(host, sizeof host - 1);
  w.host = host;
  w.pid = static_cast<int>(getpid());
  w.code_version = code_version;
  w.threads = threads;
  w.owner = fmt::format("{}:{}:{:.0f}", w.host, w.pid, now_s() * 1000);
  return w;
}

namespace {

/// Closes the attempts of expired leases and requeues their jobs (or marks them dead when the
/// budget is spent). Inside the caller's transaction.
void reap_expired(Database& db, double now, Reclaimed& out, int limit) {
  struct Expired {
    std::string job_id, owner;
    int attempts, max_attempts;
    double heartbeat_at;
  };
  std::vector<Expired> found;
  {
    Statement st(db,
                 "SELECT job_id, coalesce(lease_owner, ''), attempts, max_attempts, coalesce(heartbeat_at, 0) "
                 "FROM jobs WHERE state='running' AND lease_expires < ? ORDER BY lease_expires LIMIT ?");
    st.bind(1, now).bind(2, limit);
    while (st.step())
      found.push_back({st.get_text(0), st.get_text(1), static_cast<int>(st.get_int(2)), static_cast<int>(st.get_int(3)),
                       st.get_double(4)});
  }
  if (found.empty()) return;
  Statement close(db,
                  "UPDATE attempts SET outcome='lost', ended_at=?1, runtime_s=?1-started_at, error=?2 "
                  "WHERE job_id=?3 AND outcome='running' RETURNING coalesce(output_path, ''), attempt");
  Statement requeue(db,
                    "UPDATE jobs SET state=?1, last_error=?2, lease_owner=NULL, lease_expires=NULL, phase=NULL, "
                    "detail=NULL, progress=NULL, finished_at=CASE WHEN ?1='dead' THEN ?3 ELSE NULL END "
                    "WHERE job_id=?4 AND state='running'");
  for (const auto& e : found) {
    const std::string why = fmt::format("lease expired: no heartbeat from {} for {:.1f} s (worker killed or stalled)",
                                        e.owner, now - e.heartbeat_at);
    close.reset();
    close.bind(1, now).bind(2, why).bind(3, e.job_id);
    while (close.step()) {
      if (!close.get_text(0).empty()) out.output_rels.push_back(close.get_text(0));
      out.job_prefixes.push_back(fmt::format("{}.a{}", e.job_id, close.get_int(1)));
    }
    const bool dead = e.attempts >= e.max_attempts;
    requeue.reset();
    requeue.bind(1, dead ? "dead" : "queued").bind(2, why).bind(3, now).bind(4, e.job_id);
    requeue.run();
    ++out.lost;
    if (dead) {
      ++out.dead;
      cascade_dead(db, e.job_id, now);
    }
  }
}

}  // namespace

std::optional<Claim> claim(Database& db, const WorkerIdentity& who, const CampaignPaths& paths, double lease_s,
                           Reclaimed* reclaimed) {
  const double now = now_s();
  Reclaimed local;
  Transaction tx(db);
  reap_expired(db, now, reclaimed ? *reclaimed : local, 64);
  static constexpr const char* kSet =
      "UPDATE jobs SET state='running', lease_owner=:owner, lease_token=lease_token+1, lease_expires=:now+:lease, "
      "attempts=attempts+1, started_at=:now, heartbeat_at=:now, progress=0, phase='claimed', detail=NULL, "
      "not_before=0 WHERE job_id=(SELECT job_id FROM jobs WHERE ";
  static constexpr const char* kReturning =
      " LIMIT 1) RETURNING job_id, kind, sweep_id, scenario_json, params_json, attempts, lease_token";
  const std::string q_queued = std::string(kSet) + "state='queued' ORDER BY priority DESC, seq" + kReturning;
  const std::string q_failed = std::string(kSet) + "state='failed' AND not_before<=:now ORDER BY not_before" + kReturning;
  std::optional<Claim> c;
  for (const std::string* q : {&q_queued, &q_failed}) {
    Statement st(db, *q);
    st.bind(":owner", who.owner).bind(":now", now).bind(":lease", lease_s);
    if (st.step()) {
      c.emplace();
      c->job_id = st.get_text(0);
      c->kind = st.get_text(1);
      c->sweep_id = st.get_text(2);
      c->scenario = json::parse(st.get_text(3));
      c->params = json::parse(st.get_text(4));
      c->attempt = static_cast<int>(st.get_int(5));
      c->token = st.get_int(6);
      c->claimed_at = now;
      st.run();
      break;
    }
  }
  if (!c) {
    tx.commit();  // keeps the reaped leases
    return std::nullopt;
  }
  {
    Statement st(db,
                 "SELECT coalesce(j.output_path, ''), j.job_id, coalesce(j.output_sha256, '') FROM job_deps d "
                 "JOIN jobs j ON j.job_id=d.dep_id WHERE d.job_id=? AND j.kind='bed' AND j.state='done'");
    st.bind(1, c->job_id);
    if (st.step()) {
      c->dep_output_rel = st.get_text(0);
      c->dep_job_id = st.get_text(1);
      c->dep_sha256 = st.get_text(2);
    }
  }
  c->output_rel = paths.output_rel(c->kind, c->job_id, c->attempt);
  {
    Statement st(db,
                 "INSERT INTO attempts(job_id, attempt, lease_token, kind, worker, host, pid, threads, code_version, "
                 "started_at, outcome, output_path) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, 'running', ?) "
                 "RETURNING attempt_id");
    st.bind(1, c->job_id).bind(2, c->attempt).bind(3, c->token).bind(4, c->kind).bind(5, who.owner).bind(6, who.host);
    st.bind(7, who.pid).bind(8, who.threads).bind(9, who.code_version).bind(10, now).bind(11, c->output_rel);
    st.step();
    c->attempt_row = st.get_int(0);
    st.run();
  }
  tx.commit();
  return c;
}

bool heartbeat(Database& db, const Claim& c, double lease_s, double fraction, const std::string& phase,
               const std::string& detail) {
  const double now = now_s();
  Statement st(db,
               "UPDATE jobs SET lease_expires=?1+?2, heartbeat_at=?1, progress=?3, phase=?4, detail=?5 "
               "WHERE job_id=?6 AND lease_token=?7 AND state='running'");
  st.bind(1, now).bind(2, lease_s).bind(3, std::clamp(fraction, 0.0, 1.0)).bind(4, phase).bind(5, detail);
  st.bind(6, c.job_id).bind(7, c.token);
  st.run();  // a single statement is its own (immediate-on-write) transaction
  return db.changes() == 1;
}

bool complete(Database& db, const Claim& c, const Completion& done) {
  const double now = now_s();
  Transaction tx(db);
  {
    Statement st(db,
                 "UPDATE jobs SET state='done', output_path=?1, output_sha256=?2, output_bytes=?3, finished_at=?4, "
                 "progress=1, phase='done', detail=NULL, lease_owner=NULL, lease_expires=NULL, last_error=NULL "
                 "WHERE job_id=?5 AND lease_token=?6 AND state='running'");
    st.bind(1, done.output_rel).bind(2, done.sha256).bind(3, done.bytes).bind(4, now).bind(5, c.job_id).bind(6, c.token);
    st.run();
    if (db.changes() != 1) return false;  // fenced out: another worker holds the job now
  }
  std::string code_version;
  {
    Statement st(db,
                 "UPDATE attempts SET outcome='done', ended_at=?1, runtime_s=?1-started_at, exit_code=0, "
                 "report_json=?2, output_path=?3 WHERE attempt_id=?4 RETURNING code_version");
    st.bind(1, now).bind(2, sweep::canonical_json(done.report.is_null() ? json::object() : done.report));
    st.bind(3, done.output_rel).bind(4, c.attempt_row);
    if (st.step()) code_version = st.get_text(0);
    st.run();
  }
  {  // release dependents
    Statement st(db,
                 "UPDATE jobs SET deps_pending=deps_pending-1, state=CASE WHEN deps_pending<=1 AND state='waiting' "
                 "THEN 'queued' ELSE state END WHERE job_id IN (SELECT job_id FROM job_deps WHERE dep_id=?) "
                 "AND deps_pending>0");
    st.bind(1, c.job_id);
    st.run();
  }
  if (c.kind != "bed") {
    auto cols = result_extra_columns(db);
    std::vector<std::pair<std::string, json>> metrics;
    flatten(done.metrics.is_null() ? json::object() : done.metrics, "", metrics);
    std::vector<std::pair<std::string, json>> values;
    std::set<std::string> used(kFixedResultColumns.begin(), kFixedResultColumns.end());
    for (auto it = c.params.begin(); it != c.params.end(); ++it) {
      if (cols.count(it.key()) && used.insert(it.key()).second) values.emplace_back(it.key(), it.value());
    }
    for (auto& [key, v] : metrics) {
      std::string name = sanitize_metric(key);
      auto col = cols.find(name);
      if ((col != cols.end() && col->second != "metric") ||
          std::find(kFixedResultColumns.begin(), kFixedResultColumns.end(), name) != kFixedResultColumns.end())
        name = "metric_" + name;
      if (!cols.count(name) && v.is_null()) continue;  // the column appears with the first real value
      if (!used.insert(name).second) continue;
      if (!cols.count(name)) {
        add_result_column(db, name, "metric", sql_type_of(v));
        cols[name] = "metric";
      }
      values.emplace_back(name, v);
    }
    std::string bed_id;
    {
      Statement st(db, "SELECT dep_id FROM job_deps WHERE job_id=?");
      st.bind(1, c.job_id);
      if (st.step()) bed_id = st.get_text(0);
    }
    std::string names = "job_id, sweep, kind, bed_job_id, attempt, trace_path, trace_sha256, trace_bytes, runtime_s, "
                        "finished_at, code_version";
    std::string marks = "?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?";
    for (const auto& [name, v] : values) {
      names += ", " + quote_ident(name);
      marks += ", ?";
    }
    Statement st(db, fmt::format("INSERT INTO results({}) VALUES({})", names, marks));
    st.bind(1, c.job_id).bind(2, c.sweep_id).bind(3, c.kind);
    if (bed_id.empty()) st.bind_null(4);
    else st.bind(4, bed_id);
    st.bind(5, c.attempt).bind(6, done.output_rel).bind(7, done.sha256).bind(8, done.bytes);
    st.bind(9, now - c.claimed_at).bind(10, now).bind(11, code_version);
    int i = 12;
    for (const auto& [name, v] : values) bind_json_value(st, i++, v);
    st.run();
  }
  tx.commit();
  return true;
}

std::string fail(Database& db, const Claim& c, const std::string& error, int exit_code, bool permanent,
                 double backoff_base_s, double backoff_cap_s) {
  const double now = now_s();
  thread_local std::mt19937_64 rng(std::random_device{}());
  const double delay = std::min(backoff_cap_s, backoff_base_s * std::pow(2.0, std::max(0, c.attempt - 1)));
  const double jitter = std::uniform_real_distribution<double>(0, 0.25 * delay)(rng);
  Transaction tx(db);
  std::string state;
  {
    Statement st(db,
                 "UPDATE jobs SET state=CASE WHEN ?1 OR attempts>=max_attempts THEN 'dead' ELSE 'failed' END, "
                 "not_before=?2, last_error=?3, lease_owner=NULL, lease_expires=NULL, phase=NULL, detail=NULL, "
                 "finished_at=?4 WHERE job_id=?5 AND lease_token=?6 AND state='running' RETURNING state");
    st.bind(1, permanent ? 1 : 0).bind(2, now + delay + jitter).bind(3, error).bind(4, now).bind(5, c.job_id);
    st.bind(6, c.token);
    if (!st.step()) return "";
    state = st.get_text(0);
    st.run();
  }
  {
    Statement st(db,
                 "UPDATE attempts SET outcome=?1, ended_at=?2, runtime_s=?2-started_at, exit_code=?3, error=?4 "
                 "WHERE attempt_id=?5");
    st.bind(1, state).bind(2, now).bind(3, exit_code).bind(4, error).bind(5, c.attempt_row);
    st.run();
  }
  if (state == "dead") cascade_dead(db, c.job_id, now);
  tx.commit();
  return state;
}

bool bed_mismatch(Database& db, const Claim& c, const std::string& reason) {
  const double now = now_s();
  Transaction tx(db);
  {
    Statement st(db,
                 "UPDATE jobs SET state='waiting', deps_pending=1, last_error=?1, lease_owner=NULL, "
                 "lease_expires=NULL, phase=NULL, detail=NULL, progress=NULL, attempts=max(attempts-1, 0) "
                 "WHERE job_id=?2 AND lease_token=?3 AND state='running'");
    st.bind(1, reason).bind(2, c.job_id).bind(3, c.token);
    st.run();
    if (db.changes() != 1) return false;
  }
  {
    Statement st(db, "UPDATE attempts SET outcome='failed', ended_at=?1, runtime_s=?1-started_at, exit_code=1, "
                     "error=?2 WHERE attempt_id=?3");
    st.bind(1, now).bind(2, reason).bind(3, c.attempt_row);
    st.run();
  }
  {  // the bed is rebuilt once, by whichever drop noticed first
    Statement st(db,
                 "UPDATE jobs SET state='queued', output_path=NULL, output_sha256=NULL, output_bytes=NULL, "
                 "finished_at=NULL, last_error=?1, not_before=0, max_attempts=max(max_attempts, attempts+1) "
                 "WHERE job_id=?2 AND state='done' AND output_sha256=?3");
    st.bind(1, reason).bind(2, c.dep_job_id).bind(3, c.dep_sha256);
    st.run();
  }
  {  // its other drops that have not started wait for the new bed
    Statement st(db,
                 "UPDATE jobs SET state='waiting', deps_pending=deps_pending+1 WHERE state IN ('queued','failed') "
                 "AND job_id IN (SELECT job_id FROM job_deps WHERE dep_id=?)");
    st.bind(1, c.dep_job_id);
    st.run();
  }
  tx.commit();
  return true;
}

bool release(Database& db, const Claim& c, const std::string& why) {
  const double now = now_s();
  Transaction tx(db);
  {
    Statement st(db,
                 "UPDATE jobs SET state='queued', attempts=max(attempts-1, 0), lease_owner=NULL, lease_expires=NULL, "
                 "progress=NULL, phase=NULL, detail=NULL WHERE job_id=? AND lease_token=? AND state='running'");
    st.bind(1, c.job_id).bind(2, c.token);
    st.run();
    if (db.changes() != 1) return false;
  }
  Statement st(db,
               "UPDATE attempts SET outcome='released', ended_at=?1, runtime_s=?1-started_at, exit_code=130, "
               "error=?2 WHERE attempt_id=?3");
  st.bind(1, now).bind(2, why).bind(3, c.attempt_row);
  st.run();
  tx.commit();
  return true;
}

bool work_remains(Database& db) {
  Statement st(db, "SELECT EXISTS(SELECT 1 FROM jobs WHERE state IN ('queued','waiting','running','failed'))");
  st.step();
  return st.get_int(0) != 0;
}

int threads_for_claim(Database& db, const Claim& c, int threads, int pool_threads) {
  if (c.kind != "bed" || pool_threads <= threads) return threads;
  Statement st(db,
               "SELECT EXISTS(SELECT 1 FROM jobs WHERE job_id<>? AND state IN ('queued','running','failed'))");
  st.bind(1, c.job_id);
  st.step();
  return st.get_int(0) != 0 ? threads : pool_threads;
}

// ---- resume -----------------------------------------------------------------------------------

void remove_lost_files(const CampaignPaths& paths, const Reclaimed& r) {
  std::error_code ec;
  for (const auto& rel : r.output_rels) fs::remove(paths.abs(rel), ec);
  if (r.job_prefixes.empty() || !fs::exists(paths.tmp(), ec)) return;
  for (const auto& e : fs::directory_iterator(paths.tmp(), ec)) {
    const std::string name = e.path().filename().string();
    for (const auto& p : r.job_prefixes) {
      if (name.rfind(p + ".", 0) == 0) {
        fs::remove_all(e.path(), ec);
        break;
      }
    }
  }
}

ResumeReport resume(Database& db, const CampaignPaths& paths, const ResumeOptions& o) {
  ResumeReport rep;
  if (o.remove_orphans) check_files_belong(db, paths);
  const double now = now_s();
  Reclaimed lost;
  {
    Transaction tx(db);
    reap_expired(db, now, lost, 1 << 30);
    rep.expired_requeued = lost.lost - lost.dead;
    rep.expired_dead = lost.dead;
    {
      Statement st(db, "UPDATE jobs SET state='queued', not_before=0 WHERE state='failed'");
      st.run();
      rep.failed_requeued = db.changes();
    }
    if (o.retry_dead) {
      Statement a(db,
                  "UPDATE jobs SET max_attempts=max(max_attempts, attempts+?), last_error=NULL, finished_at=NULL, "
                  "deps_pending=(SELECT count(*) FROM job_deps d JOIN jobs j2 ON j2.job_id=d.dep_id "
                  "WHERE d.job_id=jobs.job_id AND j2.state!='done') WHERE state='dead'");
      a.bind(1, o.extra_attempts);
      a.run();
      Statement b(db, "UPDATE jobs SET state=CASE WHEN deps_pending>0 THEN 'waiting' ELSE 'queued' END WHERE state='dead'");
      b.run();
      rep.dead_requeued = db.changes();
    }
    if (o.dry_run) {
      // Transaction rolls back in its destructor.
    } else {
      tx.commit();
    }
  }
  if (!o.dry_run) remove_lost_files(paths, lost);

  if (o.remove_orphans) {
    auto q = quarantine_orphans(db, paths, o.dry_run);
    rep.orphans = std::move(q.moved);
    rep.restored = std::move(q.restored);
    rep.purged = q.purged;
  }
  return rep;
}

// ---- status -----------------------------------------------------------------------------------

Status status(Database& db, std::size_t max_running) {
  Status s;
  const double now = now_s();
  // A read transaction gives one consistent snapshot (WAL: does not block writers).
  Transaction tx(db, Transaction::Mode::deferred);
  std::map<std::string, std::int64_t> remaining;  // per kind, each job once
  {
    // Jobs counted under the sweep that created them (covering index jobs_sweep_state), plus the
    // few memberships of jobs shared with another sweep.
    Statement own(db, "SELECT sweep_id, kind, state, count(*) FROM jobs GROUP BY sweep_id, kind, state");
    Statement shared(db,
                     "SELECT sj.sweep_id, j.kind, j.state, count(*) FROM sweep_jobs sj JOIN jobs j ON "
                     "j.job_id=sj.job_id WHERE sj.shared=1 GROUP BY sj.sweep_id, j.kind, j.state");
    std::map<std::pair<std::string, std::string>, StateCounts> m;
    std::vector<std::pair<std::string, std::string>> order;
    for (Statement* q : {&own, &shared}) {
      Statement& st = *q;
      while (st.step()) {
        const auto key = std::make_pair(st.get_text(0), st.get_text(1));
        if (!m.count(key)) {
          order.push_back(key);
          m[key].sweep = key.first;
          m[key].kind = key.second;
        }
        auto& c = m[key];
        const std::string state = st.get_text(2);
        const std::int64_t n = st.get_int(3);
        if (state == "waiting") c.waiting += n;
        else if (state == "queued") c.queued += n;
        else if (state == "running") c.running += n;
        else if (state == "failed") c.failed += n;
        else if (state == "done") c.done += n;
        else if (state == "dead") c.dead += n;
        if (q == &own && (state == "waiting" || state == "queued" || state == "failed")) remaining[key.second] += n;
      }
    }
    std::sort(order.begin(), order.end());
    for (const auto& k : order) s.per_sweep.push_back(m[k]);
  }
  {
    Statement st(db,
                 "SELECT job_id, kind, coalesce(lease_owner,''), coalesce(phase,''), coalesce(detail,''), "
                 "coalesce(progress,0), coalesce(started_at,0), coalesce(heartbeat_at,0), coalesce(lease_expires,0), "
                 "attempts FROM jobs WHERE state='running' ORDER BY started_at");
    while (st.step()) {
      RunningJob r{st.get_text(0), st.get_text(1), st.get_text(2), st.get_text(3), st.get_text(4), st.get_double(5),
                   st.get_double(6), st.get_double(7), st.get_double(8), static_cast<int>(st.get_int(9)), false};
      r.stale = r.lease_expires < now;
      if (r.stale) ++s.stale_leases;
      else ++s.active_workers;
      if (s.running.size() < max_running || r.stale) s.running.push_back(std::move(r));
    }
  }
  {
    // Remaining work per kind, and the median runtime of that kind's finished attempts.
    std::map<std::string, KindRuntime> kinds;
    for (const auto& [kind, n] : remaining) {
      kinds[kind].kind = kind;
      kinds[kind].remaining = n;
    }
    for (const auto& r : s.running) kinds[r.kind].kind = r.kind;
    Statement cnt(db, "SELECT count(*) FROM attempts WHERE kind=? AND outcome='done'");
    Statement med(db, "SELECT runtime_s FROM attempts WHERE kind=? AND outcome='done' ORDER BY runtime_s LIMIT 1 OFFSET ?");
    double total = 0;
    bool known = true;
    for (auto& [name, k] : kinds) {
      cnt.reset();
      cnt.bind(1, name);
      cnt.step();
      k.finished = cnt.get_int(0);
      if (k.finished > 0) {
        med.reset();
        med.bind(1, name).bind(2, k.finished / 2);
        if (med.step()) k.median_s = med.get_double(0);
        total += static_cast<double>(k.remaining) * k.median_s;
      } else if (k.remaining > 0) {
        known = false;
      }
      s.runtimes.push_back(k);
    }
    for (const auto& r : s.running) {
      if (r.stale) continue;
      const auto& k = kinds[r.kind];
      if (k.finished > 0) total += std::max(0.0, k.median_s * (1 - r.progress));
      else known = false;
    }
    if (known) s.eta_s = total / static_cast<double>(std::max<std::int64_t>(1, s.active_workers));
  }
  {
    Statement st(db,
                 "SELECT count(*) FROM jobs WHERE state='dead' AND last_error LIKE 'dependency % is dead'");
    st.step();
    s.blocked = st.get_int(0);
  }
  {
    Statement st(db,
                 "SELECT job_id, coalesce(last_error,'') FROM jobs WHERE state='dead' AND "
                 "(last_error IS NULL OR last_error NOT LIKE 'dependency % is dead') ORDER BY finished_at DESC LIMIT 5");
    while (st.step()) s.recent_errors.emplace_back(st.get_text(0), st.get_text(1));
  }
  {
    Statement st(db,
                 "SELECT DISTINCT job_id, error FROM attempts WHERE kind='drop' AND error LIKE 'bed checksum "
                 "mismatch%' ORDER BY ended_at DESC LIMIT 20");
    while (st.step()) s.beds_rebuilt.emplace_back(st.get_text(0), st.get_text(1));
  }
  return s;
}

std::vector<std::string> result_columns(Database& db) {
  std::vector<std::string> cols = kFixedResultColumns;
  Statement st(db, "SELECT name FROM results_columns ORDER BY role DESC, position");  // params, then metrics
  while (st.step()) cols.push_back(st.get_text(0));
  return cols;
}

std::vector<std::string> summary_result_columns(Database& db) {
  static const std::vector<std::string> kPaperMetrics{"vc_m_s", "apeak_m_s2", "zstop_m", "tstop_s", "rebound"};
  std::vector<std::string> cols{"job_id"}, metrics;
  Statement st(db, "SELECT name, role FROM results_columns ORDER BY position");
  while (st.step()) {
    if (st.get_text(1) == "param") cols.push_back(st.get_text(0));
    else metrics.push_back(st.get_text(0));
  }
  for (const auto& m : kPaperMetrics)
    if (std::find(metrics.begin(), metrics.end(), m) != metrics.end()) cols.push_back(m);
  return cols;
}

}  // namespace gravsweep::queue
