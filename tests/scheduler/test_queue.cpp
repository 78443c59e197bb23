// The job queue on both backends, real ones: SQLite files, and a throwaway PostgreSQL server
// (label postgres: scheduler_postgres_tests). Idempotent submit, dependencies, claims, leases,
// fencing, retries with backoff, the dead state, release, resume and the results table.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>

#include <nlohmann/json.hpp>
#include <thread>

#include "scheduler/queue/queue.h"
#include "scheduler/sweep/impact_kinds.h"
#include "scheduler/sweep/spec.h"
#include "scheduler/sweep/sweep_kind.h"
#include "campaign_store.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::queue;
using gravsweep::test::sql_int;
using gravsweep::test::sql_text;
using nlohmann::json;

namespace {

sweep::SweepSpec noop_spec(const std::string& name, std::vector<double> gs, int max_attempts = 3,
                           json base = json::object()) {
  if (base.empty()) base = {{"g", 1.5}, {"sleep_s", 0.0}};
  json doc = {{"sweep", name},
              {"job", "noop"},
              {"base", base},
              {"max_attempts", max_attempts},
              {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", gs}}}}};
  return sweep::load_spec_text(doc.dump(), "test", ".");
}

sweep::CheckedPoint bed_key(const json& s) { return {s.dump(), {{"g", s["g"]}}, {}}; }

/// An impact-shaped sweep (bed + drop jobs) for the dependency logic; no job is run here.
sweep::SweepSpec impact_spec() {
  json doc = {{"sweep", "imp"},
              {"base", {{"g", 9.81}, {"v", 1.0}}},
              {"axes",
               {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {9.81, 1.62}}},
                {{"name", "speed_m_s"}, {"pointer", "/v"}, {"values", {1.0, 2.0, 3.0}}}}}};
  return sweep::load_spec_text(doc.dump(), "test", ".");
}

struct QueueTest : ::testing::TestWithParam<test::Store> {
  test::TempDir dir;
  test::CampaignStore store{GetParam(), dir.path};
  std::filesystem::path db_path = store.location;
  db::Database db{db_path.string()};
  CampaignPaths paths{db_path, store.files};
  WorkerIdentity me = make_identity("test", 1);
  void SetUp() override {
    if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
    ensure_schema(db);
  }
  /// The values of the first column of `sql`, joined by commas.
  std::string joined(const std::string& sql) {
    db::Statement st(db, sql);
    std::string out;
    while (st.step()) out += (out.empty() ? "" : ",") + st.get_text(0);
    return out;
  }
  /// An impact sweep planned on the bed key `key` (a drop per point, a bed per key), or a sweep of
  /// its registered kind (noop) without one.
  SubmitReport submit_spec(const sweep::SweepSpec& s, const sweep::PointCheckFn& key = {}) {
    if (!key) return submit(db, s, sweep::expand(s));
    const sweep::SweepKind kind{
        "impact", "test", {}, sweep::shared_input_planner(key, sweep::drop_kind(), sweep::bed_kind()), {}};
    return submit(db, s, sweep::expand(s, kind));
  }
  Completion done_for(const Claim& c, double value = 1.0) {
    Completion d;
    d.output_rel = c.output_rel;
    d.sha256 = std::string(64, 'a');
    d.bytes = 1;
    // What each kind declares (a bed's job is no results row: no metrics).
    if (c.kind == sweep::drop_kind())
      d.values = {{"apeak_m_s2", value}, {"rebound", false}, {"note", nullptr}};
    else if (c.kind == noop_kind())
      d.values = {{"noop_value", value}, {"sleep_s", 0.25}};
    return d;
  }
};

}  // namespace

