// A bed named on the command line: `run --bed` verifies the bed against
// the checksum `run` wrote beside it (bed.h5.sha256, the SHA-256 campaigns record for their beds)
// and refuses every changed bit with exit 2 naming the file; a corrupt bed file (cut short, random
// bytes, an HDF5 file that is not a bed or lacks a dataset) is refused the same way by `run --bed`
// and `bench --bed`; a bed without a checksum file (older runs) is used with a warning.
#include <gtest/gtest.h>

#include <hdf5.h>

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <random>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "results/io/bed_file.h"
#include "scheduler/pipeline/impact_runners.h"
#include "scheduler/queue/canonical.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
namespace fs = std::filesystem;

namespace {

std::vector<char> read_bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& p, const std::vector<char>& b) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f.write(b.data(), static_cast<std::streamsize>(b.size()));
}

/// Byte offset in the HDF5 file of element `index` of a float64 dataset (contiguous layout).
std::size_t offset_of(const fs::path& file, const char* dataset, std::size_t index) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, dataset, H5P_DEFAULT);
  const haddr_t at = H5Dget_offset(d);
  H5Dclose(d);
  H5Fclose(f);
  return at == HADDR_UNDEF ? std::string::npos : static_cast<std::size_t>(at) + 8 * index;
}

/// A real bed of the tiny scenario, prepared once for the tests of this file (about a second).
struct Prepared {
  TempDir dir;
  fs::path scenario, bed;
};

const Prepared& prepared() {
  static Prepared* p = [] {
    auto* q = new Prepared;
    q->scenario = q->dir.path / "tiny.json";
    write_text(q->scenario, tiny_base());
    const auto r = run_cli({"run", "tiny.json", "--out", "first", "--quiet", "--threads", "1"}, q->dir.path);
    EXPECT_EQ(r.code, 0) << r.err;
    q->bed = q->dir.path / "first" / "bed.h5";
    return q;
  }();
  return *p;
}

/// A copy of the prepared bed (with its checksum file when `with_checksum`) in `dir`.
fs::path copy_bed(const fs::path& dir, bool with_checksum) {
  fs::create_directories(dir);
  fs::copy_file(prepared().bed, dir / "bed.h5");
  if (with_checksum) fs::copy_file(prepared().bed.string() + ".sha256", dir / "bed.h5.sha256");
  return dir / "bed.h5";
}

}  // namespace

TEST(BedInput, RunWritesTheBedsChecksumBesideIt) {
  const auto& p = prepared();
  std::ifstream f(p.bed.string() + ".sha256");
  std::string hex, name;
  f >> hex >> name;
  EXPECT_EQ(hex, queue::sha256_file(p.bed)) << "the checksum campaigns record for a bed";
  EXPECT_EQ(name, "bed.h5") << "sha256sum's format";
}

