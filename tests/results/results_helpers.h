// Helpers for the results/ tests: temporary folders, the real binary and the shared dev campaign.
#pragma once
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "tests/common/temp_dir.h"

namespace gravsweep::testing {

/// A fresh temporary folder, removed when the object goes out of scope (the one of tests/common).
using TempDir = gravsweep::test::TempDir;

/// The exit code and output of the real `gravsweep` binary (stderr too when merge_stderr).
struct CliRun {
  int code;
  std::string out;
};
inline CliRun run_gravsweep(const std::string& args, bool merge_stderr) {
  const std::string cmd = std::string("'") + GRAVSWEEP_BINARY + "' " + args + (merge_stderr ? " 2>&1" : " 2>/dev/null");
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf{};
  while (p && fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int st = p ? pclose(p) : -1;
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

/// ../shared/data/measurements/depth-friction-dev relative to the source tree.
inline std::string dev_campaign() {
  return (std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / ".." / "shared" / "data" / "measurements" /
          "depth-friction-dev")
      .lexically_normal()
      .string();
}

}  // namespace gravsweep::testing

/// The dev campaign lives outside the repository (../shared); skip, saying so, where it is absent.
#define GRAVSWEEP_REQUIRE_DEV_CAMPAIGN()                                              \
  do {                                                                                \
    if (!std::filesystem::exists(gravsweep::testing::dev_campaign() + "/trials.csv")) \
      GTEST_SKIP() << "no dev campaign at " << gravsweep::testing::dev_campaign();    \
  } while (0)