TEST_P(QueueTest, SubmitTwiceAddsNothingExtensionAddsOnlyNewJobs) {
  auto r1 = submit_spec(noop_spec("s", {1, 2, 3}));
  EXPECT_EQ(r1.added, 3u);
  EXPECT_EQ(r1.present, 0u);
  EXPECT_TRUE(r1.sweep_new);
  auto r2 = submit_spec(noop_spec("s", {1, 2, 3}));
  EXPECT_EQ(r2.added, 0u);
  EXPECT_EQ(r2.present, 3u);
  auto r3 = submit_spec(noop_spec("s", {1, 2, 3, 4.5}));
  EXPECT_EQ(r3.added, 1u);
  EXPECT_EQ(r3.present, 3u);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs"), 4);
  EXPECT_EQ(sql_int(db, "SELECT submits FROM sweeps WHERE sweep_id='s'"), 3);
  // A second sweep sharing points shares the jobs (content addressed) but counts them in both.
  auto r4 = submit_spec(noop_spec("t", {1, 7}));
  EXPECT_EQ(r4.added, 1u);
  EXPECT_EQ(r4.present, 1u);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM sweep_jobs"), 6);
  // One results column per swept parameter, created at submit.
  const auto cols = result_columns(db);
  EXPECT_NE(std::find(cols.begin(), cols.end(), "gravity_m_s2"), cols.end());
}

TEST_P(QueueTest, ANonIntegerValueWidensAnIntegerResultsColumnAndKeepsItsValues) {
  // An axis of 1, 2 gets an INTEGER column; extended by 2.5 it must hold 2.5 (it used to refuse the
  // row: "cannot store REAL value in INTEGER column"). A metric declared REAL is REAL from submit
  // on: a first value of 3 no longer types it INTEGER.
  submit_spec(noop_spec("s", {1, 2}));
  auto finish = [&](const json& value) {
    auto c = claim(db, me, paths, 60);
    if (!c) return false;
    Completion d = done_for(*c);
    d.values["noop_value"] = value;
    return complete(db, *c, d);
  };
  EXPECT_TRUE(finish(3));
  EXPECT_TRUE(finish(4));
  EXPECT_EQ(sql_text(db, "SELECT sql_type FROM results_columns WHERE name='gravity_m_s2'"), "INTEGER");
  EXPECT_EQ(sql_text(db, "SELECT sql_type FROM results_columns WHERE name='noop_value'"), "REAL");
  submit_spec(noop_spec("s", {1, 2, 2.5}));
  EXPECT_EQ(sql_text(db, "SELECT sql_type FROM results_columns WHERE name='gravity_m_s2'"), "REAL");
  EXPECT_TRUE(finish(3.5)) << "the row with 2.5 (and a metric of 3.5) is stored";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE gravity_m_s2 IN (1, 2)"), 2);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE gravity_m_s2=2.5 AND noop_value=3.5"), 1);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE noop_value IN (3, 4)"), 2);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE sleep_s=0.25"), 3) << "other columns kept";
  // The rebuilt table still refuses a result for a job that does not exist (its foreign key).
  EXPECT_THROW(db.exec("INSERT INTO results(job_id, sweep, kind, attempt) VALUES('nope', 's', 'noop', 1)"),
               db::DbError);
}

TEST_P(QueueTest, DropsWaitForTheirBedAndBedsAreClaimedFirst) {
  auto r = submit_spec(impact_spec(), bed_key);
  EXPECT_EQ(r.added_by_kind[sweep::bed_kind()], 2u);
  EXPECT_EQ(r.added_by_kind[sweep::drop_kind()], 6u);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='waiting'"), 6);
  auto bed = claim(db, me, paths, 60);
  ASSERT_TRUE(bed);
  EXPECT_EQ(bed->kind, "bed");
  auto bed2 = claim(db, me, paths, 60);
  ASSERT_TRUE(bed2);
  EXPECT_EQ(bed2->kind, "bed");
  EXPECT_FALSE(claim(db, me, paths, 60)) << "drops must wait for their bed";
  EXPECT_TRUE(work_remains(db));
  ASSERT_TRUE(complete(db, *bed, done_for(*bed)));
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='queued' AND kind='drop'"), 3);
  auto drop = claim(db, me, paths, 60);
  ASSERT_TRUE(drop);
  EXPECT_EQ(drop->kind, "drop");
  EXPECT_EQ(drop->dep_output_rel, bed->output_rel);
  ASSERT_TRUE(complete(db, *drop, done_for(*drop, 42.0)));
  EXPECT_EQ(sql_text(db, "SELECT bed_job_id FROM results"), bed->job_id);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE apeak_m_s2=42.0 AND rebound=0"), 1);
  // Extending the sweep after the bed finished: the new drops of that bed are queued at once.
  auto spec = impact_spec();
  json doc = json::parse(spec.spec_json);  // the spec as written, its base inlined
  doc["axes"][1]["values"].push_back(4.0);
  auto r2 = submit_spec(sweep::load_spec_text(doc.dump(), "test", "."), bed_key);
  EXPECT_EQ(r2.added, 2u);
  EXPECT_EQ(r2.present, 8u);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE kind='drop' AND state='queued'"), 3);
}

