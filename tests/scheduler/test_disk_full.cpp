// A worker that fills the disk exits 1 with "database or disk is full", not with a segfault in
// HDF5's exit handler, and what it finished stays intact. Runs in a 1 MB
// tmpfs when this process may mount one (root in a permissive container); skipped with the
// reason otherwise.
#include <gtest/gtest.h>
#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>
#include <nlohmann/json.hpp>

#include "db/database.h"
#include "scheduler/pipeline/impact_runners.h"
#include "scheduler/queue/canonical.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
namespace fs = std::filesystem;

/// A tmpfs of `size` (mount's notation: 1m, 256k) mounted at dir/small for the test's life;
/// `mounted` is false, with the reason, where this process may not mount one.
struct SmallTmpfs {
  fs::path path;
  bool mounted = false;
  std::string why;
  SmallTmpfs(const fs::path& dir, const std::string& size) : path(dir / "small") {
    fs::create_directories(path);
    mounted = ::mount("tmpfs", path.c_str(), "tmpfs", 0, ("size=" + size).c_str()) == 0;
    if (!mounted) why = std::strerror(errno);
  }
  ~SmallTmpfs() {
    if (mounted) ::umount2(path.c_str(), MNT_DETACH);
  }
  SmallTmpfs(const SmallTmpfs&) = delete;
  SmallTmpfs& operator=(const SmallTmpfs&) = delete;
};

#define SKIP_WITHOUT(tmpfs)                                          \
  if (!(tmpfs).mounted)                                              \
  GTEST_SKIP() << "cannot mount a small tmpfs here (" << (tmpfs).why \
               << "): needs root and CAP_SYS_ADMIN; the disk-full case is not tested"

/// Submits five no-op jobs (one attempt each) to c.db in `dir` with their files root `root` on the
/// small disk `mnt`, makes the root's folders, then fills `mnt` (file mnt/fill) to the last block.
void submit_five_noops_and_fill_the_disk(const fs::path& dir, const fs::path& mnt, const std::string& root) {
  nlohmann::json doc = {{"sweep", "full"},
                        {"job", "noop"},
                        {"max_attempts", 1},
                        {"base", {{"g", 1.0}}},
                        {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {1, 2, 3, 4, 5}}}}}};
  write_text(dir / "spec.json", doc.dump());
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db", "--files", root}, dir).code, 0);
  for (const char* sub : {"noop", "tmp", "beds", "traces"}) fs::create_directories(fs::path(root) / sub);
  std::ofstream fill(mnt / "fill", std::ios::binary);
  const std::string block(4096, 'x');
  while (fill.write(block.data(), static_cast<std::streamsize>(block.size())) && fill.flush()) {
  }
}

TEST(DiskFull, WorkerExitsOneCleanlyAndFinishedWorkStaysIntact) {
  TempDir d;
  const SmallTmpfs tmpfs(d.path, "1m");
  SKIP_WITHOUT(tmpfs);
  const fs::path& mnt = tmpfs.path;
  const std::string example = std::string(GRAVSWEEP_SOURCE_DIR) + "/examples/sweep_tiny.json";
  ASSERT_EQ(run_cli({"submit", example, "--db", "c.db"}, mnt).code, 0);
  // stderr is captured outside the tmpfs: on the full disk the message itself could not be written.
  // --min-free-mb 0: the worker runs jobs until the disk fills under them (the free-space check
  // would stop it before the first).
  const auto r = run_cli({"work", "--db", "c.db", "--threads", "1", "--min-free-mb", "0", "--quiet"}, mnt, d.path);
  EXPECT_EQ(r.code, 1) << "exit " << r.code << ": " << r.err.substr(r.err.size() > 800 ? r.err.size() - 800 : 0);
  EXPECT_TRUE(r.err.find("disk is full") != std::string::npos || r.err.find("No space left") != std::string::npos)
      << r.err.substr(r.err.size() > 800 ? r.err.size() - 800 : 0);
  db::Database db((mnt / "c.db").string());
  int done = 0;
  db::Statement st(db, "SELECT output_path, output_sha256 FROM jobs WHERE state='done'");
  while (st.step()) {
    const fs::path p = campaign_file(mnt, "c", st.get_text(0));
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_EQ(queue::sha256_file(p), st.get_text(1)) << p;
    ++done;
  }
  std::printf("disk full after %d finished job(s): exit %d\n", done, r.code);
}

