// The steps of the paper's trace processing (Sunday et al. 2021 Sect. 2.3), see trace_steps.h.
#include "results/processing/trace_steps.h"

#include <fmt/format.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gravsweep::results::trace_steps {

double crossing_time(const std::vector<double>& t, const std::vector<double>& y, std::size_t i, double level) {
  const double dy = y[i + 1] - y[i];
  if (dy == 0.0) return t[i];
  const double f = std::clamp((level - y[i]) / dy, 0.0, 1.0);
  return t[i] + f * (t[i + 1] - t[i]);
}

double interp_at(const std::vector<double>& t, const std::vector<double>& y, double tq) {
  if (tq <= t.front()) return y.front();
  if (tq >= t.back()) return y.back();
  const auto it = std::upper_bound(t.begin(), t.end(), tq);
  const std::size_t j = static_cast<std::size_t>(it - t.begin());
  const std::size_t i = j - 1;
  const double f = (tq - t[i]) / (t[j] - t[i]);
  return y[i] + f * (y[j] - y[i]);
}

double mean_of(const std::vector<double>& x, std::size_t b, std::size_t e) {
  double s = 0;
  for (std::size_t i = b; i < e; ++i) s += x[i];
  return e > b ? s / static_cast<double>(e - b) : 0.0;
}

double stddev_of(const std::vector<double>& x, std::size_t b, std::size_t e) {
  if (e <= b + 1) return 0.0;
  const double m = mean_of(x, b, e);
  double s = 0;
  for (std::size_t i = b; i < e; ++i) s += (x[i] - m) * (x[i] - m);
  return std::sqrt(s / static_cast<double>(e - b - 1));
}

std::vector<double> filter_acceleration(const std::vector<double>& accel_up_m_s2, double fs, const MetricOptions& o,
                                        std::string& note) {
  if (o.cutoff_hz > 0 && o.cutoff_hz < 0.5 * fs)
    return butterworth_lowpass(accel_up_m_s2, fs, o.cutoff_hz, o.filter_order);
  note = fmt::format("not filtered: cut-off {} Hz is not below the Nyquist frequency {:.0f} Hz", o.cutoff_hz, 0.5 * fs);
  return accel_up_m_s2;
}

std::size_t edge_width(double fs_hz, double cutoff_hz) {
  return 1 + static_cast<std::size_t>(std::ceil(fs_hz / std::max(cutoff_hz, 1e-9)));
}

std::size_t contact_peak(const std::vector<double>& af, double g) {
  const std::size_t ipk = static_cast<std::size_t>(std::max_element(af.begin(), af.end()) - af.begin());
  if (af[ipk] < -0.5 * g)
    throw TraceError(fmt::format("the projectile never makes contact: the acceleration never rises above -g/2 "
                                 "(peak {:.3g} m/s2 at sample {} with g = {} m/s2)",
                                 af[ipk], ipk, g),
                     ipk);
  return ipk;
}

double initial_bias(const std::vector<double>& af, std::size_t ipk, double g) {
  const std::size_t head = std::clamp<std::size_t>(ipk / 3, 1, kFreeFallProbeSamples);
  std::vector<double> h(af.begin(), af.begin() + static_cast<std::ptrdiff_t>(head));
  std::nth_element(h.begin(), h.begin() + static_cast<std::ptrdiff_t>(h.size() / 2), h.end());
  return h[h.size() / 2] + g;
}

namespace {

double median_of(std::vector<double> x) {
  std::nth_element(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(x.size() / 2), x.end());
  return x[x.size() / 2];
}

}  // namespace