TEST_P(QueueTest, ExpiredLeaseIsReclaimedAndTheLateCompletionIsFencedOut) {
  submit_spec(noop_spec("s", {1}));
  auto first = claim(db, me, paths, 0.2);
  ASSERT_TRUE(first);
  EXPECT_TRUE(heartbeat(db, *first, 0.2, 0.3, "noop", "x"));
  EXPECT_DOUBLE_EQ(std::stod(sql_text(db, "SELECT progress FROM jobs")), 0.3);
  // A second worker (its own connection) cannot take a live lease...
  db::Database other_db(db_path.string());
  const auto other = make_identity("test", 1);
  EXPECT_FALSE(claim(other_db, other, paths, 60));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  // ...but takes the expired one; the first attempt is closed as lost.
  Reclaimed lost;
  auto second = claim(other_db, other, paths, 60, &lost);
  ASSERT_TRUE(second);
  EXPECT_EQ(lost.lost, 1);
  ASSERT_EQ(lost.output_rels.size(), 1u);
  EXPECT_EQ(lost.output_rels[0], first->output_rel);
  EXPECT_EQ(second->job_id, first->job_id);
  EXPECT_EQ(second->attempt, 2);
  EXPECT_GT(second->token, first->token);
  // The stalled first worker wakes up: its heartbeat and completion are refused.
  EXPECT_FALSE(heartbeat(db, *first, 60, 0.9, "noop", ""));
  EXPECT_FALSE(complete(db, *first, done_for(*first)));
  EXPECT_EQ(fail(db, *first, "late", 1, false), "");
  EXPECT_TRUE(complete(other_db, *second, done_for(*second)));
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results"), 1);
  EXPECT_EQ(sql_int(db, "SELECT attempt FROM results"), 2);
  EXPECT_EQ(joined("SELECT outcome FROM attempts ORDER BY attempt_id"), "lost,done");
}

TEST_P(QueueTest, RetriesWithBackoffThenDead) {
  submit_spec(noop_spec("s", {1}, 3));
  for (int attempt = 1; attempt <= 3; ++attempt) {
    auto c = claim(db, me, paths, 60);
    ASSERT_TRUE(c) << "attempt " << attempt;
    EXPECT_EQ(c->attempt, attempt);
    const std::string state = fail(db, *c, "boom", 1, false, /*backoff_base_s=*/0.05 * attempt);
    EXPECT_EQ(state, attempt < 3 ? "failed" : "dead");
    if (attempt < 3) {
      // Not claimable during the backoff (base * 2^(attempt-1), here >= 50 ms)...
      const double nb = std::stod(sql_text(db, "SELECT not_before FROM jobs"));
      EXPECT_GE(nb - now_s(), 0.03 * attempt);
      EXPECT_FALSE(claim(db, me, paths, 60));
      std::this_thread::sleep_for(std::chrono::duration<double>(nb - now_s() + 0.02));
    }
  }
  EXPECT_FALSE(claim(db, me, paths, 60));
  EXPECT_FALSE(work_remains(db));
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome IN ('failed','dead') AND error='boom'"), 3);
  // resume --dead gives it another try.
  ResumeOptions o;
  o.retry_dead = true;
  o.extra_attempts = 1;
  const auto rep = resume(db, paths, o);
  EXPECT_EQ(rep.dead_requeued, 1);
  auto c = claim(db, me, paths, 60);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->attempt, 4);
  EXPECT_TRUE(complete(db, *c, done_for(*c)));
}

