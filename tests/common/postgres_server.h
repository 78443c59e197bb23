// A throwaway PostgreSQL server for tests (docs/queue.md section 7.1): initdb in a
// temporary folder, pg_ctl start on 127.0.0.1 with its own port and socket folder, stopped and
// removed when the test process ends. Started once per test process, on first use; each test
// gets a new database of its own. As root, the server runs as the `postgres` user (initdb
// refuses root). When the server binaries are absent or the server cannot start, `shared()`
// returns nullptr and says why, for GTEST_SKIP() to print: a skip is never silent.
#pragma once
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>

#include "db/database.h"
#include "tests/common/started_once.h"

namespace gravsweep::test {

class PostgresServer {
 public:
  /// The server of this test process (started on the first call); nullptr with `why` filled in
  /// when it cannot run here.
  static PostgresServer* shared(std::string& why) {
    return started_once(
        why, [] { return std::unique_ptr<PostgresServer>(new PostgresServer); }, &PostgresServer::start);
  }

  /// Creates an empty database and returns its URL (postgresql://postgres@127.0.0.1:PORT/NAME).
  std::string create_database() {
    static std::atomic<int> n{0};
    const std::string name = "t" + std::to_string(::getpid()) + "_" + std::to_string(n++);
    db::Database admin(url("postgres"));
    admin.exec("CREATE DATABASE " + name);
    return url(name);
  }
  [[nodiscard]] std::string url(const std::string& dbname) const {
    return "postgresql://postgres@127.0.0.1:" + std::to_string(port_) + "/" + dbname;
  }
  [[nodiscard]] int port() const { return port_; }

  /// Restarts the server (`pg_ctl restart -m fast|immediate`, the same port and options): every
  /// open connection breaks. 0 on success.
  int restart(const std::string& mode) { return run(pg_ctl() + " -D " + data() + " -m " + mode + " -w -t 60 restart"); }
  /// Stops the server (until start_again); 0 on success.
  int stop(const std::string& mode) { return run(pg_ctl() + " -D " + data() + " -m " + mode + " -w -t 60 stop"); }
  /// Starts the stopped server again with its options; 0 on success.
  int start_again() {
    return run(pg_ctl() + " -D " + data() + " -o \"" + opts_ + "\" -l " + (dir_ / "server.log").string() +
               " -w -t 60 start");
  }

  ~PostgresServer() {
    if (started_) (void)run(pg_ctl() + " -D " + data() + " -m immediate -w stop");
    std::error_code ec;
    if (!dir_.empty()) std::filesystem::remove_all(dir_, ec);
  }
  PostgresServer(const PostgresServer&) = delete;
  PostgresServer& operator=(const PostgresServer&) = delete;

 private:
  PostgresServer() = default;
  std::filesystem::path bin_, dir_;
  int port_ = 0;
  bool started_ = false;
  std::string opts_;  ///< the server's options (port, socket folder, ...), for start_again

  [[nodiscard]] std::string data() const { return (dir_ / "data").string(); }
  [[nodiscard]] std::string pg_ctl() const { return (bin_ / "pg_ctl").string(); }
  /// Runs a shell command as the server's user; its exit status.
  [[nodiscard]] int run(const std::string& cmd) const {
    const std::string full = ::geteuid() == 0 ? "runuser -u postgres -- sh -c '" + cmd + "'" : cmd;
    return std::system((full + " >>" + (dir_ / "setup.log").string() + " 2>&1").c_str());
  }
  [[nodiscard]] std::string log_tail() const {
    std::ifstream f(dir_ / "setup.log");
    std::stringstream s;
    s << f.rdbuf();
    std::string t = s.str();
    return t.size() > 600 ? t.substr(t.size() - 600) : t;
  }

  /// "" when the server runs; otherwise why not.
  std::string start() {
    namespace fs = std::filesystem;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator("/usr/lib/postgresql", ec))
      if (fs::exists(e.path() / "bin" / "initdb") && fs::exists(e.path() / "bin" / "pg_ctl")) bin_ = e.path() / "bin";
    if (bin_.empty())
      return "PostgreSQL server binaries not found (/usr/lib/postgresql/*/bin/initdb, pg_ctl): install the Debian "
             "package `postgresql` to run the PostgreSQL tests";
    if (::geteuid() == 0 && std::system("id postgres >/dev/null 2>&1") != 0)
      return "running as root but there is no `postgres` user to run the server as (initdb refuses root)";
    std::random_device rd;
    dir_ = fs::temp_directory_path() / ("gravsweep-pg-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    fs::create_directories(dir_);
    if (::geteuid() == 0 && std::system(("chown postgres " + dir_.string()).c_str()) != 0)
      return "cannot chown the server's folder " + dir_.string() + " to postgres";
    if (run(bin_.string() + "/initdb -D " + data() + " -A trust -U postgres") != 0)
      return "initdb failed: " + log_tail();
    for (int tries = 0; tries < 5 && !started_; ++tries) {
      port_ = 20000 + static_cast<int>(rd() % 30000);
      opts_ = "-k " + dir_.string() + " -p " + std::to_string(port_) +
              " -c listen_addresses=127.0.0.1 -c fsync=off -c max_connections=200";
      started_ = start_again() == 0;
    }
    if (!started_) {
      std::ifstream f(dir_ / "server.log");
      std::stringstream s;
      s << f.rdbuf();
      return "pg_ctl start failed on 127.0.0.1 (5 ports tried): " + s.str().substr(0, 600);
    }
    return "";
  }
};

}  // namespace gravsweep::test
