// `gravsweep plot results` as users run it: a real campaign of no-op jobs, a real PNG from
// Debian's matplotlib, and bad input refused with exit code 2.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scheduler_test_helpers.h"
#include "tests/common/png_check.h"

using namespace gravsweep::test;
using nlohmann::json;

namespace {

/// Two values per gravity level, so that the mean +/- std of the repeats is drawn.
std::string spec() {
  json doc = {{"sweep", "plot"},
              {"job", "noop"},
              {"base", {{"g", 1.5}, {"value", 1.0}}},
              {"axes",
               {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {0.1, 1.62, 9.81}}},
                {{"name", "v"}, {"pointer", "/value"}, {"values", {1.0, 3.0}}}}}};
  return doc.dump();
}

std::string head_bytes(const std::filesystem::path& p, std::size_t n) {
  std::ifstream f(p, std::ios::binary);
  std::string s(n, '\0');
  f.read(s.data(), static_cast<std::streamsize>(n));
  return s;
}

}  // namespace

TEST(CliPlot, ResultsColumnAgainstColumnWritesAPng) {
  TempDir d;
  write_text(d.path / "spec.json", spec());
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  ASSERT_EQ(run_cli({"work", "--db", "c.db", "--workers", "2", "--quiet"}, d.path).code, 0);
  const auto r = run_cli({"plot", "results", "--db", "c.db", "--x", "gravity_m_s2", "--y", "noop_value", "--group", "v",
                          "--title", "test", "--out", "figs/f.png"},
                         d.path);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("6 runs plotted"), std::string::npos) << r.out;
  const auto png = d.path / "figs" / "f.png";
  ASSERT_TRUE(std::filesystem::exists(png));
  EXPECT_EQ(head_bytes(png, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_GT(std::filesystem::file_size(png), 15000u);  // axes, labels and points, not a blank canvas
  EXPECT_GT(png_stats(png).pixel_std, 0.05);
}

TEST(CliPlot, BadInputIsRefusedWithExitCode2) {
  TempDir d;
  write_text(d.path / "spec.json", spec());
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  ASSERT_EQ(run_cli({"work", "--db", "c.db", "--quiet"}, d.path).code, 0);
  auto r = run_cli(
      {"plot", "results", "--db", "c.db", "--x", "gravity_m_s2", "--y", "no_such_column", "--out", "f.png"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no_such_column"), std::string::npos) << r.err;
  r = run_cli({"plot", "results", "--db", "c.db", "--x", "gravity_m_s2", "--y", "noop_value", "--out", "f.pdf"},
              d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(".png"), std::string::npos) << r.err;
  r = run_cli({"plot", "results", "--db", "missing.db", "--x", "a", "--y", "b", "--out", "f.png"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("missing.db"), std::string::npos) << r.err;
  r = run_cli({"plot", "results", "--db", "c.db", "--x", "gravity_m_s2", "--y", "noop_value", "--where",
               "gravity_m_s2>100", "--out", "f.png"},
              d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no finished run"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d.path / "f.png"));
}

namespace {

/// A PNG that is a figure: the signature, a size, and pixels that are not all one colour.
void expect_figure(const std::filesystem::path& png, std::uintmax_t min_bytes) {
  ASSERT_TRUE(std::filesystem::exists(png)) << png;
  EXPECT_EQ(head_bytes(png, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << png;
  EXPECT_GT(std::filesystem::file_size(png), min_bytes) << png;
  const PngStats st = png_stats(png);
  ASSERT_TRUE(st.ok) << png;
  EXPECT_GT(st.width, 600) << png;
  EXPECT_GT(st.height, 400) << png;
  EXPECT_GT(st.pixel_std, 0.05) << png << ": a blank canvas";
}

/// One real `gravsweep run` of the tiny scenario (bed, trace, snapshots, fig2.png), shared by the
/// tests below: the drop is the expensive part.
/// Runs tests/scheduler/check_xdmf.py on an XDMF index; returns its exit status, `out` its output
/// ("ok <grids> <items> <times>" when every dataset the index names exists with its shape).
int check_xdmf(const std::filesystem::path& xdmf, std::string& out) {
  const std::string cmd =
      "/usr/bin/python3 '" GRAVSWEEP_SOURCE_DIR "/tests/scheduler/check_xdmf.py' '" + xdmf.string() + "' 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return -1;
  char buf[512] = {0};
  while (fgets(buf, sizeof buf, p)) out += buf;
  return pclose(p);
}

const std::filesystem::path& tiny_run() {
  static TempDir d("gravsweep-plot-run");
  static bool done = false;
  if (!done) {
    write_text(d.path / "scenario.json", tiny_base());
    const auto r = run_cli({"run", "scenario.json", "--out", "r", "--threads", "1", "--quiet"}, d.path);
    EXPECT_EQ(r.code, 0) << r.err << r.out;
    done = true;
  }
  return d.path;
}

}  // namespace

// Fig. 2 of Sunday et al. 2021 for one drop, from a real `gravsweep run` of the tiny scenario; `run` draws it.
TEST(CliPlot, TraceDrawsFig2NextToTheRun) {
  const auto& d = tiny_run();
  expect_figure(d / "r" / "fig2.png", 30000u);  // written by `run` itself
  auto r = run_cli({"plot", "trace", "r/trace.h5", "--out", "t/fig2.png"}, d);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("zstop"), std::string::npos) << r.out;
  expect_figure(d / "t" / "fig2.png", 30000u);
  // Bad input: a missing file, a file that is not a trace (the bed), a wrong extension.
  r = run_cli({"plot", "trace", "r/none.h5"}, d);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("r/none.h5"), std::string::npos) << r.err;
  r = run_cli({"plot", "trace", "r/bed.h5", "--out", "b.png"}, d);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("r/bed.h5"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d / "b.png"));
  r = run_cli({"plot", "trace", "r/trace.h5", "--out", "f.jpg"}, d);
  EXPECT_EQ(r.code, 2);
}

// A trace without contact (the time cap ends the drop before the projectile reaches the bed):
// `run` still succeeds and says why there is no figure; `plot trace` refuses it with exit 2.
TEST(CliPlot, TraceWithoutContactIsRefusedWithExitCode2) {
  const auto& d = tiny_run();
  auto doc = nlohmann::json::parse(tiny_base());
  doc["stop"]["max_time_s"] = 0.002;  // the projectile starts 5 mm above the grains at 0.5 m/s
  write_text(d / "nocontact.json", doc.dump());
  auto r = run_cli({"run", "nocontact.json", "--out", "nc", "--bed", "r/bed.h5", "--threads", "1", "--quiet",
                    "--snapshot-interval", "0"},
                   d);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("no fig2.png"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(d / "nc" / "fig2.png"));
  EXPECT_FALSE(std::filesystem::exists(d / "nc" / "snapshots.h5"));
  r = run_cli({"plot", "trace", "nc/trace.h5", "--out", "nc.png"}, d);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.err.find("nc/trace.h5"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("never makes contact"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d / "nc.png"));
}

// A lab record and a DEM record laid over each other (--compare), both ways round.
TEST(CliPlot, TraceComparesALabRecordWithTheDrop) {
  const auto& d = tiny_run();
  auto r = run_cli({"synth", "--out", "lab", "--gravity", "9.81", "--speeds", "0.5", "--repeats", "1", "--fill", "0.04",
                    "--rate", "10000"},
                   d);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  std::filesystem::path lab;
  for (const auto& e : std::filesystem::directory_iterator(d / "lab" / "traces")) lab = e.path();
  ASSERT_FALSE(lab.empty());
  r = run_cli({"plot", "trace", "r/trace.h5", "--compare", lab.string(), "--out", "cmp.png"}, d);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  expect_figure(d / "cmp.png", 30000u);
  r = run_cli({"plot", "trace", lab.string(), "--compare", "r/trace.h5", "--out", "cmp2.png"}, d);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  expect_figure(d / "cmp2.png", 30000u);
  // A CSV outside any campaign folder has no trial facts: refused, naming what is missing.
  std::filesystem::create_directories(d / "loose");
  std::filesystem::copy_file(lab, d / "loose" / "t.csv", std::filesystem::copy_options::overwrite_existing);
  r = run_cli({"plot", "trace", "loose/t.csv", "--out", "loose.png"}, d);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("trials.csv"), std::string::npos) << r.err;
  r = run_cli({"plot", "trace", "r/trace.h5", "--compare", "missing.csv", "--out", "m.png"}, d);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("missing.csv"), std::string::npos) << r.err;
}

// Fig. 1: the bed cut through its axis, with the projectile at release and at rest.
TEST(CliPlot, BedDrawsFig1WithTheProjectile) {
  const auto& d = tiny_run();
  auto r = run_cli({"plot", "bed", "r/bed.h5", "--trace", "r/trace.h5"}, d);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("grains at rest from"), std::string::npos) << r.out;  // the run's snapshots
  expect_figure(d / "r" / "fig1.png", 30000u);
  for (const char* at : {"release", "rest"}) {
    r = run_cli({"plot", "bed", "r/bed.h5", "--trace", "r/trace.h5", "--at", at, "--out", std::string(at) + ".png"}, d);
    ASSERT_EQ(r.code, 0) << r.err << r.out;
    expect_figure(d / (std::string(at) + ".png"), 20000u);
  }
  r = run_cli({"plot", "bed", "r/bed.h5", "--out", "bed.png"}, d);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  expect_figure(d / "bed.png", 20000u);
  // Bad input: a missing bed, a trace given as the bed, --at without a trace, a bad --at.
  r = run_cli({"plot", "bed", "r/none.h5", "--out", "x.png"}, d);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("r/none.h5"), std::string::npos) << r.err;
  r = run_cli({"plot", "bed", "r/trace.h5", "--out", "x.png"}, d);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("r/trace.h5"), std::string::npos) << r.err;
  r = run_cli({"plot", "bed", "r/bed.h5", "--at", "rest", "--out", "x.png"}, d);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--trace"), std::string::npos) << r.err;
  r = run_cli({"plot", "bed", "r/bed.h5", "--trace", "r/trace.h5", "--at", "later", "--out", "x.png"}, d);
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(std::filesystem::exists(d / "x.png"));
}

