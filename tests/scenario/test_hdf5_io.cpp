// bed.h5 and trace.h5: round trips are bit-exact, every dataset carries its units, files are
// readable with h5py, and errors name the file and the missing piece.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "results/io/bed_file.h"
#include "results/io/hdf5.h"
#include "results/io/trace_file.h"
#include "scenario_helpers.h"

namespace gravsweep {
namespace {

/// Five grains whose values test the round trip's bits (1/3 and steps of 1e-17 in a position).
Particles sample_grains() {
  Particles g;
  for (int i = 0; i < 5; ++i) {
    Vec3 p, v, w;
    for (int k = 0; k < 3; ++k) {
      p[k] = 0.01 * i + 1e-17 * k + 1.0 / 3.0;
      v[k] = -1e-6 * (i + k);
      w[k] = 0.1 * k;
    }
    const ParticleIndex j = g.add(p, 0.005 + 1e-5 * i, 1.3e-3, 0, SizeClass::grain);
    g.set_velocity(j, v, w);
  }
  return g;
}

results::BedFacts sample_facts() {
  results::BedFacts f;
  f.container_diameter_m = 0.315;
  f.wall_height_m = 0.2;
  f.fill_height_m = 0.1;
  f.surface_height_m = 0.1003;
  f.gravity_m_s2 = 9.81;
  f.time_s = 1.25;
  f.bed_key_json = R"({"k":1})";
  f.scenario_json = R"({"name":"x"})";
  f.report_json = R"({"grains_kept":5})";
  f.code_version = "test";
  return f;
}

results::TraceData sample_trace() {
  results::TraceData d;
  for (int i = 0; i < 20; ++i) {
    d.raw.t_s.push_back(1e-4 * i);
    d.raw.depth_m.push_back(-0.005 + 1e-4 * i);
    d.raw.velocity_down_m_s.push_back(1.0);
    d.raw.accel_up_m_s2.push_back(-9.81);
    for (int k = 0; k < 3; ++k) {
      d.omega_rad_s.push_back(0.0);
      d.position_m.push_back(k == 2 ? 0.15 : 0.0);
    }
    d.contacts.push_back(i / 10);
    d.grain_kinetic_energy_J.push_back(1e-3 * i);
  }
  d.info.sample_rate_hz = 1e4;
  d.dt_s = 1e-6;
  d.info.gravity_m_s2 = 9.81;
  d.stopped = true;
  d.metrics_json = R"({"zstop_m":0.03})";
  return d;
}

// The grains read back are the engine's particles as add() and set_velocity() make them, bit for
// bit: the state a drop from the bed in memory starts from.
TEST(Hdf5Io, BedRoundTripIsBitExact) {
  test::TempDir dir;
  const Particles g = sample_grains();
  const results::BedFacts f = sample_facts();
  results::write_bed(dir.path / "bed.h5", g, f);
  Particles r;
  r.add(Vec3(1, 2, 3), 0.1, 1.0, 0, SizeClass::projectile);  // replaced by the file's grains
  const results::BedFacts rf = results::read_bed(dir.path / "bed.h5", r);
  ASSERT_EQ(r.size(), g.size());
  EXPECT_TRUE(r.position_m == g.position_m);
  EXPECT_TRUE(r.velocity_m_s == g.velocity_m_s);
  EXPECT_TRUE(r.omega_rad_s == g.omega_rad_s);
  EXPECT_TRUE(r.eval_velocity_m_s == g.eval_velocity_m_s);
  EXPECT_TRUE(r.eval_omega_rad_s == g.eval_omega_rad_s);
  EXPECT_TRUE(r.force_N == g.force_N);
  EXPECT_TRUE(r.torque_N_m == g.torque_N_m);
  EXPECT_EQ(r.radius_m, g.radius_m);
  EXPECT_EQ(r.mass_kg, g.mass_kg);
  EXPECT_EQ(r.inv_mass_1_kg, g.inv_mass_1_kg);
  EXPECT_EQ(r.inv_inertia_1_kg_m2, g.inv_inertia_1_kg_m2);
  EXPECT_EQ(r.material, g.material);
  EXPECT_TRUE(r.size_class == g.size_class);
  EXPECT_EQ(rf.surface_height_m, f.surface_height_m);
  EXPECT_EQ(rf.time_s, f.time_s);
  EXPECT_EQ(rf.bed_key_json, f.bed_key_json);
  EXPECT_EQ(rf.report_json, f.report_json);
  // No temporary left behind.
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path)) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 1);
  // A bed file holds grains only.
  Particles with_projectile = g;
  with_projectile.add(Vec3(0, 0, 0.3), 0.02, 0.1, 2, SizeClass::projectile);
  EXPECT_THROW(results::write_bed(dir.path / "not_a_bed.h5", with_projectile, f), std::invalid_argument);
}

