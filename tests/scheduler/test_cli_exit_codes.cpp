// The documented exit codes (docs/reference.md, scheduler/cli/exit_codes.h) of the verbs that end with an
// outcome other than success or a plain error: they leave through main() (cli::ExitWith), never by
// std::exit in a callback, and what they printed before is still there. Real processes, real files.
#include <gtest/gtest.h>

#include <array>
#include <cctype>
#include <csignal>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <thread>

#include "db/database.h"
#include "results/io/trace_file.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

/// A short, valid DEM trace.h5 (free fall onto the surface, then at rest).
void write_small_trace(const fs::path& p) {
  results::TraceData d;
  constexpr double kRate_hz = 10000, kG = 9.81, kV0 = 0.5;
  for (int i = 0; i < 400; ++i) {
    const double t = i / kRate_hz;
    const bool falling = i < 100;
    d.raw.t_s.push_back(t);
    d.raw.depth_m.push_back(falling ? -kV0 * (0.01 - t) : 0.0);
    d.raw.velocity_down_m_s.push_back(falling ? kV0 : 0.0);
    d.raw.accel_up_m_s2.push_back(falling ? -kG : 0.0);
    for (int c = 0; c < 3; ++c) {
      d.omega_rad_s.push_back(0.0);
      d.position_m.push_back(0.0);
    }
    d.contacts.push_back(falling ? 0 : 3);
    d.grain_kinetic_energy_J.push_back(0.0);
  }
  d.info.sample_rate_hz = kRate_hz;
  d.dt_s = 1e-5;
  d.info.gravity_m_s2 = kG;
  d.info.fill_height_m = 0.04;
  d.release_height_m = 0.05;
  d.release_speed_m_s = kV0;
  d.info.projectile_diameter_m = 0.03;
  d.info.projectile_mass_kg = 0.03;
  d.info.grain_diameter_m = 0.01;
  d.stopped = true;
  d.scenario_json = "{}";
  d.bed_key_json = "{}";
  d.metrics_json = "{}";
  d.info.code_version = "test";
  fs::create_directories(p.parent_path());
  results::write_trace(p, d);
}

}  // namespace

TEST(ExitCodes, TheDocumentedNumbersAreStable) {
  EXPECT_EQ(cli::kExitOk, 0);
  EXPECT_EQ(cli::kExitFailure, 1);
  EXPECT_EQ(cli::kExitUsage, 2);
  EXPECT_EQ(cli::kExitNumerical, 3);
  EXPECT_EQ(cli::kExitIncomplete, 4);
  EXPECT_EQ(cli::kExitInterrupted, 130);
  EXPECT_EQ(cli::kExitInterrupted, cli::kExitSignalBase + SIGINT);
}

