// Helpers of the `gravsweep serve` tests: a small campaign of real jobs (no-op jobs that take a
// moment, one that dies, a bed and its drops), and the serve process on a free port.
#pragma once
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "scheduler_test_helpers.h"

namespace gravsweep::test {

/// Writes and submits to `<dir>/c.db`: `noops` no-op jobs of `sleep_s` each at gravity levels 1..n,
/// one no-op job that always fails (dead after one attempt), and a drop sweep of the tiny scenario
/// (one bed) at the impact speeds `speeds` and gravity levels `gs`. Returns false on failure.
inline bool make_serve_campaign(const std::filesystem::path& dir, int noops, double sleep_s,
                                const std::vector<double>& speeds, const std::vector<double>& gs = {9.81}) {
  using nlohmann::json;
  std::vector<double> levels;
  for (int i = 1; i <= noops; ++i) levels.push_back(i);
  const json wait = {{"sweep", "wait"},
                     {"job", "noop"},
                     {"base", {{"g", 1.0}, {"sleep_s", sleep_s}}},
                     {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", levels}}}}};
  const json dies = {{"sweep", "dies"},
                     {"job", "noop"},
                     {"max_attempts", 1},
                     {"base", {{"g", 7.0}, {"fail_attempts", 99}}},
                     {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {7.0}}}}}};
  const json drops = {
      {"sweep", "drops"},
      {"base", json::parse(tiny_base())},
      {"axes",
       {{{"name", "gravity_m_s2"}, {"pointer", "/gravity_m_s2"}, {"values", gs}},
        {{"name", "impact_speed_m_s"}, {"pointer", "/projectile/impact_speed_m_s"}, {"values", speeds}}}}};
  write_text(dir / "wait.json", wait.dump());
  write_text(dir / "dies.json", dies.dump());
  write_text(dir / "drops.json", drops.dump());
  const auto r = run_cli({"submit", "wait.json", "dies.json", "drops.json", "--db", "c.db"}, dir);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  return r.code == 0;
}

inline std::string read_file(const std::filesystem::path& p) {
  std::stringstream s;
  s << std::ifstream(p).rdbuf();
  return s.str();
}

/// `gravsweep serve` on a free port (--port 0), stopped (SIGTERM) at the end of the scope.
struct ServeProcess {
  pid_t pid = -1;
  int port = 0;
  std::string url;
  std::filesystem::path log;

  /// On `db_args` (--db LOCATION [--files DIR]; default `<dir>/c.db`), its output in `<dir>/serve.log`.
  explicit ServeProcess(const std::filesystem::path& dir, std::vector<std::string> db_args = {})
      : log(dir / "serve.log") {
    if (db_args.empty()) db_args = {"--db", (dir / "c.db").string()};
    std::vector<std::string> args{"serve", "--port", "0"};
    args.insert(args.end(), db_args.begin(), db_args.end());
    pid = start_cli(args, log);
    const std::regex re(R"(http://127\.0\.0\.1:(\d+)/)");
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < end) {
      std::smatch m;
      const std::string text = read_file(log);
      if (std::regex_search(text, m, re)) {
        port = std::stoi(m[1]);
        url = m[0];
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ADD_FAILURE() << "serve printed no URL within 30 s: " << read_file(log);
  }
  /// Stops the server; its exit code.
  int stop() {
    if (pid <= 0) return -1;
    kill(pid, SIGTERM);
    const int code = wait_child(pid, 20);
    pid = -1;
    return code;
  }
  ~ServeProcess() { stop(); }
  ServeProcess(const ServeProcess&) = delete;
  ServeProcess& operator=(const ServeProcess&) = delete;
};

}  // namespace gravsweep::test
