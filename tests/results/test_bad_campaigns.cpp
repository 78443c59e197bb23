// A corpus of bad measurement campaigns: for each, `gravsweep measurements import`
// exits 2, names the file and the line (and column where there is one), and writes nothing.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <vector>

#include "poncelet.h"
#include "results_helpers.h"

namespace fs = std::filesystem;

namespace {

using Cmd = gravsweep::testing::CliRun;
Cmd run(const std::string& args, bool merge_stderr = true) {
  return gravsweep::testing::run_gravsweep(args, merge_stderr);
}

constexpr const char* kHeader =
    "trial_id,trace_file,gravity_m_s2,impact_velocity_m_s,fill_height_m,projectile_mass_kg,"
    "projectile_diameter_m,grain_diameter_m,bulk_density_kg_m3,sample_rate_hz";

/// The lines of a good trace (header first): a Poncelet collision at 1400 Hz.
std::vector<std::string> good_trace() {
  gravsweep::testing::Poncelet k;
  std::vector<std::string> lines{"t_s,accel_m_s2"};
  const double t_contact = 0.0213457, fs_hz = 1400;
  for (int i = 0; i / fs_hz < t_contact + k.tstop() + 0.08; ++i) {
    std::ostringstream s;
    s.precision(10);
    s << i / fs_hz << "," << k.accel_up(i / fs_hz - t_contact);
    lines.push_back(s.str());
  }
  return lines;
}

std::vector<std::string> good_trials() {
  return {kHeader, "A,traces/A.csv,9.81,0.8,0.1,1.0,0.1,0.01,1450,1400",
          "B,traces/B.csv,9.81,0.8,0.1,1.0,0.1,0.01,1450,1400"};
}

void write_lines(const fs::path& p, const std::vector<std::string>& lines) {
  fs::create_directories(p.parent_path());
  std::ofstream f(p, std::ios::binary);
  for (const auto& l : lines) f << l << "\n";
}

struct Case {
  const char* name;
  /// Edits the campaign: trials.csv lines, trace A's lines, the campaign folder (for links).
  std::function<void(std::vector<std::string>& trials, std::vector<std::string>& trace, const fs::path& dir)> edit;
  std::string expect;  ///< "file:line[:column]" that the message must hold
  std::string what;    ///< and a word of the reason
};

std::vector<Case> corpus() {
  using V = std::vector<std::string>;
  const fs::path none;
  return {
      {"missing required column",
       [](V& t, V&, const fs::path&) {
         t[0] =
             "trial_id,trace_file,impact_velocity_m_s,fill_height_m,projectile_mass_kg,projectile_diameter_m,"
             "grain_diameter_m,bulk_density_kg_m3,sample_rate_hz";
       },
       "trials.csv:1", "missing required column 'gravity_m_s2'"},
      {"unparseable number",
       [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,abc,0.8,0.1,1.0,0.1,0.01,1450,1400"; }, "trials.csv:2:3",
       "expected a finite number"},
      {"NaN in trials.csv",
       [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,nan,0.8,0.1,1.0,0.1,0.01,1450,1400"; }, "trials.csv:2:3",
       "finite number"},
      {"negative mass", [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,0.8,0.1,-1,0.1,0.01,1450,1400"; },
       "trials.csv:2:6", "> 0"},
      {"duplicate trial id",
       [](V& t, V&, const fs::path&) { t[2] = "A,traces/A.csv,9.81,0.8,0.1,1.0,0.1,0.01,1450,1400"; }, "trials.csv:3:1",
       "appears twice"},
      {"empty trial id", [](V& t, V&, const fs::path&) { t[1] = ",traces/A.csv,9.81,0.8,0.1,1.0,0.1,0.01,1450,1400"; },
       "trials.csv:2:1", "empty"},
      {"trace path with ..",
       [](V& t, V&, const fs::path&) { t[1] = "A,../../../../../etc/passwd,9.81,0.8,0.1,1.0,0.1,0.01,1450,1400"; },
       "trials.csv:2:2", "outside"},
      {"absolute trace path",
       [](V& t, V&, const fs::path&) { t[1] = "A,/etc/passwd,9.81,0.8,0.1,1.0,0.1,0.01,1450,1400"; }, "trials.csv:2:2",
       "absolute"},
      {"symlink leading outside",
       [](V&, V&, const fs::path& dir) {
         fs::remove(dir / "traces/A.csv");
         fs::create_symlink("/etc/passwd", dir / "traces/A.csv");
       },
       "trials.csv:2:2", "outside"},
      {"missing trace file", [](V&, V&, const fs::path& dir) { fs::remove(dir / "traces/A.csv"); }, "trials.csv line 2",
       "cannot open"},
      {"trace without accel column", [](V&, V& tr, const fs::path&) { tr[0] = "t_s,acc"; }, "traces/A.csv:1",
       "missing column 'accel_m_s2'"},
      {"text in a trace", [](V&, V& tr, const fs::path&) { tr[4] = tr[4].substr(0, tr[4].find(',')) + ",abc"; },
       "traces/A.csv:5:2", "finite number"},
      {"time not increasing", [](V&, V& tr, const fs::path&) { std::swap(tr[10], tr[11]); }, "traces/A.csv:12:1",
       "time must increase"},
      {"NaN in a trace", [](V&, V& tr, const fs::path&) { tr[30] = tr[30].substr(0, tr[30].find(',')) + ",nan"; },
       "traces/A.csv:31:2", "finite number"},
      {"1e308 overflow in a trace",
       [](V&, V& tr, const fs::path&) { tr[30] = tr[30].substr(0, tr[30].find(',')) + ",1e999"; }, "traces/A.csv:31:2",
       "finite number"},
      {"declared rate contradicts the timestamps",
       [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,0.8,0.1,1.0,0.1,0.01,1450,14000"; },
       "trials.csv:2:10", "declared 14000 Hz"},
      {"gap inside the collision", [](V&, V& tr, const fs::path&) { tr.erase(tr.begin() + 40, tr.begin() + 60); },
       "traces/A.csv:41:1", "gap"},
      {"unterminated quote",
       [](V& t, V&, const fs::path&) { t[1] = "A,\"traces/A.csv,9.81,0.8,0.1,1.0,0.1,0.01,1450,1400"; },
       "trials.csv:2:2", "unterminated"},
      {"trace too short", [](V&, V& tr, const fs::path&) { tr.resize(6); }, "traces/A.csv:6", "only 5 samples"},
      {"never makes contact",
       [](V&, V& tr, const fs::path&) {
         for (std::size_t i = 1; i < tr.size(); ++i) tr[i] = tr[i].substr(0, tr[i].find(',')) + ",-9.81";
       },
       "trials.csv line 2", "never makes contact"},
      // Each unmeasurable record gets its own reason, at the line it is about.
      {"1e308 in a trace", [](V&, V& tr, const fs::path&) { tr[30] = tr[30].substr(0, tr[30].find(',')) + ",1e308"; },
       "traces/A.csv:31:2", "beyond any accelerometer's range"},
      {"no free fall (starts at rest)",
       [](V&, V& tr, const fs::path&) {
         for (std::size_t i = 1; i < 30; ++i) tr[i] = tr[i].substr(0, tr[i].find(',')) + ",0";
       },
       "traces/A.csv:2: ", "does not start in free fall"},
      {"never makes contact (a small bump)",
       [](V&, V& tr, const fs::path&) {
         for (std::size_t i = 1; i < tr.size(); ++i)
           tr[i] = tr[i].substr(0, tr[i].find(',')) + (i == 40 ? ",-6" : ",-9.81");
       },
       "traces/A.csv:41: ", "never makes contact"},
      {"record ends inside the collision", [](V&, V& tr, const fs::path&) { tr.resize(50); },
       "traces/A.csv:50: ", "shorter than the collision"},
      {"a line with a column missing", [](V&, V& tr, const fs::path&) { tr[7] = tr[7].substr(0, tr[7].find(',')); },
       "traces/A.csv:8:2", "missing on this line"},
      {"empty trials.csv", [](V& t, V&, const fs::path&) { t.clear(); }, "trials.csv:1", "empty file"},
      {"header-only trials.csv", [](V& t, V&, const fs::path&) { t.resize(1); }, "trials.csv:1", "no trial rows"},
      // Physical bounds on every trial field: a wrong unit or a corrupt number never reaches a fit.
      {"mass 1e308", [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,0.8,0.1,1e308,0.1,0.01,1450,1400"; },
       "trials.csv:2:6", "a projectile mass 1e-06 <= value <= 1000 kg"},
      {"mass 1e-300 (a fit's forces underflow)",
       [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,0.8,0.1,1e-300,0.1,0.01,1450,1400"; },
       "trials.csv:2:6", "a projectile mass 1e-06 <= value"},
      {"gravity 1e-300",
       [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,1e-300,0.8,0.1,1.0,0.1,0.01,1450,1400"; },
       "trials.csv:2:3", "a gravity 1e-06 <= value"},
      {"mass 1e30", [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,0.8,0.1,1e30,0.1,0.01,1450,1400"; },
       "trials.csv:2:6", "projectile mass"},
      {"gravity 1e6", [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,1e6,0.8,0.1,1.0,0.1,0.01,1450,1400"; },
       "trials.csv:2:3", "a gravity"},
      {"speed 1e5", [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,1e5,0.1,1.0,0.1,0.01,1450,1400"; },
       "trials.csv:2:4", "an impact speed"},
      {"bed depth 1e3 m",
       [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,0.8,1e3,1.0,0.1,0.01,1450,1400"; }, "trials.csv:2:5",
       "a bed depth"},
      {"projectile diameter in mm",
       [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,0.8,0.1,1.0,100,0.01,1450,1400"; }, "trials.csv:2:7",
       "a projectile diameter"},
      {"grain diameter in mm",
       [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,0.8,0.1,1.0,0.1,10,1450,1400"; }, "trials.csv:2:8",
       "a grain diameter"},
      {"bulk density 1e9",
       [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,0.8,0.1,1.0,0.1,0.01,1e9,1400"; }, "trials.csv:2:9",
       "a bulk density"},
      {"sample rate 1e12",
       [](V& t, V&, const fs::path&) { t[1] = "A,traces/A.csv,9.81,0.8,0.1,1.0,0.1,0.01,1450,1e12"; },
       "trials.csv:2:10", "a sample rate"},
  };
}

}  // namespace

TEST(BadCampaigns, EachIsRefusedWithExitCode2TheFileAndLineAndNothingWritten) {
  const auto cases = corpus();
  ASSERT_GE(cases.size(), 15u);
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    gravsweep::testing::TempDir d;
    const fs::path dir = d.path / "camp";
    auto trials = good_trials();
    auto trace = good_trace();
    write_lines(dir / "traces/A.csv", trace);
    write_lines(dir / "traces/B.csv", trace);
    c.edit(trials, trace, dir);
    if (fs::is_regular_file(fs::symlink_status(dir / "traces/A.csv"))) write_lines(dir / "traces/A.csv", trace);
    if (trials.empty())
      std::ofstream(dir / "trials.csv", std::ios::trunc);
    else
      write_lines(dir / "trials.csv", trials);
    const fs::path db = d.path / "out.db";
    const Cmd r = run("measurements import '" + dir.string() + "' --db '" + db.string() + "'");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << "expected '" << c.expect << "' in:\n" << r.out;
    EXPECT_NE(r.out.find(c.what), std::string::npos) << "expected '" << c.what << "' in:\n" << r.out;
    EXPECT_FALSE(fs::exists(db)) << "nothing may be written";
  }
}

TEST(BadCampaigns, KeepGoingStoresTheGoodTrialsAndExitsIncomplete) {
  gravsweep::testing::TempDir d;
  const fs::path dir = d.path / "camp";
  auto trace = good_trace();
  write_lines(dir / "traces/A.csv", trace);
  trace[4] = "0.002,abc";
  write_lines(dir / "traces/B.csv", trace);
  write_lines(dir / "trials.csv", good_trials());
  const Cmd r =
      run("measurements import '" + dir.string() + "' --db '" + (d.path / "x.db").string() + "' --keep-going");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("traces/B.csv:5:2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 trials stored"), std::string::npos) << r.out;
}