TEST(ExitCodes, MeasurementsFromRunsWithAnUnreadableInputExits4AfterWritingTheRest) {
  TempDir d;
  write_small_trace(d.path / "runs/a/trace.h5");
  fs::create_directories(d.path / "runs/b");
  write_text(d.path / "runs/b/trace.h5", "not an HDF5 file");
  const auto r = run_cli({"measurements", "from-runs", "runs", "--out", "camp"}, d.path);
  EXPECT_EQ(r.code, cli::kExitIncomplete) << r.out << r.err;
  EXPECT_NE(r.out.find("1 DEM trials written to camp/trials.csv"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("runs/b/trace.h5"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(d.path / "camp/trials.csv"));
  // Nothing readable at all is bad input: exit 2.
  const auto none = run_cli({"measurements", "from-runs", "runs/b", "--out", "none"}, d.path);
  EXPECT_EQ(none.code, cli::kExitUsage) << none.err;
}

TEST(ExitCodes, MeasurementsImportKeepGoingExits4WithItsTablePrinted) {
  TempDir d;
  ASSERT_EQ(run_cli({"synth", "--out", "c", "--gravity", "9.81", "--speeds", "0.5,1.0", "--repeats", "1"}, d.path).code,
            0);
  write_text(d.path / "c/traces/S002.csv", "t_s,accel_m_s2\n0,-9.81\n0.001,abc\n");
  const auto r = run_cli({"measurements", "import", "c", "--db", "lab.db", "--keep-going", "--format", "csv"}, d.path);
  EXPECT_EQ(r.code, cli::kExitIncomplete) << r.err;
  EXPECT_EQ(r.out.rfind("trial_id,source,", 0), 0u) << "the table on stdout, flushed before the exit:\n" << r.out;
  EXPECT_NE(r.out.find("S001"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("1 trials stored in lab.db"), std::string::npos) << r.err;
}

TEST(ExitCodes, RunInterruptedBySigtermExits130AndSaysSo) {
  TempDir d;
  json s = json::parse(tiny_base());
  s["bed"]["settle"] = {{"max_time_s", 60.0}, {"rms_speed_m_s", 1e-12}, {"max_speed_m_s", 1e-12}};  // never settles
  write_text(d.path / "s.json", s.dump(2));
  const fs::path out = d.path / "out";
  const pid_t pid = start_cli({"run", (d.path / "s.json").string(), "--out", out.string(), "--quiet", "--no-figures"},
                              d.path / "run.log");
  const auto t0 = std::chrono::steady_clock::now();
  while (!fs::exists(out)) {  // the signal handlers are installed right after the folder is made
    ASSERT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(60)) << "run never started";
    ASSERT_EQ(waitpid(pid, nullptr, WNOHANG), 0) << "run ended before it was interrupted";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  kill(pid, SIGTERM);
  EXPECT_EQ(wait_child(pid, 60), cli::kExitInterrupted);
  std::stringstream log;
  log << std::ifstream(d.path / "run.log").rdbuf();
  EXPECT_NE(log.str().find("interrupted: "), std::string::npos) << log.str();
  EXPECT_NE(log.str().find("(no partial files left)"), std::string::npos) << log.str();
  EXPECT_FALSE(fs::exists(out / "bed.h5")) << "no partial bed";
}

TEST(ExitCodes, WorkWithADeadJobExits4FromOneWorkerAndFromTheSupervisor) {
  TempDir d;
  const json spec = {{"sweep", "dead"},
                     {"job", "noop"},
                     {"max_attempts", 1},
                     {"base", {{"g", 1.0}, {"sleep_s", 0.0}, {"fail_attempts", 99}}},
                     {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {1.0, 2.0}}}}}};
  write_text(d.path / "spec.json", spec.dump(2));
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  auto r = run_cli({"work", "--db", "c.db", "--poll", "0.02", "--quiet"}, d.path);
  EXPECT_EQ(r.code, cli::kExitIncomplete) << r.err;
  r = run_cli({"work", "--db", "c.db", "--workers", "2", "--poll", "0.02", "--quiet"}, d.path);
  EXPECT_EQ(r.code, cli::kExitIncomplete) << r.err;
  db::Database db((d.path / "c.db").string());
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='dead'"), 2);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE exit_code=" + std::to_string(cli::kExitFailure)), 2);
}

// Every verb takes --format the same way (scheduler/cli/format_option.h): an unknown format is a
// usage error (exit 2) with the same message, here from `results` (the former queue table writer)
// and `model terms` (the former results::Table), before anything is read.
TEST(ExitCodes, UnknownFormatIsRefusedWithExit2AndOneMessageByEveryVerb) {
  TempDir d;
  const auto results = run_cli({"results", "--db", "absent.db", "--format", "xml"}, d.path);
  const auto terms = run_cli({"model", "terms", "--format", "xml"}, d.path);
  EXPECT_EQ(results.code, cli::kExitUsage) << results.err;
  EXPECT_EQ(terms.code, cli::kExitUsage) << terms.err;
  EXPECT_NE(results.err.find("--format: xml not in {table,csv,json}"), std::string::npos) << results.err;
  EXPECT_EQ(results.err, terms.err);
  EXPECT_TRUE(results.out.empty()) << results.out;
  EXPECT_FALSE(fs::exists(d.path / "absent.db"));
}

// The code version every run and attempt records is the source tree's at build time: it was taken
// when CMake configured, so a build after a commit or an edit kept the older version (a campaign
// binary built from a clean commit said "-dirty" and another commit's hash).
TEST(Version, IsTheSourceTreesAtBuildTime) {
  const std::string cmd =
      std::string("git -C '") + GRAVSWEEP_SOURCE_DIR + "' describe --always --dirty --abbrev=12 2>/dev/null";
  std::string described;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    std::array<char, 256> buf{};
    while (fgets(buf.data(), buf.size(), p)) described += buf.data();
    pclose(p);
  }
  while (!described.empty() && std::isspace(static_cast<unsigned char>(described.back()))) described.pop_back();
  if (described.empty()) GTEST_SKIP() << "the source tree is not a git checkout";
  TempDir dir("gravsweep-version");
  const CmdResult r = run_cli({"--version"}, dir.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("+" + described), std::string::npos)
      << "gravsweep --version says " << r.out << "; the tree is " << described
      << " (rebuild: the version is taken at every build)";
}