TEST(BedInput, RunBedRefusesEveryFlippedBitOfTheParticleDataAndTakesTheIntactBed) {
  const auto& p = prepared();
  const std::vector<char> bytes = read_bytes(p.bed);
  Particles grains;
  results::read_bed(p.bed, grains);
  const std::size_t n = grains.size();
  ASSERT_GT(n, 10u);
  // Positions in the particle data: (dataset, element, byte within it, bit).
  struct Flip {
    const char* dataset;
    std::size_t element;
    int byte, bit;
  };
  const std::vector<Flip> flips = {
      {"/grains/position_m", 0, 0, 0},                // x of the first grain, lowest mantissa bit
      {"/grains/position_m", 3 * (n / 2) + 2, 3, 5},  // z of a middle grain, a middle mantissa bit
      {"/grains/velocity_m_s", 3 * n - 1, 7, 7},      // the last value, its sign bit
      {"/grains/omega_rad_s", 3 * 7 + 1, 6, 4},       // an exponent bit
      {"/grains/radius_m", n - 1, 0, 0},              // the last radius, lowest bit
      {"/grains/mass_kg", 3, 6, 1},                   // a high mantissa bit
  };
  int refused = 0;
  for (std::size_t i = 0; i < flips.size(); ++i) {
    const Flip& fl = flips[i];
    SCOPED_TRACE(fmt::format("{}[{}] byte {} bit {}", fl.dataset, fl.element, fl.byte, fl.bit));
    const std::size_t at = offset_of(p.bed, fl.dataset, fl.element);
    ASSERT_NE(at, std::string::npos) << "not a contiguous dataset";
    ASSERT_LT(at + 8, bytes.size());
    const fs::path dir = p.dir.path / fmt::format("flip{}", i);
    const fs::path copy = copy_bed(dir, true);
    auto changed = bytes;
    changed[at + static_cast<std::size_t>(fl.byte)] ^= static_cast<char>(1 << fl.bit);
    write_bytes(copy, changed);
    const std::string out = fmt::format("out_flip{}", i);
    const auto r = run_cli({"run", "tiny.json", "--out", out, "--bed", copy.string(), "--quiet"}, p.dir.path);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(copy.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("does not match its checksum"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(p.dir.path / out)) << "nothing may be written";
    refused += r.code == 2;
  }
  std::printf("run --bed: %d of %zu single-bit flips in the particle data refused\n", refused, flips.size());
  // The intact bed (its own copy, with the checksum) is accepted and dropped into.
  const fs::path intact = copy_bed(p.dir.path / "intact", true);
  const auto r = run_cli({"run", "tiny.json", "--out", "out_intact", "--bed", intact.string(), "--quiet"}, p.dir.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(p.dir.path / "out_intact" / "trace.h5"));
}

TEST(BedInput, ABedWithoutAChecksumFileIsUsedWithAWarning) {
  const auto& p = prepared();
  const fs::path old = copy_bed(p.dir.path / "old", false);
  const auto r = run_cli({"run", "tiny.json", "--out", "out_old", "--bed", old.string(), "--quiet"}, p.dir.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no checksum file"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(old.string()), std::string::npos) << r.err;
}

TEST(BedInput, ACorruptBedFileExitsTwoNamingItInRunAndBench) {
  const auto& p = prepared();
  const std::vector<char> bytes = read_bytes(p.bed);
  struct Corrupt {
    const char* name;
    std::function<void(const fs::path&)> make;  ///< writes the bad bed at the path
    const char* why;                            ///< a word of the reason
  };
  const std::vector<Corrupt> cases = {
      {"cut short",
       [&](const fs::path& f) {
         write_bytes(f, {bytes.begin(), bytes.begin() + bytes.size() / 2});
       },
       "not a readable gravsweep bed"},
      {"random bytes",
       [&](const fs::path& f) {
         std::vector<char> junk(bytes.size());
         std::mt19937 rng(11);
         for (auto& c : junk) c = static_cast<char>(rng());
         write_bytes(f, junk);
       },
       "not an HDF5 file"},
      {"a trace, not a bed", [&](const fs::path& f) { fs::copy_file(p.dir.path / "first" / "trace.h5", f); },
       "not a gravsweep bed"},
      {"HDF5 bed missing /grains/mass_kg",
       [&](const fs::path& f) {
         fs::copy_file(p.bed, f);
         const hid_t h = H5Fopen(f.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
         ASSERT_GE(h, 0);
         EXPECT_GE(H5Ldelete(h, "/grains/mass_kg", H5P_DEFAULT), 0);
         H5Fclose(h);
       },
       "mass_kg"},
      {"a folder", [&](const fs::path& f) { fs::create_directories(f); }, "not a regular file"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(cases[i].name);
    const fs::path bad = p.dir.path / fmt::format("bad{}", i) / "bed.h5";  // no checksum file beside it
    fs::create_directories(bad.parent_path());
    cases[i].make(bad);
    const std::string out = fmt::format("out_bad{}", i);
    auto r = run_cli({"run", "tiny.json", "--out", out, "--bed", bad.string(), "--quiet"}, p.dir.path);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(cases[i].why), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(p.dir.path / out));
    if (fs::is_directory(bad)) continue;  // bench --bed takes files only (its own check: exit 2 too)
    r = run_cli({"bench", "--bed", bad.string(), "--steps", "5", "--threads", "1"}, p.dir.path);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
  }
}

namespace {

/// Multiplies element `index` of a float64 dataset of `file` by `factor` (through HDF5); a 0 becomes `factor`.
void scale_element(const fs::path& file, const char* dataset, std::size_t index, double factor) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, dataset, H5P_DEFAULT);
  const hid_t space = H5Dget_space(d);
  std::vector<double> values(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  values.at(index) = values.at(index) == 0 ? factor : values.at(index) * factor;
  H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(f);
}

}  // namespace

// A bed corrupted with its checksum regenerated (flipped exponents in radius, mass or a position):
// the physical ranges of its grains are checked when it is loaded, exit 2 naming the file and the
// grain, instead of a numerical failure (exit 3) at step 0 that names neither.
TEST(BedInput, ABedWithAGrainOutsidePhysicalRangesExitsTwoNamingTheFileAndGrain) {
  const auto& p = prepared();
  struct Corrupt {
    const char* dataset;
    std::size_t element;
    double factor;
    const char* what;
  };
  const double k2_64 = std::ldexp(1.0, 64);
  for (const Corrupt& c :
       {Corrupt{"/grains/radius_m", 5, k2_64, "radius_m"}, Corrupt{"/grains/radius_m", 6, 1 / k2_64, "radius_m"},
        Corrupt{"/grains/mass_kg", 7, k2_64, "mass_kg"}, Corrupt{"/grains/mass_kg", 8, 1 / k2_64, "mass_kg"},
        Corrupt{"/grains/position_m", 3 * 9 + 2, k2_64, "position_m"},
        Corrupt{"/grains/velocity_m_s", 3 * 10, 1e300, "velocity_m_s"}}) {
    SCOPED_TRACE(fmt::format("{}[{}] x {}", c.dataset, c.element, c.factor));
    const fs::path dir = p.dir.path / fmt::format("range_{}_{}", fs::path(c.dataset).filename().string(), c.element);
    const fs::path bed = copy_bed(dir, false);
    scale_element(bed, c.dataset, c.element, c.factor);
    write_text(bed.string() + ".sha256", queue::sha256_file(bed) + "  bed.h5\n");  // the checksum regenerated
    const std::string name(c.dataset);
    const bool per_axis = name.find("position") != std::string::npos || name.find("velocity") != std::string::npos;
    const std::size_t grain = per_axis ? c.element / 3 : c.element;
    auto r = run_cli({"run", "tiny.json", "--out", dir.filename().string() + "_out", "--bed", bed.string(), "--quiet"},
                     p.dir.path);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(bed.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(fmt::format("grain {}:", grain)), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.what), std::string::npos) << r.err;
    r = run_cli({"bench", "--bed", bed.string(), "--steps", "5", "--threads", "1"}, p.dir.path);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(fmt::format("grain {}:", grain)), std::string::npos) << r.err;
  }
}
