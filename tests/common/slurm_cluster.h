// A throwaway single-node Slurm cluster for tests (docs/queue.md section 7.2): its own
// munged (own key and socket, so a system munge is never touched), slurmctld and slurmd on
// random ports with their state, spool and logs in a temporary folder, one node of this
// machine's CPUs and one partition `debug`. Started once per test process, on first use; the
// process's SLURM_CONF then names it, so sbatch, squeue and scancel (and `gravsweep slurm`) talk
// to it. Stopped and removed when the test process ends, after cancelling its jobs. When the
// packages are absent or a daemon cannot start, `shared()` returns nullptr and says why (with the
// daemon's log), for GTEST_SKIP() to print: a skip is never silent.
#pragma once
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/common/started_once.h"

namespace gravsweep::test {

class SlurmCluster {
 public:
  /// The cluster of this test process (started on the first call); nullptr with `why` filled in
  /// when it cannot run here.
  static SlurmCluster* shared(std::string& why) {
    return started_once(
        why, [] { return std::unique_ptr<SlurmCluster>(new SlurmCluster); }, &SlurmCluster::start);
  }

  /// Runs a Slurm client command (SLURM_CONF is set) and returns its stdout; `rc` gets its status.
  std::string client(const std::string& cmd, int* rc = nullptr) const {
    std::string out;
    std::FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
    if (!p) return out;
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    const int status = ::pclose(p);
    if (rc) *rc = status;
    return out;
  }
  /// Ids of the jobs the cluster knows (pending or running), one per array task ("12_1").
  [[nodiscard]] std::vector<std::string> jobs() const {
    std::istringstream in(client("squeue -h -r -o %i"));
    std::vector<std::string> ids;
    for (std::string line; std::getline(in, line);)
      if (!line.empty()) ids.push_back(line);
    return ids;
  }
  /// Waits until no job is left; false after `timeout_s`.
  bool wait_idle(double timeout_s) const {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (!jobs().empty()) {
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    return true;
  }
  [[nodiscard]] int cpus() const { return cpus_; }
  [[nodiscard]] std::string log_tail() const { return tail(dir_ / "log" / "ctld.log") + tail(dir_ / "log" / "d.log"); }

  ~SlurmCluster() {
    if (daemons_started_) {
      client("scancel --full -u $(id -un)");
      wait_idle(60);
    }
    for (const char* pid_file : {"slurmd.pid", "slurmctld.pid", "munged.pid"}) stop(dir_ / pid_file);
    std::error_code ec;
    if (!dir_.empty()) std::filesystem::remove_all(dir_, ec);
  }
  SlurmCluster(const SlurmCluster&) = delete;
  SlurmCluster& operator=(const SlurmCluster&) = delete;

 private:
  SlurmCluster() = default;
  std::filesystem::path dir_;
  int cpus_ = 1;
  bool daemons_started_ = false;

  static std::string tail(const std::filesystem::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    const std::string t = s.str();
    return t.size() > 500 ? "..." + t.substr(t.size() - 500) : t;
  }
  /// SIGTERM to the daemon of `pid_file` (one this cluster started), then waits up to 10 s.
  static void stop(const std::filesystem::path& pid_file) {
    std::ifstream f(pid_file);
    long pid = 0;
    if (!(f >> pid) || pid <= 1) return;
    if (::kill(static_cast<pid_t>(pid), SIGTERM) != 0) return;
    for (int i = 0; i < 100 && ::kill(static_cast<pid_t>(pid), 0) == 0; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  [[nodiscard]] int sh(const std::string& cmd) const {
    return std::system((cmd + " >>" + (dir_ / "setup.log").string() + " 2>&1").c_str());
  }
  [[nodiscard]] std::string conf_text(const std::string& host, int port) const {
    const std::string d = dir_.string();
    std::string c;
    c += "ClusterName=gravsweeptest\nSlurmctldHost=" + host + "\n";
    c += "SlurmctldPort=" + std::to_string(port) + "\nSlurmdPort=" + std::to_string(port + 1) + "\n";
    c += "AuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket=" + d + "/munge.sock\n";
    c += "MpiDefault=none\nProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n";
    c += "JobAcctGatherType=jobacct_gather/none\nSelectType=select/cons_tres\nSelectTypeParameters=CR_Core\n";
    c += "SlurmctldPidFile=" + d + "/slurmctld.pid\nSlurmdPidFile=" + d + "/slurmd.pid\n";
    c += "SlurmdSpoolDir=" + d + "/spool\nStateSaveLocation=" + d + "/state\n";
    c += "SlurmctldLogFile=" + d + "/log/ctld.log\nSlurmdLogFile=" + d + "/log/d.log\n";
    // scancel and the time limit: SIGTERM, then SIGKILL after KillWait (a worker needs far less).
    c += "SlurmUser=root\nReturnToService=2\nKillWait=10\nMinJobAge=2\n";
    c += "NodeName=" + host + " CPUs=" + std::to_string(cpus_) + " State=UNKNOWN\n";
    c += "PartitionName=debug Nodes=" + host + " Default=YES MaxTime=INFINITE State=UP\n";
    return c;
  }

  /// "" when the cluster is up (its node idle); otherwise why not.
  std::string start() {
    namespace fs = std::filesystem;
    for (const char* exe : {"munged", "slurmctld", "slurmd", "sbatch", "squeue", "scancel", "sinfo"})
      if (std::system(("command -v " + std::string(exe) + " >/dev/null 2>&1").c_str()) != 0)
        return std::string(exe) +
               " not found: install the Debian packages slurmctld slurmd slurm-client munge "
               "to run the Slurm tests";
    if (::geteuid() != 0)
      return "slurmd must run as root to start jobs; these tests run as uid " + std::to_string(::geteuid());
    std::random_device rd;
    dir_ = fs::temp_directory_path() / ("gravsweep-slurm-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    for (const char* sub : {"spool", "state", "log"}) fs::create_directories(dir_ / sub);
    fs::permissions(dir_, fs::perms::owner_all);
    {  // a key of its own: the tests never depend on, or disturb, the machine's munge
      std::ofstream key(dir_ / "munge.key", std::ios::binary);
      for (int i = 0; i < 256; ++i) key.put(static_cast<char>(rd() & 0xff));
    }
    fs::permissions(dir_ / "munge.key", fs::perms::owner_read);
    const std::string d = dir_.string();
    if (sh("munged --force --socket=" + d + "/munge.sock --key-file=" + d + "/munge.key --pid-file=" + d +
           "/munged.pid --log-file=" + d + "/log/munged.log --seed-file=" + d + "/munged.seed") != 0)
      return "munged did not start: " + tail(dir_ / "setup.log") + tail(dir_ / "log" / "munged.log");
    char host[256] = {0};
    ::gethostname(host, sizeof host - 1);
    std::string h(host);
    h = h.substr(0, h.find('.'));
    cpus_ = std::max(1u, std::thread::hardware_concurrency());
    const std::string conf = d + "/slurm.conf";
    ::setenv("SLURM_CONF", conf.c_str(), 1);  // for every client this process and its children run
    for (int tries = 0; tries < 3; ++tries) {
      std::ofstream(conf) << conf_text(h, 20000 + static_cast<int>(rd() % 30000));
      if (sh("slurmctld -f " + conf) != 0 || sh("slurmd -f " + conf) != 0) {
        for (const char* pid_file : {"slurmd.pid", "slurmctld.pid"}) stop(dir_ / pid_file);
        continue;  // a port in use, most likely: another pair
      }
      daemons_started_ = true;
      for (int i = 0; i < 150; ++i) {
        if (client("sinfo -h -o %t").find("idle") != std::string::npos) return "";
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
      }
      return "the Slurm node never became idle (30 s): sinfo says '" + client("sinfo -h -o %t") +
             "'; slurmctld/slurmd logs: " + log_tail();
    }
    return "slurmctld/slurmd did not start (3 port pairs tried): " + tail(dir_ / "setup.log") + log_tail();
  }
};

}  // namespace gravsweep::test