// Snapshots: `run` writes them by default; the XDMF parses as XML and every dataset it names
// exists in the HDF5 file with the shape and type it declares (tests/scheduler/check_xdmf.py).
TEST(CliPlot, RunWritesSnapshotsThatTheXdmfIndexDescribes) {
  const auto& d = tiny_run();
  const auto xdmf = d / "r" / "snapshots.xdmf";
  ASSERT_TRUE(std::filesystem::exists(d / "r" / "snapshots.h5"));
  ASSERT_TRUE(std::filesystem::exists(xdmf));
  std::string out;
  ASSERT_EQ(check_xdmf(xdmf, out), 0) << out;
  int grids = 0, items = 0, times = 0;
  ASSERT_EQ(std::sscanf(out.c_str(), "ok %d %d %d", &grids, &items, &times), 3) << out;
  EXPECT_GE(times, 3) << out;          // release, every 5 ms, the end
  EXPECT_EQ(grids, 2 * times) << out;  // grains and projectile per snapshot
  EXPECT_EQ(items, 5 * grids) << out;  // position, radius, velocity, omega, contacts
  // A corrupted index (a dataset renamed) is caught: the check can fail.
  std::ifstream f(xdmf);
  std::string x{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
  x.replace(x.find("/velocity_m_s"), 13, "/velocity_m_S");
  write_text(d / "r" / "bad.xdmf", x);
  const std::string bad = "/usr/bin/python3 '" GRAVSWEEP_SOURCE_DIR "/tests/scheduler/check_xdmf.py' '" +
                          (d / "r" / "bad.xdmf").string() + "' >/dev/null 2>&1";
  EXPECT_NE(std::system(bad.c_str()), 0);
}

// Campaign drops write snapshots when their scenario asks (/output/snapshot_interval_s), into
// <campaign>.files/snapshots/, one .h5 + .xdmf per drop that the same check reads; drops that do
// not ask write none.
TEST(CliPlot, CampaignDropsWriteSnapshotsWhenTheScenarioAsks) {
  TempDir d;
  for (const double interval_s : {0.0, 0.01}) {  // two sweeps: one drop without, one with snapshots
    json spec;
    spec["sweep"] = interval_s > 0 ? "snap" : "nosnap";
    spec["base"] = json::parse(tiny_base());
    spec["base"]["output"]["snapshot_interval_s"] = interval_s;
    spec["axes"] = json::array({{{"name", "impact_speed_m_s"},
                                 {"pointer", "/projectile/impact_speed_m_s"},
                                 {"values", {interval_s > 0 ? 0.5 : 0.6}}}});
    write_text(d.path / "spec.json", spec.dump(2));
    ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  }
  const auto r = run_cli({"work", "--db", "c.db", "--threads", "1", "--quiet"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<std::filesystem::path> xdmfs;
  for (const auto& e : std::filesystem::directory_iterator(d.path / "c.files" / "snapshots"))
    if (e.path().extension() == ".xdmf") xdmfs.push_back(e.path());
  ASSERT_EQ(xdmfs.size(), 1u) << "one of the two drops asked for snapshots";
  std::string out;
  ASSERT_EQ(check_xdmf(xdmfs[0], out), 0) << out;
  int grids = 0, items = 0, times = 0;
  ASSERT_EQ(std::sscanf(out.c_str(), "ok %d %d %d", &grids, &items, &times), 3) << out;
  EXPECT_GE(times, 3) << out;
  EXPECT_EQ(grids, 2 * times) << out;
  auto h5 = xdmfs[0];
  EXPECT_TRUE(std::filesystem::exists(h5.replace_extension(".h5"))) << h5;
}
