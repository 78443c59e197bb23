// Two trace.h5 files compared column by column, value for value: the check that a resumed drop
// (from a checkpoint, in a test of the engine's job or of a campaign) ran the same drop.
#pragma once
#include <gtest/gtest.h>

#include <filesystem>

#include "results/io/trace_file.h"

namespace gravsweep::test {

/// Every sampled column of two traces, value for value (== on doubles: bit-identical but for
/// -0/+0). Fatal (ASSERT) only on different lengths; wrap a call in EXPECT_NO_FATAL_FAILURE.
inline void expect_same_trace_columns(const std::filesystem::path& a_path, const std::filesystem::path& b_path) {
  const results::TraceData a = results::read_trace(a_path), b = results::read_trace(b_path);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.raw.t_s, b.raw.t_s);
  EXPECT_EQ(a.raw.depth_m, b.raw.depth_m);
  EXPECT_EQ(a.raw.velocity_down_m_s, b.raw.velocity_down_m_s);
  EXPECT_EQ(a.raw.accel_up_m_s2, b.raw.accel_up_m_s2);
  EXPECT_EQ(a.omega_rad_s, b.omega_rad_s);
  EXPECT_EQ(a.position_m, b.position_m);
  EXPECT_EQ(a.contacts, b.contacts);
  EXPECT_EQ(a.grain_kinetic_energy_J, b.grain_kinetic_energy_J);
}

}  // namespace gravsweep::test
