// Checkpoints of a campaign's drop through real worker processes (`gravsweep work`,
// scheduler/pipeline/job_checkpoint.h): a worker stopped by SIGTERM mid-drop writes the drop's
// checkpoint, gives its lease back and says so in the attempts table; a worker killed by SIGKILL
// leaves the last periodic checkpoint, which `status` names while the drop runs (and perhaps the
// temporary of a write it never finished); either way the next worker continues the drop and
// records the trace of an uninterrupted campaign, value for value, and removes the checkpoint
// and any temporary of it.
#include <gtest/gtest.h>

#include <csignal>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scheduler_test_helpers.h"
#include "tests/common/same_trace.h"

using namespace gravsweep;
using namespace gravsweep::test;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

/// One bed and one long drop of the tiny scenario: 2 s of simulated time at 1 m/s2 (about 4 s of
/// wall time), run to the time cap (the hold time is longer), long enough to be caught mid-drop.
std::string one_drop_spec() {
  json base = json::parse(tiny_base());
  base["stop"]["max_time_s"] = 2.0;
  // The test bed, relaxed briefly at 1 m/s2, is not at rest for a 0.5 m/s impact; this test is
  // about the checkpoints, not the bed.
  base["at_rest"] = {{"surface_speed_fraction", 1.0}, {"rms_speed_fraction", 1.0}};
  base["stop"]["hold_time_s"] = 10.0;
  json spec;
  spec["sweep"] = "ckpt";
  spec["base"] = base;
  spec["axes"] = json::array({{{"name", "gravity_m_s2"}, {"pointer", "/gravity_m_s2"}, {"values", {1.0}}}});
  return spec.dump(2);
}

/// Submits the spec into `<dir>/<name>.db`.
void submit(const fs::path& dir, const std::string& name) {
  write_text(dir / "spec.json", one_drop_spec());
  const CmdResult r = run_cli({"submit", "spec.json", "--db", name + ".db"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
}

/// A worker of campaign `<dir>/<name>.db` (absolute: start_cli runs in the test's folder).
std::vector<std::string> work_args(const fs::path& dir, const std::string& name, const std::string& interval_s) {
  return {"work",      "--db", (dir / (name + ".db")).string(), "--threads", "1", "--lease", "2",
          "--backoff", "0",    "--checkpoint-interval",         interval_s};
}

/// Waits until the drop job's progress detail (what `status` shows) contains `text`; false after
/// `timeout_s`.
bool wait_for_detail(const fs::path& db_path, const std::string& text, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    try {
      db::Database db(db_path.string());
      if (sql_text(db, "SELECT coalesce(detail,'') FROM jobs WHERE kind='drop' AND state='running'").find(text) !=
          std::string::npos)
        return true;
    } catch (const std::exception&) {  // busy: ask again
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

fs::path trace_of(const fs::path& dir, const std::string& name) {
  db::Database db((dir / (name + ".db")).string());
  return campaign_file(dir, name, sql_text(db, "SELECT trace_path FROM results WHERE kind='drop'"));
}

class CampaignCheckpoint : public ::testing::Test {
 protected:
  TempDir d_;
  void SetUp() override {
    ASSERT_NO_FATAL_FAILURE(submit(d_.path, "ref"));
    const CmdResult r = run_cli(work_args(d_.path, "ref", "0"), d_.path);
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_NO_FATAL_FAILURE(submit(d_.path, "c"));
  }
  fs::path checkpoints() const { return d_.path / "c.files" / "checkpoints"; }
  /// Runs a worker to the end and checks what the resumed campaign recorded.
  void finish_and_compare() {
    const CmdResult r = run_cli(work_args(d_.path, "c", "300"), d_.path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("discarded"), std::string::npos) << r.err;
    db::Database db((d_.path / "c.db").string());
    EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 2);
    EXPECT_EQ(sql_int(db, "SELECT checkpoint_resumes FROM results WHERE kind='drop'"), 1);
    EXPECT_TRUE(fs::is_empty(checkpoints())) << "the checkpoint outlived the recorded drop";
    EXPECT_NO_FATAL_FAILURE(expect_same_trace_columns(trace_of(d_.path, "ref"), trace_of(d_.path, "c")));
  }
};

}  // namespace

TEST_F(CampaignCheckpoint, SigtermCheckpointsAndTheNextWorkerContinues) {
  // --max-releases 1: a release that saved no progress would stop the drop; this one saved its
  // checkpoint, so the drop stays queued.
  std::vector<std::string> args = work_args(d_.path, "c", "300");
  args.insert(args.end(), {"--max-releases", "1"});
  const pid_t w = start_cli(args, d_.path / "w1.log");
  ASSERT_TRUE(wait_for_detail(d_.path / "c.db", "depth=", 60)) << "the drop never started";
  std::this_thread::sleep_for(std::chrono::milliseconds(700));  // well inside the drop
  kill(w, SIGTERM);
  ASSERT_EQ(wait_child(w, 60), 130);
  ASSERT_EQ(std::distance(fs::directory_iterator(checkpoints()), fs::directory_iterator()), 1);
  {
    db::Database db((d_.path / "c.db").string());
    const std::string why = sql_text(db, "SELECT coalesce(error,'') FROM attempts WHERE outcome='released'");
    EXPECT_NE(why.find("checkpoint"), std::string::npos) << "the attempts table says where it stopped: " << why;
    EXPECT_EQ(sql_text(db, "SELECT state FROM jobs WHERE kind='drop'"), "queued");
    EXPECT_EQ(sql_int(db, "SELECT stalled_releases FROM jobs WHERE kind='drop'"), 0);
  }
  EXPECT_NO_FATAL_FAILURE(finish_and_compare());
}

TEST_F(CampaignCheckpoint, SigkillLosesAtMostOneIntervalAndStatusNamesTheCheckpoint) {
  const pid_t w = start_cli(work_args(d_.path, "c", "0.3"), d_.path / "w1.log");
  ASSERT_TRUE(wait_for_detail(d_.path / "c.db", "ckpt t=", 60)) << "no checkpoint shown in the progress detail";
  const CmdResult status = run_cli({"status", "--db", "c.db"}, d_.path);
  EXPECT_NE(status.out.find("ckpt t="), std::string::npos) << status.out;
  kill(w, SIGKILL);
  wait_child(w, 10);
  // One checkpoint; the kill may also have caught a write of the next one half done (its
  // temporary): the next worker removes it. One is planted so that this is always tested.
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(checkpoints()))
    if (e.path().filename().string().find(".tmp") == std::string::npos) files.push_back(e.path());
  ASSERT_EQ(files.size(), 1u);
  write_text(fs::path(files[0].string() + ".tmp999999"), "half a checkpoint");
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));  // the lease (2 s) lapses
  EXPECT_NO_FATAL_FAILURE(finish_and_compare());
}
