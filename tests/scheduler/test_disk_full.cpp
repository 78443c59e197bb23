// A worker that fills the disk exits 1 with "database or disk is full", not with a segfault in
// HDF5's exit handler (issue #10 item 7), and what it finished stays intact. Runs in a 1 MB
// tmpfs when this process may mount one (root in a permissive container); skipped with the
// reason otherwise.
#include <gtest/gtest.h>
#include <sys/mount.h>

#include <cerrno>
#include <cstring>

#include "db/database.h"
#include "scheduler/queue/impact.h"
#include "scheduler/sweep/canonical.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
namespace fs = std::filesystem;

TEST(DiskFull, WorkerExitsOneCleanlyAndFinishedWorkStaysIntact) {
  TempDir d;
  const fs::path mnt = d.path / "small";
  fs::create_directories(mnt);
  if (::mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=1m") != 0)
    GTEST_SKIP() << "cannot mount a 1 MB tmpfs here (" << std::strerror(errno)
                 << "): needs root and CAP_SYS_ADMIN; the disk-full case is not tested";
  struct Unmount {
    fs::path p;
    ~Unmount() { ::umount2(p.c_str(), MNT_DETACH); }
  } unmount{mnt};
  const std::string example = std::string(GRAVSWEEP_SOURCE_DIR) + "/examples/sweep_tiny.json";
  ASSERT_EQ(run_cli({"submit", example, "--db", "c.db"}, mnt).code, 0);
  // stderr is captured outside the tmpfs: on the full disk the message itself could not be written.
  const auto r = run_cli({"work", "--db", "c.db", "--threads", "1", "--quiet"}, mnt, d.path);
  EXPECT_EQ(r.code, 1) << "exit " << r.code << ": " << r.err.substr(r.err.size() > 800 ? r.err.size() - 800 : 0);
  EXPECT_TRUE(r.err.find("disk is full") != std::string::npos || r.err.find("No space left") != std::string::npos)
      << r.err.substr(r.err.size() > 800 ? r.err.size() - 800 : 0);
  db::Database db((mnt / "c.db").string());
  int done = 0;
  db::Statement st(db, "SELECT output_path, output_sha256 FROM jobs WHERE state='done'");
  while (st.step()) {
    const fs::path p = campaign_file(mnt, "c", st.get_text(0));
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_EQ(sweep::sha256_file(p), st.get_text(1)) << p;
    ++done;
  }
  std::printf("disk full after %d finished job(s): exit %d\n", done, r.code);
}