void check_starts_in_free_fall(const std::vector<double>& t, const std::vector<double>& af, std::size_t ipk, double g) {
  const std::size_t n = af.size();
  const std::size_t k = std::clamp<std::size_t>(ipk / 3, 1, kFreeFallProbeSamples);
  const double head = median_of({af.begin(), af.begin() + static_cast<std::ptrdiff_t>(k)});
  const double tail = median_of({af.end() - static_cast<std::ptrdiff_t>(std::min(k, n)), af.end()});
  if (head - tail > -kFreeFallMinDrop_g * g)
    throw TraceError(fmt::format("the record does not start in free fall: its first {} samples read {:.4g} m/s2 "
                                 "(median), its last {} {:.4g} m/s2; free fall reads g = {:.4g} m/s2 below rest "
                                 "(at least {} g below expected before the peak at t = {:.4f} s)",
                                 k, head, k, tail, g, kFreeFallMinDrop_g, t[ipk]),
                     0);
}

CollisionStart contact_start(const std::vector<double>& t, double t_contact_s) {
  const auto it = std::upper_bound(t.begin(), t.end(), t_contact_s);
  const std::size_t i = it == t.begin() ? 0 : static_cast<std::size_t>(it - t.begin()) - 1;
  return {i, t_contact_s, false};
}

double filter_step_rise_s(double fs_hz, const MetricOptions& o) {
  if (!(o.cutoff_hz > 0 && o.cutoff_hz < 0.5 * fs_hz)) return 0.8 / fs_hz;  // a jump between two samples
  const std::size_t half = 10 * edge_width(fs_hz, o.cutoff_hz);
  std::vector<double> x(2 * half, 0.0), t(2 * half);
  for (std::size_t i = 0; i < x.size(); ++i) {
    t[i] = static_cast<double>(i) / fs_hz;
    if (i >= half) x[i] = 1.0;
  }
  const std::vector<double> y = butterworth_lowpass(x, fs_hz, o.cutoff_hz, o.filter_order);
  // Up to its overshoot, as free_fall_start measures an edge.
  return rise_10_90_s(t, y, 0, y.size() - 1, 0.0, *std::max_element(y.begin(), y.end()));
}

double rise_10_90_s(const std::vector<double>& t, const std::vector<double>& y, std::size_t b, std::size_t e,
                    double foot, double top) {
  const double lo = foot + 0.1 * (top - foot), hi = foot + 0.9 * (top - foot);
  std::size_t k = b;
  while (k < e && y[k + 1] < lo) ++k;
  const double t_lo = k < e ? crossing_time(t, y, k, lo) : t[e];
  while (k < e && y[k + 1] < hi) ++k;
  const double t_hi = k < e ? crossing_time(t, y, k, hi) : t[e];
  return t_hi - t_lo;
}

CollisionStart free_fall_start(const std::vector<double>& t, const std::vector<double>& a, std::size_t ipk, double g,
                               double thr, std::size_t w, double step_rise_s) {
  const std::size_t n = t.size();
  std::size_t i = ipk;
  while (i > 0 && a[i] > -g + thr) --i;
  if (i == 0 && a[0] > -g + thr)
    throw TraceError("the record does not start in free fall (no sample reads -g before the peak)", 0);
  CollisionStart cs{i, crossing_time(t, a, i, -g + thr), false};
  // Height of the edge: the level reached 2w samples after the threshold crossing.
  const std::size_t k_hi = std::min(n - 1, i + 2 * w);
  const double top = *std::max_element(a.begin() + static_cast<std::ptrdiff_t>(i + 1),
                                       a.begin() + static_cast<std::ptrdiff_t>(k_hi + 1));
  if (!(top + g > 4.0 * thr)) return cs;
  const double half = -g + 0.5 * (top + g);
  std::size_t k = i;
  while (k < k_hi && a[k + 1] < half) ++k;
  if (k == k_hi) return cs;
  // The edge's own 10-90 % rise, the filter's taken out (rise times add in quadrature), is 0.8 of
  // a linear ramp's duration; the ramp starts half of that before its half height.
  const double rise = rise_10_90_s(t, a, i, k_hi, -g, top);
  const double ramp_s = std::sqrt(std::max(0.0, rise * rise - step_rise_s * step_rise_s)) / 0.8;
  double t_onset = crossing_time(t, a, k, half) - 0.5 * ramp_s;
  const bool step = ramp_s <= kStepRampRises * step_rise_s;
  if (!step) {
    // Slower than the filter: the threshold crossing lags the ramp's foot by thr over its slope
    // (in high gravity g times that lag, carried through the integration, is several %
    // of a slow impact's zstop). The ramp extrapolated back to -g from its crossings of 20 and
    // 40 % of its height (at least thr and 2 thr), above the foot that the filter rounds.
    const double d1 = std::max(thr, 0.2 * (top + g)), d2 = std::max(2.0 * thr, 0.4 * (top + g));
    std::size_t k1 = i;
    while (k1 < k_hi && a[k1 + 1] < -g + d1) ++k1;
    std::size_t k2 = k1;
    while (k2 < k_hi && a[k2 + 1] < -g + d2) ++k2;
    const double t1 = crossing_time(t, a, k1, -g + d1), t2 = crossing_time(t, a, k2, -g + d2);
    t_onset = t1 - (t2 - t1) * d1 / (d2 - d1);
    // The filter rounds the foot, so the threshold may be crossed a little before it; beyond half
    // the filter's rise either way, or more than an edge width back, it is not a ramp out of free fall.
    if (i < w || t_onset < t[i - w] || t_onset > cs.t_start_s + 0.5 * step_rise_s) return cs;
  } else if (t_onset <= cs.t_start_s) {
    return cs;
  }
  std::size_t j = step ? k : i;
  while (j > 0 && t[j] > t_onset) --j;
  return {j, t_onset, step};
}

