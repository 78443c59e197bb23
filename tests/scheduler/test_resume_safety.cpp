// `resume` never loses data, with real processes on real files:
// - a loop of `resume` beside `work --workers 8` on 400 no-op jobs loses no finished output;
// - a 0-byte or foreign database next to a full files folder is refused by every verb but submit;
// - a renamed copy of a campaign (backup + copied folder) resumes without removing anything, and a
//   database whose folder does not belong to it is refused before anything is removed.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <csignal>
#include <nlohmann/json.hpp>
#include <thread>

#include "db/database.h"
#include "scheduler/pipeline/impact_runners.h"
#include "scheduler/queue/canonical.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

/// A no-op sweep of `n` jobs (0.01, 0.02, ... on /g), each sleeping `sleep_s`.
std::string noop_sweep(int n, double sleep_s) {
  json doc = {{"sweep", "race"},
              {"job", "noop"},
              {"max_attempts", 5},
              {"base", {{"g", 1.0}, {"sleep_s", sleep_s}}},
              {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", json::array()}}}}};
  for (int i = 1; i <= n; ++i) doc["axes"][0]["values"].push_back(i * 0.01);
  return doc.dump();
}

/// Counts done jobs whose file is missing or does not match its recorded checksum.
int lost_outputs(db::Database& db, const fs::path& dir, const std::string& stem, std::string* first = nullptr) {
  int lost = 0;
  db::Statement st(db, "SELECT output_path, output_sha256 FROM jobs WHERE state='done'");
  while (st.step()) {
    const fs::path p = campaign_file(dir, stem, st.get_text(0));
    if (!fs::exists(p) || queue::sha256_file(p) != st.get_text(1)) {
      if (first && lost == 0) *first = p.string();
      ++lost;
    }
  }
  return lost;
}

std::size_t files_under(const fs::path& dir) {
  std::size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec))
    if (e.is_regular_file()) ++n;
  return n;
}

/// A finished no-op campaign of `n` jobs in dir/c.db.
void finished_campaign(const fs::path& dir, int n) {
  write_text(dir / "spec.json", noop_sweep(n, 0.0));
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, dir).code, 0);
  const auto r = run_cli({"work", "--db", "c.db", "--workers", "2", "--quiet"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
}

}  // namespace

TEST(ResumeSafety, ResumeLoopBesideEightWorkersLosesNoFinishedOutput) {
  TempDir d;
  constexpr int kJobs = 400;
  write_text(d.path / "spec.json", noop_sweep(kJobs, 0.0));
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "r.db"}, d.path).code, 0);
  const std::string db_path = (d.path / "r.db").string();
  const pid_t work = start_cli({"work", "--db", db_path, "--workers", "8", "--lease", "5", "--threads", "1", "--quiet"},
                               d.path / "work.log");
  int resumes = 0, resume_failures = 0;
  std::string resume_err;
  const auto t0 = std::chrono::steady_clock::now();
  while (waitpid(work, nullptr, WNOHANG) == 0) {
    // waitpid with WNOHANG reaped nothing: the supervisor still runs.
    const auto r = run_cli({"resume", "--db", "r.db"}, d.path);
    ++resumes;
    if (r.code != 0) {
      ++resume_failures;
      resume_err = r.err;
    }
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(50)) {
      kill(work, SIGKILL);
      FAIL() << "work did not finish in 50 s";
    }
  }
  // The supervisor was reaped by waitpid above; its exit code is lost, so check the database.
  db::Database db(db_path);
  std::string first;
  const int lost = lost_outputs(db, d.path, "r", &first);
  const auto no_output = sql_int(db,
                                 "SELECT count(*) FROM attempts WHERE error LIKE '%wrote no output%' OR "
                                 "error LIKE '%cannot rename%' OR error LIKE '%filesystem error%'");
  std::printf(
      "resume loop: %d resumes beside 8 workers on %d jobs: %d done files lost, %lld attempts lost their "
      "file\n",
      resumes, kJobs, lost, static_cast<long long>(no_output));
  ::testing::Test::RecordProperty("resumes", resumes);
  EXPECT_GE(resumes, 3) << "the loop must overlap the workers";
  EXPECT_EQ(resume_failures, 0) << resume_err;
  EXPECT_EQ(lost, 0) << "first: " << first;
  EXPECT_EQ(no_output, 0);
  // Everything finishes (work again picks up anything a lost file sent back).
  const auto r = run_cli({"work", "--db", "r.db", "--quiet"}, d.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), kJobs);
  EXPECT_EQ(lost_outputs(db, d.path, "r"), 0);
  const auto log = run_cli({"status", "--db", "r.db"}, d.path);
  EXPECT_EQ(log.code, 0) << log.err;
}