// A bed is kept and shared by many drops: its larger arrays are deflated (chunked, shuffled), as
// they were before its layout became one visit function; a checkpoint's stay contiguous.
TEST(Hdf5Io, ABedsLargeArraysAreStoredCompressed) {
  test::TempDir dir;
  Particles g = sample_grains();
  for (int i = 0; i < 3000; ++i)  // 3,005 grains: (3005, 3) positions, 9,015 values
    g.add(Vec3(0.001 * (i % 100), 0.01, 0.02), 0.005, 1.3e-3, 0, SizeClass::grain);
  results::write_bed(dir.path / "bed.h5", g, sample_facts());
  auto f = results::h5::File::open_read(dir.path / "bed.h5");
  auto grains = results::h5::open_group(f.id(), "grains");
  for (const char* name : {"position_m", "velocity_m_s", "omega_rad_s"}) {  // 4,096 values or more
    const hid_t ds = H5Dopen2(grains, name, H5P_DEFAULT);
    ASSERT_GE(ds, 0) << name;
    const hid_t plist = H5Dget_create_plist(ds);
    EXPECT_EQ(H5Pget_layout(plist), H5D_CHUNKED) << name;
    EXPECT_GE(H5Pget_nfilters(plist), 2) << name << ": shuffle and deflate";
    H5Pclose(plist);
    H5Dclose(ds);
  }
  Particles back;
  results::read_bed(dir.path / "bed.h5", back);
  EXPECT_TRUE(back.position_m == g.position_m);
}

TEST(Hdf5Io, EveryDatasetHasUnits) {
  test::TempDir dir;
  results::write_bed(dir.path / "bed.h5", sample_grains(), sample_facts());
  results::write_trace(dir.path / "trace.h5", sample_trace());
  {
    auto f = results::h5::File::open_read(dir.path / "bed.h5");
    auto g = results::h5::open_group(f.id(), "grains");
    EXPECT_EQ(results::h5::dataset_units(g, "position_m"), "m");
    EXPECT_EQ(results::h5::dataset_units(g, "velocity_m_s"), "m/s");
    EXPECT_EQ(results::h5::dataset_units(g, "omega_rad_s"), "rad/s");
    EXPECT_EQ(results::h5::dataset_units(g, "mass_kg"), "kg");
    EXPECT_EQ(results::h5::dataset_units(g, "material"), "1");
  }
  auto f = results::h5::File::open_read(dir.path / "trace.h5");
  auto g = results::h5::open_group(f.id(), "trace");
  EXPECT_EQ(results::h5::dataset_units(g, "t_s"), "s");
  EXPECT_EQ(results::h5::dataset_units(g, "depth_m"), "m");
  EXPECT_EQ(results::h5::dataset_units(g, "velocity_down_m_s"), "m/s");
  EXPECT_EQ(results::h5::dataset_units(g, "accel_up_m_s2"), "m/s2");
  EXPECT_EQ(results::h5::dataset_units(g, "grain_kinetic_energy_J"), "J");
  EXPECT_EQ(results::h5::dataset_units(g, "contacts"), "1");
  EXPECT_DOUBLE_EQ(results::h5::get_attr_double(g, "sample_rate_hz"), 1e4);
}

TEST(Hdf5Io, TraceRoundTripFeedsTheMetrics) {
  test::TempDir dir;
  const auto d = sample_trace();
  results::write_trace(dir.path / "trace.h5", d);
  const auto r = results::read_trace(dir.path / "trace.h5");
  EXPECT_EQ(r.raw.depth_m, d.raw.depth_m);
  EXPECT_EQ(r.contacts, d.contacts);
  EXPECT_EQ(r.metrics_json, d.metrics_json);
  EXPECT_TRUE(r.stopped);
  const results::Trace& t = r.raw;  // the processing's Trace, the record's own
  EXPECT_EQ(t.source, results::TraceSource::dem);
  EXPECT_EQ(r.info.source, results::TraceSource::dem);
  EXPECT_EQ(r.info.sample_rate_hz, 1e4);  // a trial fact, read where the trial holds it
  // The engine's first contact, read back from the contacts: sample 10 is the first that counts
  // one, so the collision starts at the sample before it.
  ASSERT_TRUE(t.contact_start_s.has_value());
  EXPECT_DOUBLE_EQ(*t.contact_start_s, d.raw.t_s[9]);
  EXPECT_EQ(t.accel_up_m_s2, d.raw.accel_up_m_s2);
  EXPECT_EQ(t.velocity_down_m_s, d.raw.velocity_down_m_s);
}

