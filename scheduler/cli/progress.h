// A progress bar with phase name and ETA for long work. On a terminal it redraws one line on
// stderr; otherwise (logs, CI) it prints a line at most every few seconds.
#pragma once
#include <chrono>
#include <string>

namespace gravsweep::cli {

class ProgressBar {
 public:
  explicit ProgressBar(bool enabled = true);
  ~ProgressBar();
  /// fraction in [0, 1] of the current phase; a new phase name restarts the ETA clock.
  void update(const std::string& phase, double fraction, const std::string& detail = "");
  /// Ends the current line.
  void finish();

 private:
  bool enabled_;
  bool tty_;
  std::string phase_;
  std::chrono::steady_clock::time_point phase_start_, last_print_;
  bool open_line_ = false;
};

/// "1h02m", "3m05s", "12.3s"
std::string format_duration(double seconds);

}  // namespace gravsweep::cli