std::size_t end_hold_samples(double fs_hz, double hold_s) {
  return std::max<std::size_t>(3, static_cast<std::size_t>(std::ceil(hold_s * fs_hz)));
}

DepthEnd depth_end(const std::vector<double>& t, const std::vector<double>& z, std::size_t i_start, std::size_t i_last,
                   double fraction) {
  const std::size_t last = std::min(i_last, z.size() - 1);
  std::size_t i_max = i_start;
  for (std::size_t k = i_start; k <= last; ++k)
    if (z[k] > z[i_max]) i_max = k;
  const double level = fraction * z[i_max];
  std::size_t k = i_start;
  while (k < i_max && z[k + 1] < level) ++k;
  if (k >= i_max) return {i_max, t[i_max]};
  return {k + 1, crossing_time(t, z, k, level)};
}

std::optional<std::size_t> end_sample(const std::vector<double>& a, std::size_t ipk, const EndCriteria& c) {
  const std::size_t n = a.size();
  for (std::size_t j = ipk; j < n; ++j) {
    if (c.speed && (*c.speed)[j] > c.v_end_m_s) continue;
    bool stays = true;
    for (std::size_t k = j; k < std::min(n, j + c.hold); ++k) stays = stays && a[k] < c.end_level_m_s2;
    if (stays && j + std::min<std::size_t>(c.hold, 3) <= n) return j;
  }
  return std::nullopt;
}

double robust_sigma(const std::vector<double>& x, std::size_t b, std::size_t e) {
  if (e < b + 3) return 0.0;
  constexpr double kMadToSigma = 1.4826;  // 1 / Phi^-1(3/4)
  const double med =
      median_of({x.begin() + static_cast<std::ptrdiff_t>(b), x.begin() + static_cast<std::ptrdiff_t>(e)});
  std::vector<double> dev;
  dev.reserve(e - b);
  for (std::size_t i = b; i < e; ++i) dev.push_back(std::abs(x[i] - med));
  return kMadToSigma * median_of(std::move(dev));
}

double end_level(double end_threshold_g, double g, double noise_sigma) {
  return std::max(end_threshold_g * g, kEndNoiseSigmas * noise_sigma);
}

double record_noise(const std::vector<double>& af, std::size_t ff_end) {
  constexpr std::size_t kMinFreeFall = 5;
  if (ff_end >= kMinFreeFall) return robust_sigma(af, 0, std::min(ff_end, af.size()));
  return robust_sigma(af, af.size() - af.size() / 4, af.size());
}

