#include "scheduler/cli/bench_checkpoint.h"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>

#include "results/io/checkpoint_file.h"

namespace gravsweep::cli {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Bytes of the samples' columns (what a checkpoint stores of them, besides HDF5's headers).
std::size_t column_bytes(const DropSamples& s) {
  std::size_t doubles = 0;
  for (const auto* c : {&s.t_s, &s.depth_m, &s.velocity_down_m_s, &s.accel_up_m_s2, &s.omega_rad_s, &s.position_m,
                        &s.grain_kinetic_energy_J})
    doubles += c->size();
  return doubles * sizeof(double) + s.contacts.size() * sizeof(std::int32_t);
}

}  // namespace

void print_checkpoint_cost(const System& sys, const std::filesystem::path& dir, std::size_t samples) {
  const std::filesystem::path file = dir / fmt::format("bench-{}.ckpt.h5", static_cast<long>(::getpid()));
  auto t0 = std::chrono::steady_clock::now();
  results::CheckpointData c;
  DropState drop{sys.save_state(), {}};
  drop.loop.result.samples.resize(samples);  // the trace so far: a drop of samples / rate seconds
  drop.loop.samples_done = static_cast<long long>(samples) - 1;
  const std::size_t sample_bytes = column_bytes(drop.loop.result.samples);
  c.state = std::move(drop);
  const double save_s = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  results::write_checkpoint(file, c);
  const double write_s = seconds_since(t0);
  const auto bytes = static_cast<double>(std::filesystem::file_size(file));
  t0 = std::chrono::steady_clock::now();
  results::CheckpointData back = results::read_checkpoint(file);
  const double read_s = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  System fresh(sys.config());
  fresh.walls = sys.walls;
  fresh.restore_state(std::get<DropState>(std::move(back.state)).system);
  const double restore_s = seconds_since(t0);
  std::filesystem::remove(file);
  const double n = static_cast<double>(sys.particles.size());
  fmt::print(
      "\ncheckpoint of {} grains and {} trace samples in {}: {:.2f} MB, {:.0f} bytes per grain (without the samples, "
      "{} bytes each: {:.1f} MB), {} listed pairs, {} wall candidates\n"
      "  save_state {:.3f} s, write + fsync {:.3f} s, read + verify {:.3f} s, restore {:.3f} s\n",
      sys.particles.size(), samples, dir.string(), bytes / 1e6, (bytes - static_cast<double>(sample_bytes)) / n,
      samples > 0 ? sample_bytes / samples : 0, static_cast<double>(sample_bytes) / 1e6,
      c.drop()->system.list_neighbor.size(), c.drop()->system.wall_candidates.size(), save_s, write_s, read_s,
      restore_s);
}

}  // namespace gravsweep::cli