TEST_P(QueueTest, PermanentErrorGoesDeadAtOnceAndKillsDependents) {
  submit_spec(impact_spec(), bed_key);
  auto bed = claim(db, me, paths, 60);
  ASSERT_TRUE(bed);
  EXPECT_EQ(fail(db, *bed, "numerical failure", 3, true), "dead");
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='dead' AND kind='drop'"), 3);
  const auto s = status(db);
  EXPECT_EQ(s.blocked, 3);
  ASSERT_FALSE(s.recent_errors.empty());
  EXPECT_EQ(s.recent_errors[0].second, "numerical failure");
  // resume --dead revives the bed and puts its drops back to waiting.
  ResumeOptions o;
  o.retry_dead = true;
  resume(db, paths, o);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='waiting'"), 6);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='queued' AND kind='bed'"),
            2);  // the revived bed and the one never claimed
}

TEST_P(QueueTest, ReleaseDoesNotSpendTheBudget) {
  submit_spec(noop_spec("s", {1}, 1));
  auto c = claim(db, me, paths, 60);
  ASSERT_TRUE(c);
  EXPECT_EQ(release(db, *c, "SIGTERM"), "queued");
  EXPECT_EQ(sql_text(db, "SELECT state FROM jobs"), "queued");
  EXPECT_EQ(sql_int(db, "SELECT attempts FROM jobs"), 0);
  auto again = claim(db, me, paths, 60);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->attempt, 1);
  EXPECT_GT(again->token, c->token);
  EXPECT_EQ(release(db, *c, "stale"), "") << "an old token cannot release the new lease";
}