// A noop job whose output cannot be written (the files root's disk is full) fails its attempt with
// the errno's text; it is never recorded done with an empty output.
TEST(DiskFull, ANoopJobOnAFullFilesRootFailsWithTheErrno) {
  TempDir d;
  const SmallTmpfs tmpfs(d.path, "256k");
  SKIP_WITHOUT(tmpfs);
  const std::string root = (tmpfs.path / "files").string();
  ASSERT_NO_FATAL_FAILURE(submit_five_noops_and_fill_the_disk(d.path, tmpfs.path, root));
  // --min-free-mb 0: the worker claims on the full disk (the free-space check would stop it first).
  const auto r = run_cli({"work", "--db", "c.db", "--files", root, "--min-free-mb", "0", "--quiet"}, d.path);
  EXPECT_NE(r.code, 0) << r.err;
  db::Database db((d.path / "c.db").string());
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 0) << "done with an empty output";
  EXPECT_GE(sql_int(db, "SELECT count(*) FROM attempts WHERE error LIKE '%No space left on device%'"), 1)
      << sql_text(db, "SELECT error FROM attempts LIMIT 1");
}

// A full files root burns no retry budget: the worker checks the free space before it claims (and
// stops, exit 1, naming the root and the bytes free); an attempt that fails on the full disk goes
// back to the queue uncounted; with space again every job finishes.
TEST(DiskFull, AFullFilesRootStopsClaimingAndCountsNothingAgainstTheJobs) {
  TempDir d;
  const SmallTmpfs tmpfs(d.path, "256k");
  SKIP_WITHOUT(tmpfs);
  const std::string root = (tmpfs.path / "files").string();
  ASSERT_NO_FATAL_FAILURE(submit_five_noops_and_fill_the_disk(d.path, tmpfs.path, root));
  db::Database db((d.path / "c.db").string());
  auto r = run_cli({"work", "--db", "c.db", "--files", root, "--quiet"}, d.path);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("disk is full"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(root), std::string::npos) << r.err;
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts"), 0) << "nothing may start on a full disk";
  r = run_cli({"work", "--db", "c.db", "--files", root, "--min-free-mb", "0", "--quiet"}, d.path);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='released' AND error LIKE '%No space left%'"), 1);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='queued' AND attempts=0 AND releases=0"), 5)
      << "an environmental failure counts against no job";
  fs::remove(tmpfs.path / "fill");
  r = run_cli({"work", "--db", "c.db", "--files", root, "--min-free-mb", "0", "--quiet"}, d.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 5);
}

// A checkpoint that cannot be written on a full disk is a warning and the job goes on; the worker
// and a supervisor of two then exit 0 with every job done and its output intact. (HDF5 1.10 kept a
// file whose flush had failed and crashed on it in its exit handler: exit 139, and 1 from the
// supervisor, although every job was done. Files are now built in memory and written by us.)
TEST(DiskFull, ACheckpointThatCannotBeWrittenLeavesTheWorkerAndItsSupervisorExitingZero) {
  std::ifstream tiny(std::string(GRAVSWEEP_SOURCE_DIR) + "/examples/sweep_tiny.json");
  auto spec = nlohmann::json::parse(tiny);
  spec.erase("$schema");
  spec["axes"] = {{{"name", "impact_speed_m_s"}, {"pointer", "/projectile/impact_speed_m_s"}, {"values", {1.0}}}};
  spec["repeats"]["count"] = 1;  // one bed job and one drop
  for (const int workers : {1, 2}) {
    SCOPED_TRACE("--workers " + std::to_string(workers));
    TempDir d;
    // 1.3 MB: the bed (190 kB) and the trace (140 kB) fit, a checkpoint (1 MB) beside them does not.
    const SmallTmpfs tmpfs(d.path, "1300k");
    SKIP_WITHOUT(tmpfs);
    const fs::path& mnt = tmpfs.path;
    write_text(d.path / "one.json", spec.dump());
    const std::string root = (mnt / "files").string();
    ASSERT_EQ(run_cli({"submit", "one.json", "--db", "c.db", "--files", root}, d.path).code, 0);
    const auto r = run_cli({"work", "--db", "c.db", "--files", root, "--workers", std::to_string(workers), "--threads",
                            "1", "--min-free-mb", "0", "--checkpoint-interval", "0.2", "--quiet"},
                           d.path);
    EXPECT_EQ(r.code, 0) << r.err.substr(r.err.size() > 800 ? r.err.size() - 800 : 0);
    EXPECT_NE(r.err.find("not written (the drop goes on)"), std::string::npos) << "no checkpoint met the full disk";
    EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << "the warning names the errno";
    db::Database db((d.path / "c.db").string());
    EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 2);
    db::Statement st(db, "SELECT output_path, output_sha256 FROM jobs WHERE state='done'");
    while (st.step()) {
      const fs::path stored(st.get_text(0));
      const fs::path p = stored.is_absolute() ? stored : fs::path(root) / stored;
      ASSERT_TRUE(fs::exists(p)) << p;
      EXPECT_EQ(queue::sha256_file(p), st.get_text(1)) << p;
    }
  }
}
