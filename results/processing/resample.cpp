#include "results/processing/resample.h"

#include <stdexcept>

#include "results/processing/trace.h"

namespace gravsweep::results {

std::vector<double> every_nth(const std::vector<double>& x, std::size_t step) {
  if (step == 0) throw std::invalid_argument("every_nth: step must be >= 1");
  std::vector<double> y;
  y.reserve(x.size() / step + 1);
  for (std::size_t i = 0; i < x.size(); i += step) y.push_back(x[i]);
  return y;
}

std::vector<double> decimate(const std::vector<double>& x, double sample_rate_hz, std::size_t step) {
  if (step <= 1) return x;
  const double cutoff_hz = kAntiAliasFraction * sample_rate_hz / static_cast<double>(step);
  return every_nth(butterworth_lowpass(x, sample_rate_hz, cutoff_hz, kAntiAliasOrder), step);
}

}  // namespace gravsweep::results
