#include "scheduler/cli/progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gravsweep::cli {

std::string format_duration(double s) {
  if (!std::isfinite(s) || s < 0) return "--";
  if (s < 60) return fmt::format("{:.1f}s", s);
  const long t = std::lround(s);
  if (t < 3600) return fmt::format("{}m{:02}s", t / 60, t % 60);
  return fmt::format("{}h{:02}m", t / 3600, (t % 3600) / 60);
}

ProgressBar::ProgressBar(bool enabled) : enabled_(enabled), tty_(isatty(STDERR_FILENO) != 0) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(const std::string& phase, double fraction, const std::string& detail) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (phase != phase_) {
    if (open_line_) finish();
    phase_ = phase;
    phase_start_ = now;
    last_print_ = now - std::chrono::hours(1);
  }
  fraction = std::clamp(fraction, 0.0, 1.0);
  const double since_print = std::chrono::duration<double>(now - last_print_).count();
  if (tty_ ? since_print < 0.1 : since_print < 5.0) {
    if (fraction < 1.0) return;
  }
  last_print_ = now;
  const double elapsed = std::chrono::duration<double>(now - phase_start_).count();
  const double eta = fraction > 1e-3 ? elapsed * (1 - fraction) / fraction : NAN;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(std::lround(fraction * kWidth));
  const std::string bar = std::string(filled, '#') + std::string(kWidth - filled, '-');
  const std::string line = fmt::format("{:<8} [{}] {:5.1f}%  elapsed {:>7}  ETA {:>7}  {}", phase, bar, 100 * fraction,
                                       format_duration(elapsed), format_duration(eta), detail);
  if (tty_) {
    std::fprintf(stderr, "\r%-120s", line.c_str());
    open_line_ = true;
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (open_line_) {
    std::fprintf(stderr, "\n");
    open_line_ = false;
  }
}

}  // namespace gravsweep::cli