// trace.h5 keeps format version 1's layout, whichever part of the record holds a field: the same
// names in the same order, the trial's facts written from the record's trial part and read back
// into it (surface_height_m is the trial's fill height, written once more as fill_height_m).
TEST(Hdf5Io, TheTraceTablesKeepFormatVersion1sNamesOrderAndValues) {
  std::vector<std::string> texts, attributes, columns;
  for (const auto& t : results::trace_texts()) texts.emplace_back(t.name);
  for (const auto& a : results::trace_attributes()) attributes.emplace_back(a.name);
  for (const auto& c : results::trace_columns()) columns.emplace_back(c.name);
  EXPECT_EQ(texts, (std::vector<std::string>{"code_version", "scenario", "bed_key", "bed_file", "metrics"}));
  EXPECT_EQ(attributes, (std::vector<std::string>{"sample_rate_hz", "dt_s", "gravity_m_s2", "surface_height_m",
                                                  "release_height_m", "release_speed_m_s", "projectile_diameter_m",
                                                  "projectile_mass_kg", "grain_diameter_m"}));
  EXPECT_EQ(columns, (std::vector<std::string>{"t_s", "depth_m", "velocity_down_m_s", "accel_up_m_s2", "omega_rad_s",
                                               "position_m", "grain_kinetic_energy_J"}));
  test::TempDir dir;
  results::TraceData d = sample_trace();
  d.info.fill_height_m = 0.0625;
  d.info.projectile_diameter_m = 0.04;
  d.info.projectile_mass_kg = 0.25;
  d.info.grain_diameter_m = 0.01;
  d.info.code_version = "v1";
  d.release_height_m = 0.125;
  results::write_trace(dir.path / "trace.h5", d);
  {
    auto f = results::h5::File::open_read(dir.path / "trace.h5");
    EXPECT_EQ(results::h5::get_attr_string(f.id(), "code_version"), "v1");
    auto g = results::h5::open_group(f.id(), "trace");
    EXPECT_EQ(results::h5::get_attr_double(g, "surface_height_m"), 0.0625);
    EXPECT_EQ(results::h5::get_attr_double(g, "fill_height_m"), 0.0625);
    EXPECT_EQ(results::h5::get_attr_double(g, "projectile_mass_kg"), 0.25);
    EXPECT_EQ(results::h5::get_attr_double(g, "release_height_m"), 0.125);
  }
  const results::TraceData r = results::read_trace(dir.path / "trace.h5");
  EXPECT_EQ(r.info.fill_height_m, 0.0625);
  EXPECT_EQ(r.info.projectile_diameter_m, 0.04);
  EXPECT_EQ(r.info.projectile_mass_kg, 0.25);
  EXPECT_EQ(r.info.grain_diameter_m, 0.01);
  EXPECT_EQ(r.info.gravity_m_s2, 9.81);
  EXPECT_EQ(r.info.code_version, "v1");
  EXPECT_EQ(r.release_height_m, 0.125);
  EXPECT_EQ(r.raw.t_s, d.raw.t_s);
  EXPECT_EQ(r.grain_kinetic_energy_J, d.grain_kinetic_energy_J);
}

TEST(Hdf5Io, ErrorsNameTheFileAndTheMissingPiece) {
  test::TempDir dir;
  std::ofstream(dir.path / "not.h5") << "plain text";
  try {
    results::read_bed(dir.path / "not.h5");
    FAIL();
  } catch (const results::h5::H5Error& e) {
    EXPECT_NE(std::string(e.what()).find("not.h5"), std::string::npos) << e.what();
  }
  // A trace is not a bed.
  results::write_trace(dir.path / "trace.h5", sample_trace());
  try {
    results::read_bed(dir.path / "trace.h5");
    FAIL();
  } catch (const results::h5::H5Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a gravsweep bed"), std::string::npos) << e.what();
  }
  // Missing dataset.
  {
    auto f = results::h5::File::create(dir.path / "partial.h5");
    auto g = results::h5::create_group(f.id(), "trace");
    EXPECT_THROW(results::h5::read_doubles(g, "depth_m"), results::h5::H5Error);
    try {
      results::h5::read_doubles(g, "depth_m");
    } catch (const results::h5::H5Error& e) {
      EXPECT_NE(std::string(e.what()).find("partial.h5"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("depth_m"), std::string::npos) << e.what();
    }
  }
  // Writing into a missing folder fails cleanly.
  EXPECT_THROW(results::write_bed(dir.path / "no" / "bed.h5", sample_grains(), sample_facts()), results::h5::H5Error);
}

TEST(Hdf5Io, ReadableWithH5py) {
  const char* py = "/usr/bin/python3";
  if (std::system("/usr/bin/python3 -c 'import h5py' 2>/dev/null") != 0)
    GTEST_SKIP() << "python3-h5py (deploy/debian-packages.txt) is not installed";
  test::TempDir dir;
  results::write_bed(dir.path / "bed.h5", sample_grains(), sample_facts());
  results::write_trace(dir.path / "trace.h5", sample_trace());
  const std::string cmd = std::string(py) + " -c \"import h5py, json; b = h5py.File('" +
                          (dir.path / "bed.h5").string() + "'); t = h5py.File('" + (dir.path / "trace.h5").string() +
                          "'); print(b['grains/position_m'].shape, b['grains/position_m'].attrs['units'], "
                          "json.loads(b.attrs['report'])['grains_kept'], t['trace/depth_m'].attrs['units'], "
                          "t['trace'].attrs['sample_rate_hz'], json.loads(t.attrs['metrics'])['zstop_m'])\"";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  ASSERT_TRUE(pipe);
  std::array<char, 512> buf{};
  std::string out;
  while (fgets(buf.data(), buf.size(), pipe.get())) out += buf.data();
  EXPECT_EQ(out, "(5, 3) m 5 m 10000.0 0.03\n");
}

}  // namespace
}  // namespace gravsweep