// A job interrupted at every attempt (a Slurm time limit shorter than the job) does not loop
// forever uncounted: each release is counted apart from the retry budget, `status` shows them,
// and the job stops (dead, with the reason) at the release limit; `resume --dead` revives it.
TEST_P(QueueTest, ReleasesAreCountedAndAJobReleasedTooOftenStops) {
  submit_spec(noop_spec("s", {1}, 3));
  for (int i = 1; i <= 5; ++i) {
    auto c = claim(db, me, paths, 60);
    ASSERT_TRUE(c) << "release " << i << ": "
                   << sql_text(db, "SELECT state || ' ' || coalesce(last_error,'') FROM jobs");
    EXPECT_EQ(c->attempt, 1) << "a released attempt is not counted against the retry budget";
    release(db, *c, "time limit");
    EXPECT_EQ(sql_int(db, "SELECT releases FROM jobs"), i);
    EXPECT_EQ(sql_int(db, "SELECT attempts FROM jobs"), 0);
    EXPECT_EQ(sql_text(db, "SELECT state FROM jobs"), i < 5 ? "queued" : "dead");
  }
  EXPECT_FALSE(claim(db, me, paths, 60)) << "stopped after 5 releases";
  EXPECT_NE(sql_text(db, "SELECT last_error FROM jobs").find("released 5 times in a row without finishing"),
            std::string::npos)
      << sql_text(db, "SELECT last_error FROM jobs");
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='released'"), 5);
  const auto st = test::run_cli({"status", "--db", store.location}, dir.path);
  ASSERT_EQ(st.code, 0) << st.err;
  EXPECT_NE(st.out.find("5 attempt(s) released"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("1 job(s) stopped after too many releases"), std::string::npos) << st.out;
  ResumeOptions o;
  o.retry_dead = true;
  resume(db, paths, o);
  EXPECT_EQ(sql_int(db, "SELECT releases FROM jobs"), 0);
  auto again = claim(db, me, paths, 60);
  ASSERT_TRUE(again);
  EXPECT_TRUE(complete(db, *again, done_for(*again)));
}

// A long drop run across many batch tasks is released once per task, each time after saving a
// checkpoint further on: those releases never stop it. Only releases in a row that saved nothing
// count towards the limit, and one that saved progress starts the count again.
TEST_P(QueueTest, ReleasesThatSavedProgressNeverStopTheJob) {
  submit_spec(noop_spec("s", {1}, 3));
  auto release_once = [&](bool saved_progress) {
    auto c = claim(db, me, paths, 60);
    EXPECT_TRUE(c) << sql_text(db, "SELECT state || ' ' || coalesce(last_error,'') FROM jobs");
    return c ? release(db, *c, "time limit", kDefaultMaxReleases, saved_progress) : std::string("not claimed");
  };
  for (int i = 1; i <= 2 * kDefaultMaxReleases; ++i) EXPECT_EQ(release_once(true), "queued") << "release " << i;
  EXPECT_EQ(sql_int(db, "SELECT releases FROM jobs"), 2 * kDefaultMaxReleases);
  EXPECT_EQ(sql_int(db, "SELECT stalled_releases FROM jobs"), 0);
  for (int i = 1; i < kDefaultMaxReleases; ++i) EXPECT_EQ(release_once(false), "queued") << "stall " << i;
  EXPECT_EQ(release_once(true), "queued") << "progress starts the count again";
  for (int i = 1; i < kDefaultMaxReleases; ++i) EXPECT_EQ(release_once(false), "queued") << "stall " << i;
  EXPECT_EQ(release_once(false), "dead") << kDefaultMaxReleases << " releases in a row saved nothing";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='released'"), 4 * kDefaultMaxReleases);
}

TEST_P(QueueTest, ResumeRequeuesExpiredAndFailedAndRemovesOrphans) {
  submit_spec(noop_spec("s", {1, 2, 3}));
  auto a = claim(db, me, paths, 0.1);
  auto b = claim(db, me, paths, 60);
  auto live = claim(db, me, paths, 60);
  ASSERT_TRUE(a && b && live);
  fail(db, *b, "transient", 1, false, 100);
  // Files: one of the lost attempt, one orphan with no owner, one of the live attempt.
  std::filesystem::create_directories(paths.root / "noop");
  std::filesystem::create_directories(paths.tmp());
  test::write_text(paths.abs(a->output_rel), "lost");
  test::write_text(paths.root / "noop" / "ffffffffffffffffffff.a9.json", "orphan");
  // An orphan is moved only when it is older than the resume's snapshot: this
  // one was left an hour ago.
  std::filesystem::last_write_time(paths.root / "noop" / "ffffffffffffffffffff.a9.json",
                                   std::filesystem::file_time_type::clock::now() - std::chrono::hours(1));
  test::write_text(paths.tmp() / (live->job_id + ".a1.out.json"), "in progress");
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  const auto rep = resume(db, paths, ResumeOptions{});
  EXPECT_EQ(rep.expired_requeued, 1);
  EXPECT_EQ(rep.failed_requeued, 1);
  EXPECT_EQ(rep.orphans.size(), 1u);
  EXPECT_FALSE(std::filesystem::exists(paths.abs(a->output_rel)));
  EXPECT_FALSE(std::filesystem::exists(paths.root / "noop" / "ffffffffffffffffffff.a9.json"));
  EXPECT_TRUE(std::filesystem::exists(paths.tmp() / (live->job_id + ".a1.out.json")));
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='queued'"), 2);
  if (GetParam() == test::Store::sqlite) {
    EXPECT_EQ(sql_text(db, "PRAGMA integrity_check"), "ok");
  }
}

TEST_P(QueueTest, StatusCountsRunningAndEta) {
  submit_spec(noop_spec("s", {1, 2, 3, 4}));
  auto c = claim(db, me, paths, 60);
  ASSERT_TRUE(c);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_TRUE(complete(db, *c, done_for(*c)));
  auto r = claim(db, me, paths, 60);
  ASSERT_TRUE(r);
  heartbeat(db, *r, 60, 0.5, "drop", "t = 0.1 s");
  const auto s = status(db);
  ASSERT_EQ(s.per_sweep.size(), 1u);
  EXPECT_EQ(s.per_sweep[0].done, 1);
  EXPECT_EQ(s.per_sweep[0].running, 1);
  EXPECT_EQ(s.per_sweep[0].queued, 2);
  ASSERT_EQ(s.running.size(), 1u);
  EXPECT_DOUBLE_EQ(s.running[0].progress, 0.5);
  EXPECT_EQ(s.running[0].phase, "drop");
  EXPECT_EQ(s.active_workers, 1);
  ASSERT_EQ(s.runtimes.size(), 1u);
  EXPECT_GT(s.runtimes[0].median_s, 0.04);
  // 2 queued + half of the running one, each at the median runtime, over 1 worker.
  EXPECT_NEAR(s.eta_s, 2.5 * s.runtimes[0].median_s, 1e-9);
}

TEST_P(QueueTest, EtaTakesTheMedianOfTheSameSweepNotOfEveryJobOfTheKind) {
  // Two fast jobs of one sweep finished, one slow job of another: the slow sweep's remaining job is
  // estimated at the slow one's runtime (the kind-wide median, a fast one, said almost nothing left:
  // a campaign of 1 g drops and 0.1 m/s2 drops showed "ETA 14 min" for hours of work).
  submit_spec(noop_spec("fast", {1, 2}));
  submit_spec(noop_spec("slow", {3, 4}));
  for (int i = 0; i < 3; ++i) {
    auto c = claim(db, me, paths, 60);
    ASSERT_TRUE(c);
    if (i == 2) {
      ASSERT_EQ(sql_text(db, "SELECT sweep_id FROM jobs WHERE job_id='" + c->job_id + "'"), "slow");
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
    }
    ASSERT_TRUE(complete(db, *c, done_for(*c)));
    if (i == 2) {
      const double slow_s = std::stod(sql_text(db, "SELECT runtime_s FROM attempts WHERE job_id='" + c->job_id + "'"));
      const auto s = status(db);
      ASSERT_EQ(s.runtimes.size(), 1u);
      EXPECT_LT(s.runtimes[0].median_s, 0.5 * slow_s) << "the kind's median is a fast job's";
      EXPECT_NEAR(s.eta_s, slow_s, 1e-6) << "one slow job left, one worker's worth";
    }
  }
}

TEST_P(QueueTest, EtaOfASweepWithNothingFinishedComesFromItsRunningJobsProgress) {
  submit_spec(noop_spec("fast", {1}));
  submit_spec(noop_spec("slow", {3, 4}));
  auto f = claim(db, me, paths, 60);
  ASSERT_TRUE(f);
  ASSERT_TRUE(complete(db, *f, done_for(*f)));  // the kind's median: a fast job's
  auto r = claim(db, me, paths, 60);
  ASSERT_TRUE(r);
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  heartbeat(db, *r, 60, 0.5, "drop", "half way");
  const auto s = status(db);
  // Half way after ~0.4 s projects ~0.8 s a job: ~0.4 s left of it, ~0.8 s for the queued one.
  EXPECT_GT(s.eta_s, 0.9);
  EXPECT_LT(s.eta_s, 3.0);
}

// How fast `status` is on 100,000 jobs is a benchmark (`gravsweep bench-queue --status-jobs 100000`,
// BENCHMARKS.md), never a timed test: a loaded CI host took 1.6 s where a quiet one takes 40 ms.
TEST_P(QueueTest, StatusCountsAHundredThousandJobs) {
  json doc = {{"sweep", "big"},
              {"job", "noop"},
              {"base", {{"i", 0}}},
              {"axes", {{{"name", "i"}, {"pointer", "/i"}, {"range", {{"start", 0}, {"stop", 99999}, {"step", 1}}}}}}};
  const auto spec = sweep::load_spec_text(doc.dump(), "test", ".");
  const auto r = submit_spec(spec);
  ASSERT_EQ(r.added, 100000u);
  for (int i = 0; i < 3; ++i) {
    auto c = claim(db, me, paths, 60);
    ASSERT_TRUE(c);
    if (i < 2) {
      ASSERT_TRUE(complete(db, *c, done_for(*c)));
    }
  }
  const auto s = status(db);
  ASSERT_EQ(s.per_sweep.size(), 1u);
  EXPECT_EQ(s.per_sweep[0].queued, 99997);
  EXPECT_EQ(s.per_sweep[0].done, 2);
  EXPECT_EQ(s.per_sweep[0].running, 1);
  EXPECT_GT(s.eta_s, 0);
  ASSERT_EQ(s.running.size(), 1u);
  EXPECT_EQ(s.running[0].job_id, sql_text(db, "SELECT job_id FROM jobs WHERE state='running'"));
}

TEST_P(QueueTest, ABedThatRunsAloneGetsThePoolsThreads) {
  // Two beds claimable: the first one claimed shares the machine (the other bed waits for a worker).
  submit_spec(impact_spec(), bed_key);
  auto bed = claim(db, me, paths, 60);
  ASSERT_TRUE(bed);
  EXPECT_EQ(threads_for_claim(db, *bed, 1, 2), 1) << "another bed is claimable";
  // The second bed while the first still runs: still its own share.
  auto bed2 = claim(db, me, paths, 60);
  ASSERT_TRUE(bed2);
  EXPECT_EQ(threads_for_claim(db, *bed2, 1, 2), 1) << "another bed is running";
  // The first bed done: its drops are claimable, so the second bed keeps one thread.
  ASSERT_TRUE(complete(db, *bed, done_for(*bed)));
  EXPECT_EQ(threads_for_claim(db, *bed2, 1, 2), 1) << "drops are claimable";
  // Every drop done: the second bed is alone (its drops wait for it) and gets the pool.
  while (auto d = claim(db, me, paths, 60)) {
    EXPECT_EQ(threads_for_claim(db, *d, 1, 2), 1) << "drops keep the worker's threads";
    ASSERT_TRUE(complete(db, *d, done_for(*d)));
  }
  EXPECT_EQ(threads_for_claim(db, *bed2, 1, 2), 2);
  EXPECT_EQ(threads_for_claim(db, *bed2, 2, 2), 2) << "one worker: its own threads";
}

GRAVSWEEP_INSTANTIATE_ON_THE_QUEUE_BACKEND(QueueTest);

// A kind registered by the library that plans and runs it: its name enters a new database's check
// of jobs.kind and its folder the files root; a name registered again with another row, or a
// folder two kinds would share, is refused; an unknown name lists the registered ones.
TEST(JobKinds, AreRegisteredByTheLibrariesThatRunThem) {
  const JobKind probe = register_kind({"kind_probe", "kind_probe_out", ".json", true, false, {}});
  EXPECT_EQ(register_kind({"kind_probe", "kind_probe_out", ".json", true, false, {}}), probe) << "same row: same kind";
  EXPECT_EQ(parse_kind("kind_probe"), probe);
  EXPECT_EQ(parse_kind("bed"), sweep::bed_kind());
  EXPECT_EQ(parse_kind("noop"), noop_kind());
  EXPECT_THROW(register_kind({"kind_probe", "elsewhere", ".json", true, false, {}}), gravsweep::ConfigError);
  EXPECT_THROW(register_kind({"another", "beds", ".h5", true, false, {}}), gravsweep::ConfigError)
      << "beds/ is the bed kind's";
  EXPECT_THROW(register_kind({"scratch", "tmp", ".h5", true, false, {}}), gravsweep::ConfigError)
      << "tmp/ holds running attempts";
  try {
    parse_kind("gpu");
    ADD_FAILURE() << "an unknown kind was accepted";
  } catch (const gravsweep::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("noop, bed, drop, kind_probe"), std::string::npos) << e.what();
  }
  const auto folders = kind_folders();
  EXPECT_NE(std::find(folders.begin(), folders.end(), "kind_probe_out"), folders.end());
  test::TempDir dir;
  db::Database db((dir.path / "kinds.db").string());
  ensure_schema(db);
  const std::string sql = sql_text(db, "SELECT sql FROM sqlite_master WHERE name='jobs'");
  EXPECT_NE(sql.find("'noop','bed','drop','kind_probe'"), std::string::npos) << sql;
}