std::optional<std::size_t> last_exceedance_end(const std::vector<double>& a, std::size_t ipk, double level,
                                               std::size_t hold) {
  const std::size_t n = a.size();
  std::size_t j = n;
  while (j > ipk + 1 && a[j - 1] < level) --j;
  if (n - j < hold) return std::nullopt;
  return j;
}

CollisionEnd end_edge(const std::vector<double>& t, const std::vector<double>& a, std::size_t j, std::size_t i_start,
                      std::size_t w, double end_level) {
  CollisionEnd e{j, j > 0 ? crossing_time(t, a, j - 1, end_level) : t[j], false};
  if (j > w + 1 && j - w - 1 > i_start) {
    // Level before the edge; a fall to half of it within w samples before j is a step.
    const double pre = a[j - w - 1];
    if (pre > 2.0 * end_level) {
      std::size_t k = j - w - 1;
      while (k + 1 < j && a[k + 1] > 0.5 * pre) ++k;
      if (k + 1 <= j) {
        e.step = true;
        e.t_end_s = crossing_time(t, a, k, 0.5 * pre);
        e.step_height_m_s2 = pre;
      }
    }
  }
  return e;
}

std::size_t rest_begin(std::size_t i_end, std::size_t w, std::size_t n) {
  const std::size_t after = std::min(n, i_end + w + 1);
  return after + (n - after) / 4;
}

BiasEstimate bias_from_segments(const std::vector<double>& af, double g, std::size_t ff_end, std::size_t rb) {
  const std::size_t n = af.size();
  BiasEstimate b;
  b.free_fall_samples = ff_end;
  b.rest_samples = n - rb;
  double b_sum = 0, w_sum = 0;
  if (b.free_fall_samples >= 3) {
    b_sum += static_cast<double>(ff_end) * (mean_of(af, 0, ff_end) + g);
    w_sum += static_cast<double>(ff_end);
    b.sigma_free_fall_m_s2 = stddev_of(af, 0, ff_end);
  }
  if (b.rest_samples >= kMinRestSamples) {
    b_sum += static_cast<double>(b.rest_samples) * mean_of(af, rb, n);
    w_sum += static_cast<double>(b.rest_samples);
  }
  b.any = w_sum > 0;
  if (b.any) b.bias_m_s2 = b_sum / w_sum;
  return b;
}

void integrate_from_start(const std::vector<double>& t, const std::vector<double>& a, std::size_t i_start,
                          double t_start, double v0, std::vector<double>& v, std::vector<double>& z) {
  const std::size_t n = t.size();
  v.assign(n, 0.0);
  z.assign(n, 0.0);
  const std::size_t i0 = std::min(n - 1, i_start + 1);  // first sample after t_start
  const double dt0 = t[i0] - t_start;
  const double a_start = interp_at(t, a, t_start);
  v[i0] = v0 - 0.5 * (a_start + a[i0]) * dt0;
  z[i0] = 0.5 * (v0 + v[i0]) * dt0;
  for (std::size_t k = i0 + 1; k < n; ++k) {
    const double dt = t[k] - t[k - 1];
    v[k] = v[k - 1] - 0.5 * (a[k] + a[k - 1]) * dt;
    z[k] = z[k - 1] + 0.5 * (v[k] + v[k - 1]) * dt;
  }
  for (std::size_t k = i0; k-- > 0;) {
    const double dt = t[k + 1] - t[k];
    v[k] = v[k + 1] + 0.5 * (a[k] + a[k + 1]) * dt;
    z[k] = z[k + 1] - 0.5 * (v[k] + v[k + 1]) * dt;
  }
}

double bring_to_rest(const std::vector<double>& t, std::size_t rb, double t_start, double end_tolerance,
                     std::vector<double>& v, std::vector<double>& z) {
  const std::size_t n = v.size();
  if (rb + kMinRestSamples > n) return 0.0;
  const double reading = mean_of(v, rb, n);
  const double c = std::copysign(std::max(0.0, std::abs(reading) - end_tolerance), reading);
  for (std::size_t k = 0; k < n; ++k) {
    v[k] -= c;
    z[k] -= c * (t[k] - t_start);
  }
  return c;
}

