#include "scheduler/cli/bench_host.h"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <fstream>
#include <memory>

namespace gravsweep::cli {

namespace {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto start = line.find_first_not_of(" \t", line.find(':') + 1);
      if (line.find(':') != std::string::npos && start != std::string::npos) return line.substr(start);
    }
  return "unknown";
}

double load_1min() {
  std::ifstream in("/proc/loadavg");
  double load = -1;
  in >> load;
  return in ? load : -1;
}

/// The best triad bandwidth (GB/s) with `threads` threads; the arrays are first touched by the
/// same static schedule, so each thread's pages sit where it runs.
double triad_GB_s(int threads) {
  const std::size_t n = kTriadDoubles;
  const std::unique_ptr<double[]> a(new double[n]), b(new double[n]), c(new double[n]);
  const auto ns = static_cast<long long>(n);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (long long i = 0; i < ns; ++i) a[i] = 0, b[i] = 1, c[i] = 2;
  constexpr double kScale = 3;
  double best_s = 1e30;
  for (int r = 0; r < kTriadRounds; ++r) {
    const double t0 = omp_get_wtime();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long i = 0; i < ns; ++i) a[i] = b[i] + kScale * c[i];
    best_s = std::min(best_s, omp_get_wtime() - t0);
  }
  if (a[n / 2] != 1 + kScale * 2) return 0;  // the loop ran (and the compiler kept it)
  return 3.0 * sizeof(double) * static_cast<double>(n) / best_s / 1e9;
}

}  // namespace

HostReport measure_host(const std::vector<int>& threads) {
  HostReport h;
  h.cpu_model = cpu_model();
  h.cores = static_cast<unsigned>(omp_get_num_procs());
  h.load_1min = load_1min();
  for (int t : threads) h.triad_GB_s.emplace_back(t, triad_GB_s(t));
  return h;
}

void print_host(const HostReport& h) {
  fmt::print("host: {}, {} hardware threads, load {:.2f} (1 min)\n", h.cpu_model, h.cores, h.load_1min);
  std::string bw;
  for (const auto& [t, gbs] : h.triad_GB_s)
    bw += fmt::format("{}{} thread{}: {:.1f} GB/s", bw.empty() ? "" : ", ", t, t == 1 ? "" : "s", gbs);
  fmt::print("host memory bandwidth (STREAM-like triad, {} MB arrays, best of {}): {}\n",
             kTriadDoubles * sizeof(double) >> 20, kTriadRounds, bw);
}

}  // namespace gravsweep::cli
