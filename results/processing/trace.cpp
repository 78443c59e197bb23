// The paper's processing of a projectile trace (Sunday et al. 2021 Sect. 2.3): 2nd-order
// Butterworth low-pass at 500 Hz, collision start = no longer in free fall, collision end =
// acceleration below 0.1 g (and the speed below 10 % of vc, see MetricOptions), velocity and
// depth by integrating the acceleration from the impact speed, and the metrics vc, apeak, zstop,
// tstop. Conventions in trace.h (z down, a up).
#include "results/processing/trace.h"

#include <fmt/format.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace gravsweep::results {

namespace {

/// One section of a cascaded IIR filter, transposed direct form II, a0 normalised to 1.
struct Section {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0;

  /// Runs the section over x in place, starting from the steady state of a constant input x[0]
  /// (unit DC gain, so the output starts at x[0] too and no start-up transient appears).
  void run(std::vector<double>& x) const {
    if (x.empty()) return;
    const double c = x.front();
    double z2 = c * (b2 - a2);
    double z1 = c * (b1 - a1) + z2;
    for (double& xi : x) {
      const double in = xi;
      const double y = b0 * in + z1;
      z1 = b1 * in - a1 * y + z2;
      z2 = b2 * in - a2 * y;
      xi = y;
    }
  }
};

/// Butterworth low-pass of order n by the bilinear transform with pre-warping:
/// analog prototype poles s_k = exp(i pi (2k + n - 1) / (2n)), grouped in conjugate pairs
/// 1 / (s^2 + 2 zeta_k s + 1) with zeta_k = sin(pi (2k - 1) / (2n)), plus 1 / (s + 1) for odd n;
/// s -> (1 - 1/z) / (K (1 + 1/z)) with K = tan(pi fc / fs).
std::vector<Section> butterworth_sections(double fs, double fc, int order) {
  const double K = std::tan(std::numbers::pi * fc / fs);
  const double K2 = K * K;
  std::vector<Section> s;
  for (int k = 1; k <= order / 2; ++k) {
    const double two_zeta = 2.0 * std::sin(std::numbers::pi * (2.0 * k - 1.0) / (2.0 * order));
    const double a0 = 1.0 + two_zeta * K + K2;
    Section q;
    q.b0 = K2 / a0;
    q.b1 = 2.0 * q.b0;
    q.b2 = q.b0;
    q.a1 = 2.0 * (K2 - 1.0) / a0;
    q.a2 = (1.0 - two_zeta * K + K2) / a0;
    s.push_back(q);
  }
  if (order % 2 == 1) {
    Section q;
    q.b0 = K / (1.0 + K);
    q.b1 = q.b0;
    q.a1 = (K - 1.0) / (K + 1.0);
    s.push_back(q);
  }
  return s;
}

/// Linear interpolation of the time where y crosses `level` between samples i and i + 1.
double crossing_time(const std::vector<double>& t, const std::vector<double>& y, std::size_t i,
                     double level) {
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

/// Velocity (positive down) and depth from the acceleration (positive up), dv_down/dt = -a_up, by
/// trapezoids both ways from the collision start (v = v0, z = 0 at t_start, between samples
/// i_start and i_start + 1).
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

/// The collision start: the last sample before it and its time, and whether it is a step edge
/// (faster than the filter, located at half height).
struct CollisionStart {
  std::size_t i_start = 0;
  double t_start_s = 0;
  bool step = false;
};

/// DEM records: the engine's first contact (Trace::contact_start_s).
CollisionStart contact_start(const std::vector<double>& t, double t_contact_s) {
  const auto it = std::upper_bound(t.begin(), t.end(), t_contact_s);
  const std::size_t i = it == t.begin() ? 0 : static_cast<std::size_t>(it - t.begin()) - 1;
  return {i, t_contact_s, false};
}

/// The paper's rule (Sect. 2.3): the last sample before the peak ipk still within the free-fall
/// band -g + thr; a step edge (rising within the edge width w) is located at its half height.
CollisionStart free_fall_start(const std::vector<double>& t, const std::vector<double>& a,
                               std::size_t ipk, double g, double thr, std::size_t w) {
  const std::size_t n = t.size();
  std::size_t i = ipk;
  while (i > 0 && a[i] > -g + thr) --i;
  if (i == 0 && a[0] > -g + thr)
    throw std::invalid_argument(
        "the record does not start in free fall (no sample reads -g before the peak)");
  CollisionStart cs{i, crossing_time(t, a, i, -g + thr), false};
  // Height of the edge: the level reached 2w samples after the threshold crossing.
  const std::size_t k_hi = std::min(n - 1, i + 2 * w);
  const double top = *std::max_element(a.begin() + static_cast<std::ptrdiff_t>(i + 1),
                                       a.begin() + static_cast<std::ptrdiff_t>(k_hi + 1));
  const double half = -g + 0.5 * (top + g);
  std::size_t k = i;
  while (k < k_hi && a[k + 1] < half) ++k;
  if (k < k_hi && k + 1 <= i + w && top + g > 4.0 * thr) cs = {k, crossing_time(t, a, k, half), true};
  return cs;
}

void validate(const Trace& tr) {
  const std::size_t n = tr.t_s.size();
  if (tr.accel_up_m_s2.size() != n)
    throw std::invalid_argument(fmt::format("accel_m_s2 has {} samples but t_s has {}",
                                            tr.accel_up_m_s2.size(), n));
  if (!tr.depth_m.empty() && tr.depth_m.size() != n)
    throw std::invalid_argument(fmt::format("position_m has {} samples but t_s has {}",
                                            tr.depth_m.size(), n));
  if (!tr.velocity_down_m_s.empty() && tr.velocity_down_m_s.size() != n)
    throw std::invalid_argument(fmt::format("velocity_m_s has {} samples but t_s has {}",
                                            tr.velocity_down_m_s.size(), n));
  if (tr.source == TraceSource::dem && (tr.velocity_down_m_s.empty() || tr.depth_m.empty()))
    throw std::invalid_argument("a DEM trace carries its own velocity and depth; this one has none");
  if (n < 8)
    throw std::invalid_argument(fmt::format("trace too short: {} samples, at least 8 expected", n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(tr.t_s[i]) || !std::isfinite(tr.accel_up_m_s2[i]))
      throw std::invalid_argument(fmt::format("sample {} is not a finite number", i));
    if (i > 0 && !(tr.t_s[i] > tr.t_s[i - 1]))
      throw std::invalid_argument(fmt::format(
          "time does not increase at sample {} (t_s = {} after {})", i, tr.t_s[i], tr.t_s[i - 1]));
  }
}

}  // namespace

const char* to_string(TraceSource s) { return s == TraceSource::dem ? "dem" : "lab"; }

TraceSource trace_source_of(const std::string& s) {
  if (s == "lab") return TraceSource::lab;
  if (s == "dem") return TraceSource::dem;
  throw std::invalid_argument(fmt::format("trace source '{}': expected 'lab' or 'dem'", s));
}

std::vector<double> butterworth_lowpass(const std::vector<double>& x, double sample_rate_hz,
                                        double cutoff_hz, int order) {
  if (!(sample_rate_hz > 0) || !(cutoff_hz > 0) || cutoff_hz >= 0.5 * sample_rate_hz)
    throw std::invalid_argument(fmt::format(
        "butterworth_lowpass: cut-off {} Hz must lie in (0, sample_rate/2 = {} Hz)", cutoff_hz,
        0.5 * sample_rate_hz));
  if (order < 1 || order > 12)
    throw std::invalid_argument(fmt::format("butterworth_lowpass: order {} not in 1..12", order));
  const std::size_t n = x.size();
  if (n < 2) return x;
  const auto sections = butterworth_sections(sample_rate_hz, cutoff_hz, order);
  // Zero phase: forward then backward pass (the magnitude response is squared). The record is
  // extended at both ends by an odd reflection about its end values so that the ends carry no
  // start-up transient.
  const std::size_t pad = std::min<std::size_t>(n - 1, 3 * (2 * sections.size() + 1));
  std::vector<double> y;
  y.reserve(n + 2 * pad);
  for (std::size_t i = pad; i >= 1; --i) y.push_back(2.0 * x.front() - x[i]);
  y.insert(y.end(), x.begin(), x.end());
  for (std::size_t i = 1; i <= pad; ++i) y.push_back(2.0 * x.back() - x[n - 1 - i]);
  for (const auto& s : sections) s.run(y);
  std::reverse(y.begin(), y.end());
  for (const auto& s : sections) s.run(y);
  std::reverse(y.begin(), y.end());
  return {y.begin() + static_cast<std::ptrdiff_t>(pad),
          y.begin() + static_cast<std::ptrdiff_t>(pad + n)};
}

ProcessedTrace process_trace(const Trace& trace, const MetricOptions& o) {
  validate(trace);
  const auto& t = trace.t_s;
  const std::size_t n = t.size();
  const double g = o.gravity_m_s2;
  if (!(g > 0)) throw std::invalid_argument(fmt::format("gravity {} m/s2 must be > 0", g));
  ProcessedTrace out;
  Metrics& m = out.metrics;
  out.t_s = t;

  const double fs = static_cast<double>(n - 1) / (t.back() - t.front());
  out.sample_rate_hz = fs;
  std::vector<double> af;
  if (o.cutoff_hz > 0 && o.cutoff_hz < 0.5 * fs) {
    af = butterworth_lowpass(trace.accel_up_m_s2, fs, o.cutoff_hz, o.filter_order);
  } else {
    af = trace.accel_up_m_s2;
    m.note = fmt::format("not filtered: cut-off {} Hz is not below the Nyquist frequency {:.0f} Hz",
                         o.cutoff_hz, 0.5 * fs);
  }

  // Contact: the filtered peak must stand clear of free fall.
  const std::size_t ipk =
      static_cast<std::size_t>(std::max_element(af.begin(), af.end()) - af.begin());
  if (af[ipk] < -0.5 * g)
    throw std::invalid_argument(fmt::format(
        "the projectile never makes contact: the acceleration never rises above -g/2 (peak {:.3g} "
        "m/s2 with g = {} m/s2)",
        af[ipk], g));

  // Sensor bias, first guess: the record starts in free fall (reads -g).
  const std::size_t head = std::max<std::size_t>(1, ipk / 3);
  std::vector<double> h(af.begin(), af.begin() + static_cast<std::ptrdiff_t>(head));
  std::nth_element(h.begin(), h.begin() + static_cast<std::ptrdiff_t>(h.size() / 2), h.end());
  // The source decides the bias: a lab record has a sensor (its bias is removed), a DEM record has
  // none, whatever columns either carries. Own velocity and depth are used when present.
  const bool sensor = trace.source == TraceSource::lab;
  const bool own_kinematics = !trace.velocity_down_m_s.empty() && !trace.depth_m.empty();
  double bias = sensor ? h[h.size() / 2] + g : 0.0;

  const double end_level = o.end_threshold_g * g;
  // Edge width: a zero-phase Butterworth spreads (and rings around) a step over about fs/fc
  // samples on each side. Steps faster than that (contact and stop in Poncelet-type laws) are
  // located at their half-height crossing, which a zero-phase filter leaves in place; gradual
  // edges at the threshold crossing, as the paper does.
  const std::size_t w = 1 + static_cast<std::size_t>(std::ceil(fs / std::max(o.cutoff_hz, 1e-9)));
  std::size_t i_start = 0, i_end = n - 1;
  bool step_start = false, step_end = false;
  double sigma_ff = 0;
  std::vector<double> a(n);
  for (int pass = 0; pass < 3; ++pass) {
    for (std::size_t i = 0; i < n; ++i) a[i] = af[i] - bias;
    const double thr = std::max(6.0 * sigma_ff, 0.03 * g);
    const CollisionStart cs = trace.contact_start_s
                                  ? contact_start(t, *trace.contact_start_s)
                                  : free_fall_start(t, a, ipk, g, thr, w);
    i_start = cs.i_start;
    m.t_start_s = cs.t_start_s;
    step_start = cs.step;
    // Free-fall segment: up to the edge width before the start.
    const std::size_t ff_end = i_start > w + 1 ? i_start - w - 1 : 0;
    // End: acceleration below end_threshold_g * g after the peak, staying there for 2 ms (at least
    // 3 samples), so that a grain-scale dip inside the collision does not end it, with the speed
    // down to end_speed_fraction of the collision speed, so that a lull between force-chain bursts
    // does not either (MetricOptions).
    std::vector<double> v_pass, z_pass;
    const std::vector<double>* speed = nullptr;
    double vc_pass = 0;
    if (own_kinematics) {
      speed = &trace.velocity_down_m_s;
      vc_pass = interp_at(t, trace.velocity_down_m_s, m.t_start_s);
    } else if (o.impact_velocity_m_s) {
      integrate_from_start(t, a, i_start, m.t_start_s, *o.impact_velocity_m_s, v_pass, z_pass);
      speed = &v_pass;
      vc_pass = *o.impact_velocity_m_s;
    }
    const double v_end = o.end_speed_fraction * std::abs(vc_pass);
    const std::size_t hold = std::max<std::size_t>(3, static_cast<std::size_t>(std::ceil(0.002 * fs)));
    std::size_t j = ipk;
    bool found = false;
    for (; j < n; ++j) {
      if (speed && (*speed)[j] > v_end) continue;
      bool stays = true;
      for (std::size_t k = j; k < std::min(n, j + hold); ++k) stays = stays && a[k] < end_level;
      if (stays && j + std::min<std::size_t>(hold, 3) <= n) {
        found = true;
        break;
      }
    }
    if (!found)
      throw std::invalid_argument(fmt::format(
          "trace shorter than the collision: after the peak at t = {:.4f} s the acceleration never "
          "stays below {} g with the speed below {} of the collision speed",
          t[ipk], o.end_threshold_g, o.end_speed_fraction));
    i_end = j;
    m.t_end_s = j > 0 ? crossing_time(t, a, j - 1, end_level) : t[j];
    step_end = false;
    if (j > w + 1 && j - w - 1 > i_start) {
      // Level before the edge; a fall to half of it within w samples before j is a step.
      const double pre = a[j - w - 1];
      if (pre > 2.0 * end_level) {
        std::size_t k = j - w - 1;
        while (k + 1 < j && a[k + 1] > 0.5 * pre) ++k;
        if (k + 1 <= j) {
          step_end = true;
          m.t_end_s = crossing_time(t, a, k, 0.5 * pre);
        }
      }
    }
    // Rest segment: the last three quarters of what follows the collision end, so that late settling
    // (grain-scale bursts after the 0.1 g crossing) stays out of it.
    const std::size_t after = std::min(n, i_end + w + 1);
    const std::size_t rest_begin = after + (n - after) / 4;
    const std::size_t n_ff = ff_end, n_rest = n - rest_begin;
    double b_sum = 0, w_sum = 0;
    if (n_ff >= 3) {
      b_sum += static_cast<double>(n_ff) * (mean_of(af, 0, ff_end) + g);
      w_sum += static_cast<double>(n_ff);
      sigma_ff = stddev_of(af, 0, ff_end);
    }
    if (n_rest >= 10) {
      b_sum += static_cast<double>(n_rest) * mean_of(af, rest_begin, n);
      w_sum += static_cast<double>(n_rest);
    }
    if (w_sum > 0 && sensor) bias = b_sum / w_sum;
    out.free_fall_samples = n_ff;
    out.rest_samples = n_rest;
  }
  for (std::size_t i = 0; i < n; ++i) a[i] = af[i] - bias;
  out.bias_m_s2 = bias;
  out.accel_up_m_s2 = a;
  m.tstop_s = m.t_end_s - m.t_start_s;

  // Velocity and depth: the trace's own when present (DEM), else integrated from the impact speed.
  out.velocity_down_m_s.assign(n, 0.0);
  out.depth_m.assign(n, 0.0);
  if (own_kinematics) {
    out.velocity_down_m_s = trace.velocity_down_m_s;
    out.depth_m = trace.depth_m;
    m.vc_m_s = interp_at(t, out.velocity_down_m_s, m.t_start_s);
  } else {
    if (!o.impact_velocity_m_s)
      throw std::invalid_argument(
          "no velocity in the trace and no impact velocity given: cannot integrate a into v and z");
    const double v0 = *o.impact_velocity_m_s;
    m.vc_m_s = v0;
    integrate_from_start(t, a, i_start, m.t_start_s, v0, out.velocity_down_m_s, out.depth_m);
  }
  // Peak: the largest filtered upward acceleration of the collision, leaving out the filter's
  // ringing next to step edges; at a step-like contact the collision's early samples (beyond
  // the ringing) are extrapolated back to the contact speed by a least-squares line in v^2
  // (a = c0 + c1 v^2 is exact for Eq. 1 with f = f0, h = m/d1, and the a-vs-v^2 view of
  // Katsuragi & Durian 2007 near the surface for the other laws).
  {
    std::size_t lo = i_start + 1, hi = std::min(n - 1, i_end);
    if (step_start) lo = std::min(hi, i_start + 1 + 2 * w);  // filtfilt rings ~2w samples
    if (step_end && hi > lo + 2 * w) hi -= 2 * w;
    double peak = -g;
    for (std::size_t k = lo; k <= hi; ++k) peak = std::max(peak, a[k]);
    if (step_start && hi >= lo + 4) {
      const std::size_t k1 = std::min(hi, lo + 3 * w + 2);
      Eigen::MatrixXd X(static_cast<Eigen::Index>(k1 - lo + 1), 2);
      Eigen::VectorXd y(X.rows());
      const auto& v = out.velocity_down_m_s;
      for (std::size_t k = lo; k <= k1; ++k) {
        const auto r = static_cast<Eigen::Index>(k - lo);
        X(r, 0) = 1.0;
        X(r, 1) = v[k] * v[k];
        y(r) = a[k];
      }
      const Eigen::Vector2d c = X.colPivHouseholderQr().solve(y);
      const double v0 = m.vc_m_s;
      if (std::isfinite(c(0)) && std::isfinite(c(1))) peak = std::max(peak, c(0) + c(1) * v0 * v0);
    }
    m.apeak_m_s2 = peak;
  }

  m.zstop_m = interp_at(t, out.depth_m, m.t_end_s);

  // Rebound: clearly moving up during the collision, or down to within one grain of the floor.
  double vmin = 0, zmax = 0;
  for (std::size_t k = i_start; k <= std::min(n - 1, i_end); ++k) {
    vmin = std::min(vmin, out.velocity_down_m_s[k]);
    zmax = std::max(zmax, out.depth_m[k]);
  }
  if (vmin < -std::max(0.1 * m.vc_m_s, 0.01)) {
    m.rebound = true;
    m.note += (m.note.empty() ? "" : "; ") + fmt::format("moved up at {:.3f} m/s", -vmin);
  }
  if (o.fill_height_m) {
    const double grain = o.grain_diameter_m.value_or(0.0);
    if (zmax >= *o.fill_height_m - grain) {
      m.rebound = true;
      m.note += (m.note.empty() ? "" : "; ") +
                fmt::format("reached {:.3f} m, within one grain of the floor at {:.3f} m", zmax,
                            *o.fill_height_m);
    }
  }
  out.i_start = i_start;
  out.i_end = i_end;
  return out;
}

Metrics compute_metrics(const Trace& trace, const MetricOptions& options) {
  return process_trace(trace, options).metrics;
}

}  // namespace gravsweep::results