double peak_acceleration(const std::vector<double>& a, const std::vector<double>& v, std::size_t i_start,
                         std::size_t i_end, bool step_start, bool step_end, std::size_t w, double vc, double g) {
  // (a = c0 + c1 v^2 is exact for Eq. 1 with f = f0, h = m/d1, and the a-vs-v^2 view of
  // Katsuragi & Durian 2007 near the surface for the other laws.)
  const std::size_t n = a.size();
  std::size_t lo = i_start + 1, hi = std::min(n - 1, i_end);
  if (step_start) lo = std::min(hi, i_start + 1 + 2 * w);  // filtfilt rings ~2w samples
  // The line in v^2 only on samples clear of the end's ringing too: a collision too short for
  // that (a slow impact at 1 g, a dozen samples) extrapolated the stop's ringing to 9 g.
  const bool clear_of_end = !step_end || hi > lo + 2 * w;
  if (step_end && hi > lo + 2 * w) hi -= 2 * w;
  double peak = -g;
  for (std::size_t k = lo; k <= hi; ++k) peak = std::max(peak, a[k]);
  if (step_start && clear_of_end && hi >= lo + 4) {
    const std::size_t k1 = std::min(hi, lo + 3 * w + 2);
    Eigen::MatrixXd X(static_cast<Eigen::Index>(k1 - lo + 1), 2);
    Eigen::VectorXd y(X.rows());
    for (std::size_t k = lo; k <= k1; ++k) {
      const auto r = static_cast<Eigen::Index>(k - lo);
      X(r, 0) = 1.0;
      X(r, 1) = v[k] * v[k];
      y(r) = a[k];
    }
    const Eigen::Vector2d c = X.colPivHouseholderQr().solve(y);
    if (std::isfinite(c(0)) && std::isfinite(c(1))) peak = std::max(peak, c(0) + c(1) * vc * vc);
  }
  return peak;
}

Rebound rebound_of(const std::vector<double>& v, const std::vector<double>& z, std::size_t i_start, std::size_t i_end,
                   std::size_t i_last_depth, double vc, const MetricOptions& o) {
  Rebound r;
  const std::size_t last = std::min(v.size() - 1, i_end);
  double vmin = 0;
  for (std::size_t k = i_start; k <= last; ++k) vmin = std::min(vmin, v[k]);
  r.i_max_depth = i_start;
  for (std::size_t k = i_start; k <= std::min(z.size() - 1, i_last_depth); ++k)
    if (z[k] > z[r.i_max_depth]) r.i_max_depth = k;
  r.max_depth_m = z[r.i_max_depth];
  // The one rule: back up by more than kReboundRiseFraction of the deepest point, at any time
  // after it (a bounce off the floor that falls back in still rose).
  double z_after_min = r.max_depth_m;
  for (std::size_t k = r.i_max_depth; k < z.size(); ++k) z_after_min = std::min(z_after_min, z[k]);
  const double rise_m = r.max_depth_m - z_after_min;
  auto add = [&](const std::string& s) { r.note += (r.note.empty() ? "" : "; ") + s; };
  if (r.max_depth_m > 0 && rise_m > kReboundRiseFraction * r.max_depth_m) {
    r.rebound = true;
    add(fmt::format("rose {:.4f} m back up from its deepest point {:.4f} m", rise_m, r.max_depth_m));
  }
  if (vmin < -std::max(0.1 * vc, 0.01)) add(fmt::format("moved up at {:.3f} m/s", -vmin));
  if (o.fill_height_m) {
    const double grain = o.grain_diameter_m.value_or(0.0);
    if (r.max_depth_m >= *o.fill_height_m - grain)
      add(fmt::format("reached {:.3f} m, within one grain of the floor at {:.3f} m", r.max_depth_m, *o.fill_height_m));
  }
  return r;
}

}  // namespace gravsweep::results::trace_steps
