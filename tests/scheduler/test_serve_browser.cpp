// The page of `gravsweep serve` in a real browser: Debian's chromium, headless, driven by
// playwright-core from npm (deploy/node/, installed by deploy/install-deps.sh) through
// serve_page_check.js. The page loads, its done count changes while a worker finishes jobs, a
// click on a drop draws its trace, the Froude collapse is drawn and the model's verdict appears. Skipped, saying why,
// only without chromium or node; a missing playwright-core is a failure that names the command that installs it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>

#include "serve_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
namespace fs = std::filesystem;

namespace {

std::string chromium_path() {
  const char* env = std::getenv("CHROMIUM");
  return env ? env : "/usr/bin/chromium";
}

bool have_node() { return std::system("command -v node >/dev/null 2>&1") == 0; }

/// `node serve_page_check.js args...` in the background, stdout and stderr to files in `dir`.
pid_t start_page_check(const std::vector<std::string>& args, const fs::path& dir) {
  std::string cmd = "exec node '" GRAVSWEEP_SOURCE_DIR "/tests/scheduler/serve_page_check.js'";
  for (const auto& a : args) cmd += " '" + a + "'";
  cmd += " >'" + (dir / "page.out").string() + "' 2>'" + (dir / "page.err").string() + "'";
  const pid_t pid = fork();
  if (pid == 0) {
    setenv("NODE_PATH", GRAVSWEEP_SOURCE_DIR "/deploy/node/node_modules", 1);
    setenv("CHROMIUM", chromium_path().c_str(), 1);
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

/// Where the screenshot goes: the build's test folder; docs/serve.png when
/// GRAVSWEEP_UPDATE_SCREENSHOT=1 (kept out of ordinary runs: a test must not change tracked files).
fs::path screenshot_path() {
  const char* update = std::getenv("GRAVSWEEP_UPDATE_SCREENSHOT");
  if (update && std::string(update) == "1") return fs::path(GRAVSWEEP_SOURCE_DIR) / "docs" / "serve.png";
  return fs::current_path() / "serve.png";
}

}  // namespace

TEST(ServeBrowser, ThePageFollowsAWorkerAndDrawsADropOnAClick) {
  if (!fs::exists(chromium_path())) GTEST_SKIP() << "chromium not installed (apt-get install chromium)";
  if (!have_node()) GTEST_SKIP() << "node not installed (deploy/install-deps.sh installs nodejs and npm)";
  ASSERT_TRUE(fs::exists(GRAVSWEEP_SOURCE_DIR "/deploy/node/node_modules/playwright-core"))
      << "playwright-core missing: run deploy/install-deps.sh (npm ci in deploy/node)";
  TempDir d;
  // Six no-op jobs of a second each first, then two beds and six drops at two gravity levels (the
  // fewest `model rank` gives a verdict on).
  ASSERT_TRUE(make_serve_campaign(d.path, 6, 1.0, {0.4, 0.5, 0.6}, {9.81, 3.71}));
  std::string drop;
  {
    db::Database db((d.path / "c.db").string());
    drop = sql_text(db, "SELECT job_id FROM jobs WHERE kind='drop' ORDER BY seq LIMIT 1");
  }
  ServeProcess serve(d.path);
  ASSERT_GT(serve.port, 0);
  const fs::path shot = screenshot_path(), ready = d.path / "ready";
  const pid_t page = start_page_check({serve.url, shot.string(), ready.string(), drop}, d.path);
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!fs::exists(ready) && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(fs::exists(ready)) << "the page showed no counts within 120 s\n"
                                 << read_file(d.path / "page.err") << read_file(serve.log);
  const pid_t w =
      start_cli({"work", "--db", (d.path / "c.db").string(), "--threads", "1", "--poll", "0.05"}, d.path / "w.log");
  const int page_code = wait_child(page, 900);
  const int work_code = wait_child(w, 600);
  EXPECT_EQ(page_code, 0) << read_file(d.path / "page.err") << read_file(d.path / "page.out");
  EXPECT_EQ(work_code, 4) << "a dead job: work exits 4\n" << read_file(d.path / "w.log");
  const auto seen = nlohmann::json::parse(read_file(d.path / "page.out"), nullptr, false);
  ASSERT_TRUE(seen.is_object()) << read_file(d.path / "page.out");
  EXPECT_GT(seen.at("later").get<int>(), seen.at("first").get<int>()) << seen.dump();
  EXPECT_GT(seen.at("traceInk").get<int>(), 500) << seen.dump();
  EXPECT_GT(seen.at("collapseInk").get<int>(), 500) << seen.dump();
  EXPECT_GE(seen.at("collapseDrops").get<int>(), 1) << seen.dump();
  EXPECT_EQ(seen.at("verdict").get<std::string>().rfind("Verdict: ", 0), 0u) << seen.dump();
  EXPECT_GT(seen.at("verdict").get<std::string>().size(), 20u) << seen.dump();
  EXPECT_GT(seen.at("rankRows").get<int>(), 0) << seen.dump();
  EXPECT_EQ(seen.at("levelRows").get<int>(), 6 + 1 + 2 + 2) << seen.dump();  // waits, dies, beds, drops
  EXPECT_TRUE(seen.at("errors").empty()) << seen.dump();
  EXPECT_GT(fs::file_size(shot), 10000u) << shot;
  std::printf("page seen: %s; screenshot %s\n", seen.dump().c_str(), shot.c_str());
}
