// `gravsweep plot results` as users run it: a real campaign of no-op jobs, a real PNG from
// Debian's matplotlib, and bad input refused with exit code 2.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "scheduler_test_helpers.h"

using namespace gravsweep::test;
using nlohmann::json;

namespace {

/// Two values per gravity level, so that the mean +/- std of the repeats is drawn.
std::string spec() {
  json doc = {{"sweep", "plot"}, {"job", "noop"},
              {"base", {{"g", 1.5}, {"value", 1.0}}},
              {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {0.1, 1.62, 9.81}}},
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
  const auto r = run_cli({"plot", "results", "--db", "c.db", "--x", "gravity_m_s2", "--y", "noop_value",
                          "--group", "v", "--title", "test", "--out", "figs/f.png"},
                         d.path);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("6 runs plotted"), std::string::npos) << r.out;
  const auto png = d.path / "figs" / "f.png";
  ASSERT_TRUE(std::filesystem::exists(png));
  EXPECT_EQ(head_bytes(png, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_GT(std::filesystem::file_size(png), 15000u);  // axes, labels and points, not a blank canvas
}

TEST(CliPlot, BadInputIsRefusedWithExitCode2) {
  TempDir d;
  write_text(d.path / "spec.json", spec());
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  ASSERT_EQ(run_cli({"work", "--db", "c.db", "--quiet"}, d.path).code, 0);
  auto r = run_cli({"plot", "results", "--db", "c.db", "--x", "gravity_m_s2", "--y", "no_such_column", "--out", "f.png"},
                   d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no_such_column"), std::string::npos) << r.err;
  r = run_cli({"plot", "results", "--db", "c.db", "--x", "gravity_m_s2", "--y", "noop_value", "--out", "f.pdf"}, d.path);
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

// Issue #15's Fig. 2 for one drop, from a real `gravsweep run` of the tiny scenario.
TEST(CliPlot, TraceDrawsFig2NextToTheRun) {
  TempDir d;
  write_text(d.path / "scenario.json", tiny_base());
  auto r = run_cli({"run", "scenario.json", "--out", "r", "--threads", "1"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cli({"plot", "trace", "r/trace.h5"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("zstop"), std::string::npos) << r.out;
  const auto png = d.path / "r" / "fig2.png";
  ASSERT_TRUE(std::filesystem::exists(png));
  EXPECT_EQ(head_bytes(png, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_GT(std::filesystem::file_size(png), 30000u);
  // Bad input: a missing file, a file that is not a trace (the bed), a wrong extension.
  r = run_cli({"plot", "trace", "r/none.h5"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("r/none.h5"), std::string::npos) << r.err;
  r = run_cli({"plot", "trace", "r/bed.h5", "--out", "b.png"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("r/bed.h5"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d.path / "b.png"));
  r = run_cli({"plot", "trace", "r/trace.h5", "--out", "f.jpg"}, d.path);
  EXPECT_EQ(r.code, 2);
}
