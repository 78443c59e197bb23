// Helpers of the scheduler tests: temporary folders, running the gravsweep binary, SQL counts.
#pragma once
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "db/database.h"
#include "tests/common/temp_dir.h"       // TempDir
#include "tests/common/tiny_campaign.h"  // tiny_base

namespace gravsweep::test {

inline void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream f(p);
  f << text;
}

struct CmdResult {
  int code = -1;
  std::string out, err;
};

/// Runs the gravsweep binary with args; captures stdout and stderr (through files in
/// capture_dir, by default workdir: a test that fills workdir's disk must capture elsewhere).
inline CmdResult run_cli(const std::vector<std::string>& args, const std::filesystem::path& workdir,
                         const std::filesystem::path& capture_dir = {}) {
  const auto& cap = capture_dir.empty() ? workdir : capture_dir;
  const auto out_path = cap / ".cli_out", err_path = cap / ".cli_err";
  const pid_t pid = fork();
  if (pid == 0) {
    const int o = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(o, 1);
    dup2(e, 2);
    if (chdir(workdir.c_str()) != 0) _exit(126);
    std::vector<char*> argv{const_cast<char*>(GRAVSWEEP_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(GRAVSWEEP_BINARY, argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  CmdResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::stringstream a, b;
  a << std::ifstream(out_path).rdbuf();
  b << std::ifstream(err_path).rdbuf();
  r.out = a.str();
  r.err = b.str();
  return r;
}

/// Starts the gravsweep binary in the background (output to `log`); returns its pid.
inline pid_t start_cli(const std::vector<std::string>& args, const std::filesystem::path& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int o = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    dup2(o, 1);
    dup2(o, 2);
    std::vector<char*> argv{const_cast<char*>(GRAVSWEEP_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(GRAVSWEEP_BINARY, argv.data());
    _exit(127);
  }
  return pid;
}

/// Waits for a child with a deadline; returns its exit code, or -1 on timeout (child killed).
inline int wait_child(pid_t pid, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  for (;;) {
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (std::chrono::steady_clock::now() > end) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

/// The file of a path stored in campaign `stem` of `dir`: relative to `<stem>.files/` (older
/// campaigns stored `<stem>.files/...`, relative to the database's folder).
inline std::filesystem::path campaign_file(const std::filesystem::path& dir, const std::string& stem,
                                           const std::string& stored) {
  const std::filesystem::path p(stored);
  if (p.is_absolute()) return p;
  const std::string first = p.begin()->string();
  if (first.size() > 6 && first.compare(first.size() - 6, 6, ".files") == 0) return dir / p;
  return dir / (stem + ".files") / p;
}

inline std::int64_t sql_int(db::Database& db, const std::string& sql) {
  db::Statement st(db, sql);
  st.step();
  return st.get_int(0);
}

inline std::string sql_text(db::Database& db, const std::string& sql) {
  db::Statement st(db, sql);
  if (!st.step()) return {};
  return st.get_text(0);
}

/// The smallest sweep spec (JSON text): sweep "s" of two no-op jobs, i = 1 and 2, for the tests
/// that need a campaign to exist rather than any work in it.
inline std::string two_noop_jobs_spec() {
  return R"({"sweep": "s", "job": "noop", "base": {"i": 0},
             "axes": [{"name": "i", "pointer": "/i", "values": [1, 2]}]})";
}

}  // namespace gravsweep::test
