// Distribution functions (see stats.h).
#include "results/model/stats.h"

#include <algorithm>
#include <cmath>

#include <cmath>
#include <limits>

namespace gravsweep::results {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kMaxTerms = 500;
constexpr double kRelTolerance = 1e-14;
constexpr double kTiny = 1e-300;  ///< Lentz's guard against a zero denominator

/// The continued fraction of A&S 26.5.8 for I_x(a, b), without its prefactor.
double beta_fraction(double a, double b, double x) {
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= kMaxTerms; ++m) {
    const double m2 = 2.0 * m;
    // Even step: d_{2m} = m (b - m) x / ((a + 2m - 1)(a + 2m)).
    double num = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
    d = 1.0 + num * d;
    c = 1.0 + num / c;
    if (std::abs(d) < kTiny) d = kTiny;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    // Odd step: d_{2m+1} = -(a + m)(a + b + m) x / ((a + 2m)(a + 2m + 1)).
    num = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
    d = 1.0 + num * d;
    c = 1.0 + num / c;
    if (std::abs(d) < kTiny) d = kTiny;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double step = d * c;
    h *= step;
    if (std::abs(step - 1.0) < kRelTolerance) break;
  }
  return h;
}

}  // namespace

double regularized_beta(double a, double b, double x) {
  if (!(a > 0) || !(b > 0) || !(x >= 0) || !(x <= 1)) return kNaN;
  if (x == 0.0 || x == 1.0) return x;
  const double log_front = std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x);
  if (x < (a + 1.0) / (a + b + 2.0)) return std::exp(log_front) * beta_fraction(a, b, x) / a;
  return 1.0 - std::exp(log_front) * beta_fraction(b, a, 1.0 - x) / b;
}

double f_upper_p(double f, double d1, double d2) {
  if (!(d1 > 0) || !(d2 > 0)) return kNaN;
  if (!(f > 0)) return 1.0;
  return regularized_beta(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f));
}

double quantile(std::vector<double> v, double q) {
  std::erase_if(v, [](double x) { return !std::isfinite(x); });
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double at = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(at));
  const auto hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (at - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

double weighted_quantile(const std::vector<double>& v, const std::vector<double>& w, double q) {
  std::vector<std::size_t> order;
  double total = 0;
  for (std::size_t i = 0; i < v.size() && i < w.size(); ++i)
    if (std::isfinite(v[i]) && w[i] > 0) {
      order.push_back(i);
      total += w[i];
    }
  if (order.empty() || !(total > 0)) return NAN;
  std::sort(order.begin(), order.end(), [&v](std::size_t a, std::size_t b) { return v[a] < v[b]; });
  // Each value sits at the middle of its weight's share of [0, total].
  double below = 0, prev_pos = NAN, prev_v = NAN;
  const double target = q * total;
  for (const std::size_t i : order) {
    const double pos = below + 0.5 * w[i];
    if (pos >= target) {
      if (std::isnan(prev_pos)) return v[i];
      return prev_v + (v[i] - prev_v) * (target - prev_pos) / (pos - prev_pos);
    }
    below += w[i];
    prev_pos = pos;
    prev_v = v[i];
  }
  return prev_v;
}

std::vector<int> resample_within(const std::vector<std::vector<std::size_t>>& groups, std::size_t n,
                                 std::mt19937& rng) {
  std::vector<int> count(n, 0);
  for (const auto& g : groups) {
    if (g.empty()) continue;
    std::uniform_int_distribution<std::size_t> pick(0, g.size() - 1);
    for (std::size_t k = 0; k < g.size(); ++k) ++count[g[pick(rng)]];
  }
  return count;
}

}  // namespace gravsweep::results
