// The host a `gravsweep bench` figure was measured on: CPU model, cores, load, and the memory
// bandwidth a STREAM-like triad reaches with each thread count (the engine's step streams its
// particle arrays, so a host's bandwidth bounds what a second thread can add).
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace gravsweep::cli {

struct HostReport {
  std::string cpu_model;  ///< /proc/cpuinfo "model name" ("unknown" when absent)
  unsigned cores = 0;     ///< processors the process may use (omp_get_num_procs: its affinity)
  double load_1min = -1;  ///< /proc/loadavg, -1 when unreadable
  /// {threads, triad GB/s}: a[i] = b[i] + s c[i] over three arrays of kTriadDoubles doubles,
  /// 24 bytes an element counted as STREAM does, the best of kTriadRounds.
  std::vector<std::pair<int, double>> triad_GB_s;
};

/// Doubles per triad array: 8 M (64 MB each, 192 MB in all), beyond any L3 of these hosts.
inline constexpr std::size_t kTriadDoubles = std::size_t{8} << 20;
inline constexpr int kTriadRounds = 5;

/// Reads the host and measures the triad with each of `threads` (about 1 s in all).
HostReport measure_host(const std::vector<int>& threads);
/// The report as "host: ..." lines.
void print_host(const HostReport& h);

}  // namespace gravsweep::cli