TEST(ResumeSafety, OrphansGoToQuarantineAndTheNextResumeEmptiesIt) {
  TempDir d;
  ASSERT_NO_FATAL_FAILURE(finished_campaign(d.path, 3));
  const fs::path orphan = d.path / "c.files" / "noop" / "deadbeef.a1.json";
  write_text(orphan, "left by a killed attempt");
  // An old file: orphans are only files older than any live lease and than the resume itself.
  fs::last_write_time(orphan, fs::file_time_type::clock::now() - std::chrono::seconds(60));
  auto r = run_cli({"resume", "--db", "c.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("orphaned files moved to quarantine: 1"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(orphan));
  EXPECT_EQ(files_under(d.path / "c.files" / "quarantine"), 1u);
  r = run_cli({"resume", "--db", "c.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("quarantined files removed: 1"), std::string::npos) << r.out;
  EXPECT_EQ(files_under(d.path / "c.files" / "quarantine"), 0u);
  // A fresh orphan (younger than the resume's margin) stays for the next resume.
  write_text(orphan, "new");
  r = run_cli({"resume", "--db", "c.db"}, d.path);
  EXPECT_NE(r.out.find("orphaned files moved to quarantine: 0"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(orphan));
  db::Database db((d.path / "c.db").string());
  EXPECT_EQ(lost_outputs(db, d.path, "c"), 0);
}

TEST(ResumeSafety, EveryVerbButSubmitRefusesAnEmptyOrForeignDatabase) {
  TempDir d;
  ASSERT_NO_FATAL_FAILURE(finished_campaign(d.path, 5));
  const std::size_t files = files_under(d.path / "c.files");
  ASSERT_EQ(files, 6u) << "5 outputs and the files root's marker";
  fs::resize_file(d.path / "c.db", 0);
  fs::remove(d.path / "c.db-wal");
  fs::remove(d.path / "c.db-shm");
  const std::vector<std::vector<std::string>> verbs = {{"status"}, {"results"}, {"resume"}, {"work"}};
  for (const auto& v : verbs) {
    std::vector<std::string> args = v;
    args.insert(args.end(), {"--db", "c.db"});
    const auto r = run_cli(args, d.path);
    EXPECT_EQ(r.code, 2) << v[0] << ": " << r.out << r.err;
    EXPECT_NE(r.err.find("c.db"), std::string::npos) << v[0] << ": " << r.err;
    EXPECT_NE(r.err.find("not a gravsweep campaign"), std::string::npos) << v[0] << ": " << r.err;
    EXPECT_EQ(fs::file_size(d.path / "c.db"), 0u) << v[0] << " wrote into the database";
  }
  EXPECT_EQ(files_under(d.path / "c.files"), files) << "no output may be removed";
  // A SQLite file of something else (another program's tables): refused too, and left as it was.
  {
    db::Database other((d.path / "o.db").string());
    other.exec("CREATE TABLE notes(x TEXT)");
  }
  for (const auto& v : verbs) {
    std::vector<std::string> args = v;
    args.insert(args.end(), {"--db", "o.db"});
    const auto r = run_cli(args, d.path);
    EXPECT_EQ(r.code, 2) << v[0] << ": " << r.err;
    EXPECT_NE(r.err.find("not a gravsweep campaign"), std::string::npos) << v[0] << ": " << r.err;
  }
  db::Database other((d.path / "o.db").string());
  EXPECT_EQ(sql_int(other, "SELECT count(*) FROM sqlite_master WHERE name='jobs'"), 0);
  // submit into the empty file next to a files folder: refused as well (it would hide the outputs).
  const auto r = run_cli({"submit", "spec.json", "--db", "c.db"}, d.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("c.files"), std::string::npos) << r.err;
  EXPECT_EQ(files_under(d.path / "c.files"), files);
}

TEST(ResumeSafety, RenamedCopyResumesWithoutRemovingItsOutputs) {
  TempDir d;
  ASSERT_NO_FATAL_FAILURE(finished_campaign(d.path, 6));
  {
    db::Database db((d.path / "c.db").string());
    db.exec("VACUUM INTO '" + (d.path / "c2.db").string() + "'");
  }
  fs::copy(d.path / "c.files", d.path / "c2.files", fs::copy_options::recursive);
  auto r = run_cli({"resume", "--db", "c2.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("orphaned files moved to quarantine: 0"), std::string::npos) << r.out;
  EXPECT_EQ(files_under(d.path / "c2.files" / "noop"), 6u);
  {
    db::Database c2((d.path / "c2.db").string());
    EXPECT_EQ(lost_outputs(c2, d.path, "c2"), 0);
  }
  // The original is untouched by the copy's resume, and the copy no longer names c.files.
  fs::remove_all(d.path / "c.files");
  r = run_cli({"results", "--db", "c2.db", "--format", "json"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.find("c.files"), std::string::npos) << r.out;
  // A database whose folder does not hold its outputs: resume refuses to touch anything.
  fs::copy(d.path / "c2.db", d.path / "c3.db");
  fs::create_directories(d.path / "c3.files" / "noop");
  write_text(d.path / "c3.files" / "noop" / "other.a1.json", "{}");
  fs::last_write_time(d.path / "c3.files" / "noop" / "other.a1.json",
                      fs::file_time_type::clock::now() - std::chrono::seconds(60));
  r = run_cli({"resume", "--db", "c3.db"}, d.path);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("6 of 6"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(d.path / "c3.files" / "noop" / "other.a1.json"));
}

TEST(ResumeSafety, VersionOneCampaignIsMigratedAndItsRenamedCopyKeepsItsFiles) {
  TempDir d;
  ASSERT_NO_FATAL_FAILURE(finished_campaign(d.path, 4));
  {
    // As gravsweep wrote campaigns before schema version 2: paths relative to the database's folder.
    db::Database db((d.path / "c.db").string());
    db.exec(
        "UPDATE jobs SET output_path='c.files/' || output_path; UPDATE attempts SET output_path='c.files/' || "
        "output_path; UPDATE results SET trace_path='c.files/' || trace_path; UPDATE queue_meta SET value='1' "
        "WHERE key='schema_version'");
    db.exec("VACUUM INTO '" + (d.path / "c2.db").string() + "'");
  }
  fs::copy(d.path / "c.files", d.path / "c2.files", fs::copy_options::recursive);
  auto r = run_cli({"status", "--db", "c2.db"}, d.path);  // read-only verbs read version 1 as it is
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli({"resume", "--db", "c2.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("orphaned files moved to quarantine: 0"), std::string::npos) << r.out;
  db::Database c2((d.path / "c2.db").string());
  EXPECT_EQ(sql_text(c2, "SELECT value FROM queue_meta WHERE key='schema_version'"), "2");
  EXPECT_EQ(sql_int(c2, "SELECT count(*) FROM jobs WHERE output_path LIKE '%.files%'"), 0);
  EXPECT_EQ(sql_int(c2, "SELECT count(*) FROM results WHERE trace_path LIKE 'noop/%'"), 4);
  EXPECT_EQ(lost_outputs(c2, d.path, "c2"), 0);
  EXPECT_EQ(files_under(d.path / "c2.files" / "noop"), 4u);
}

TEST(BedChecksum, AFlippedBitInAFinishedBedFailsTheDropAndRebuildsTheBed) {
  TempDir d;
  write_text(d.path / "spec.json", tiny_speed_sweep("flip", {0.4, 0.6}));
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  auto r = run_cli({"work", "--db", "c.db", "--max-jobs", "1", "--quiet"}, d.path);  // the bed (priority)
  ASSERT_EQ(r.code, 0) << r.err;
  db::Database db((d.path / "c.db").string());
  ASSERT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE kind='bed' AND state='done'"), 1);
  const fs::path bed = campaign_file(d.path, "c", sql_text(db, "SELECT output_path FROM jobs WHERE kind='bed'"));
  {  // one bit, in the middle of the file
    std::fstream f(bed, std::ios::in | std::ios::out | std::ios::binary);
    const auto mid = static_cast<std::streamoff>(fs::file_size(bed) / 2);
    f.seekg(mid);
    char b = 0;
    f.get(b);
    f.seekp(mid);
    f.put(static_cast<char>(b ^ 0x10));
  }
  r = run_cli({"work", "--db", "c.db", "--quiet"}, d.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(
      sql_int(db,
              "SELECT count(*) FROM attempts WHERE kind='drop' AND error LIKE 'bed checksum mismatch: % of bed job %'"),
      1);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE kind='bed' AND outcome='done'"), 2) << "rebuilt once";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 3);
  // Every drop used the rebuilt bed, whose file matches its new checksum.
  const fs::path rebuilt = campaign_file(d.path, "c", sql_text(db, "SELECT output_path FROM jobs WHERE kind='bed'"));
  EXPECT_NE(rebuilt, bed);
  EXPECT_EQ(queue::sha256_file(rebuilt), sql_text(db, "SELECT output_sha256 FROM jobs WHERE kind='bed'"));
  r = run_cli({"status", "--db", "c.db"}, d.path);
  EXPECT_NE(r.out.find("beds rebuilt after a checksum mismatch"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bed checksum mismatch"), std::string::npos) << r.out;
}
