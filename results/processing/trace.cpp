// The paper's processing of a projectile trace (Sunday et al. 2021 Sect. 2.3): 2nd-order
// Butterworth low-pass at 500 Hz, collision start = no longer in free fall, collision end =
// acceleration below 0.1 g of the local g (and the speed below 10 % of vc, see MetricOptions; for
// lab records searched back from the rest at the record's end, at a level above the noise),
// velocity and depth by integrating the acceleration from the impact speed (brought to rest
// after the collision), and the metrics vc, apeak, zstop, tstop. Conventions in trace.h (z down,
// a up); the steps in trace_steps.h.
#include "results/processing/trace.h"

#include "results/processing/trace_steps.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace gravsweep::results {

using namespace trace_steps;

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

void validate(const Trace& tr) {
  const std::size_t n = tr.t_s.size();
  if (tr.accel_up_m_s2.size() != n)
    throw std::invalid_argument(fmt::format("accel_m_s2 has {} samples but t_s has {}", tr.accel_up_m_s2.size(), n));
  if (!tr.depth_m.empty() && tr.depth_m.size() != n)
    throw std::invalid_argument(fmt::format("position_m has {} samples but t_s has {}", tr.depth_m.size(), n));
  if (!tr.velocity_down_m_s.empty() && tr.velocity_down_m_s.size() != n)
    throw std::invalid_argument(
        fmt::format("velocity_m_s has {} samples but t_s has {}", tr.velocity_down_m_s.size(), n));
  if (tr.source == TraceSource::dem && (tr.velocity_down_m_s.empty() || tr.depth_m.empty()))
    throw std::invalid_argument("a DEM trace carries its own velocity and depth; this one has none");
  if (n < 8) throw std::invalid_argument(fmt::format("trace too short: {} samples, at least 8 expected", n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(tr.t_s[i]) || !std::isfinite(tr.accel_up_m_s2[i]))
      throw TraceError(fmt::format("sample {} is not a finite number", i), i, !std::isfinite(tr.accel_up_m_s2[i]));
    if (std::abs(tr.accel_up_m_s2[i]) > kMaxAccel_m_s2)
      throw TraceError(fmt::format("sample {} (t = {} s): acceleration {:g} m/s2 is beyond any accelerometer's "
                                   "range; |a| <= {:g} m/s2 expected",
                                   i, tr.t_s[i], tr.accel_up_m_s2[i], kMaxAccel_m_s2),
                       i, true);
    if (i > 0 && !(tr.t_s[i] > tr.t_s[i - 1]))
      throw TraceError(
          fmt::format("time does not increase at sample {} (t_s = {} after {})", i, tr.t_s[i], tr.t_s[i - 1]), i);
  }
}

}  // namespace

const char* to_string(TraceSource s) { return s == TraceSource::dem ? "dem" : "lab"; }

const char* to_string(TimeScale s) { return s == TimeScale::fixed ? "fixed" : "froude"; }

TimeScale time_scale_of(const std::string& s) {
  if (s == "froude") return TimeScale::froude;
  if (s == "fixed") return TimeScale::fixed;
  throw std::invalid_argument(
      fmt::format("time scale '{}': expected 'froude' (the drop's sqrt(D/g)) or 'fixed' "
                  "(the paper's hertz and seconds at every gravity)",
                  s));
}

const char* to_string(EndRule r) {
  switch (r) {
    case EndRule::paper:
      return "paper";
    case EndRule::depth:
      return "depth";
    case EndRule::speed:
      break;
  }
  return "speed";
}

EndRule end_rule_of(const std::string& s) {
  if (s == "speed" || s.empty()) return EndRule::speed;
  if (s == "paper") return EndRule::paper;
  if (s == "depth") return EndRule::depth;
  throw std::invalid_argument(fmt::format("end rule '{}': expected 'speed', 'paper' or 'depth'", s));
}

TraceSource trace_source_of(const std::string& s) {
  if (s == "lab") return TraceSource::lab;
  if (s == "dem") return TraceSource::dem;
  throw std::invalid_argument(fmt::format("trace source '{}': expected 'lab' or 'dem'", s));
}

std::vector<double> butterworth_lowpass(const std::vector<double>& x, double sample_rate_hz, double cutoff_hz,
                                        int order) {
  if (!(sample_rate_hz > 0) || !(cutoff_hz > 0) || cutoff_hz >= 0.5 * sample_rate_hz)
    throw std::invalid_argument(fmt::format("butterworth_lowpass: cut-off {} Hz must lie in (0, sample_rate/2 = {} Hz)",
                                            cutoff_hz, 0.5 * sample_rate_hz));
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
  return {y.begin() + static_cast<std::ptrdiff_t>(pad), y.begin() + static_cast<std::ptrdiff_t>(pad + n)};
}

namespace {

/// One pass of the bias iteration: start, end and rest with the current bias, then the bias
/// re-estimated from free fall and rest (a lab record; a DEM record keeps 0).
struct PassResult {
  CollisionStart start;
  CollisionEnd end;
  BiasEstimate bias;
};

PassResult collision_pass(const Trace& trace, const MetricOptions& o, const std::vector<double>& af,
                          const std::vector<double>& a, std::size_t ipk, std::size_t w, double fs, double sigma_ff,
                          double step_rise_s) {
  const auto& t = trace.t_s;
  const std::size_t n = t.size();
  const double g = o.gravity_m_s2;
  const double thr = std::max(6.0 * sigma_ff, 0.03 * g);
  PassResult r;
  r.start = trace.contact_start_s ? contact_start(t, *trace.contact_start_s)
                                  : free_fall_start(t, a, ipk, g, thr, w, step_rise_s);
  // Free-fall segment: up to the edge width before the start.
  const std::size_t ff_end = r.start.i_start > w + 1 ? r.start.i_start - w - 1 : 0;
  // End: acceleration below end_threshold_g * g after the peak, staying there for 2 ms (at least
  // 3 samples), so that a grain-scale dip inside the collision does not end it, with the speed
  // down to end_speed_fraction of the collision speed, so that a lull between force-chain bursts
  // does not either (MetricOptions).
  std::vector<double> v_pass, z_pass;
  EndCriteria ec;
  ec.end_level_m_s2 = o.end_threshold_g * g;
  ec.hold = end_hold_samples(fs, o.end_hold_s);
  const bool paper_rule = o.end_rule == EndRule::paper;
  double vc_pass = 0;
  if (paper_rule) {
    // The paper's rule: the acceleration alone.
  } else if (!trace.velocity_down_m_s.empty() && !trace.depth_m.empty()) {
    ec.speed = &trace.velocity_down_m_s;
    vc_pass = interp_at(t, trace.velocity_down_m_s, r.start.t_start_s);
  } else if (o.impact_speed_m_s) {
    integrate_from_start(t, a, r.start.i_start, r.start.t_start_s, *o.impact_speed_m_s, v_pass, z_pass);
    ec.speed = &v_pass;
    vc_pass = *o.impact_speed_m_s;
  }
  ec.v_end_m_s = o.end_speed_fraction * std::abs(vc_pass);
  std::optional<std::size_t> j;
  if (!v_pass.empty() && o.end_from_rest) {
    // A lab record (velocity integrated from the impact speed): the end level of the
    // local g raised above the noise, the end searched back from the rest at the record's end,
    // accepted where the integrated speed is down too. That speed is known to within g times the
    // start's uncertainty (an edge width; 0.01 m/s for a slow impact at 1 g, 1/10 of its vc), so
    // that much is allowed on top: after the last exceedance nothing but rest or a truncated
    // record's coasting follows, and no projectile coasts this slowly for long at 0.1 g.
    ec.end_level_m_s2 = end_level(o.end_threshold_g, g, record_noise(af, ff_end));
    const double v_tol_m_s = g * static_cast<double>(w) / fs;
    // Nothing but rest follows the last exceedance, so no dip inside the collision can pass for
    // it: the rest needs the paper's hold, not the drop-scaled one (at 0.1 m/s2 a lab record's
    // tail after a 6 g stop rings above 0.1 g for 70 ms through a 50 Hz filter).
    const std::size_t rest_hold = std::min(ec.hold, end_hold_samples(fs, kPaperEndHold_s));
    const std::optional<std::size_t> jb = last_exceedance_end(a, ipk, ec.end_level_m_s2, rest_hold);
    if (jb && v_pass[*jb] <= ec.v_end_m_s + v_tol_m_s) j = jb;
  }
  if (!j) j = end_sample(a, ipk, ec);
  if (!j) {
    // The level, when the noise raised it above the paper's, is part of the reason.
    const std::string level = ec.end_level_m_s2 > o.end_threshold_g * g
                                  ? fmt::format(" (raised to {:.3g} m/s2, {} sigma of the record's noise)",
                                                ec.end_level_m_s2, kEndNoiseSigmas)
                                  : "";
    const std::string speed =
        ec.speed ? fmt::format(" with the speed below {} of the collision speed", o.end_speed_fraction) : "";
    throw TraceError(fmt::format("trace shorter than the collision: after the peak at t = {:.4f} s the acceleration "
                                 "never stays below {} g{} for {:.3g} s{}",
                                 t[ipk], o.end_threshold_g, level, o.end_hold_s, speed),
                     n - 1);
  }
  r.end = end_edge(t, a, *j, r.start.i_start, w, ec.end_level_m_s2);
  r.bias = bias_from_segments(af, g, ff_end, rest_begin(r.end.i_end, w, n));
  return r;
}

}  // namespace

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
  const std::vector<double> af = filter_acceleration(trace.accel_up_m_s2, fs, o, m.note);
  // Contact: the filtered peak must stand clear of free fall.
  const std::size_t ipk = contact_peak(af, g);
  // The source decides the bias: a lab record has a sensor (its bias is removed; first guess: the
  // record starts in free fall), a DEM record has none, whatever columns either carries. Own
  // velocity and depth are used when present.
  const bool sensor = trace.source == TraceSource::lab;
  const bool own_kinematics = !trace.velocity_down_m_s.empty() && !trace.depth_m.empty();
  double bias = sensor ? initial_bias(af, ipk, g) : 0.0;
  if (sensor) check_starts_in_free_fall(t, af, ipk, g);
  // Steps faster than the filter (contact and stop in Poncelet-type laws) are located at their
  // half-height crossing, which a zero-phase filter leaves in place; gradual edges at the
  // threshold crossing, as the paper does.
  const std::size_t w = edge_width(fs, o.cutoff_hz);
  double sigma_ff = 0;
  const double step_rise_s = filter_step_rise_s(fs, o);
  PassResult pass;
  std::vector<double> a(n);
  for (int k = 0; k < 3; ++k) {
    for (std::size_t i = 0; i < n; ++i) a[i] = af[i] - bias;
    pass = collision_pass(trace, o, af, a, ipk, w, fs, sigma_ff, step_rise_s);
    if (pass.bias.sigma_free_fall_m_s2) sigma_ff = *pass.bias.sigma_free_fall_m_s2;
    if (pass.bias.any && sensor) bias = pass.bias.bias_m_s2;
    out.free_fall_samples = pass.bias.free_fall_samples;
    out.rest_samples = pass.bias.rest_samples;
  }
  const std::size_t i_start = pass.start.i_start, i_end = pass.end.i_end;
  m.t_start_s = pass.start.t_start_s;
  m.t_end_s = pass.end.t_end_s;
  for (std::size_t i = 0; i < n; ++i) a[i] = af[i] - bias;
  out.bias_m_s2 = bias;
  out.accel_up_m_s2 = a;
  m.tstop_s = m.t_end_s - m.t_start_s;
  m.cutoff_hz = o.cutoff_hz;
  m.end_hold_s = o.end_hold_s;

  // Velocity and depth: the trace's own when present (DEM), else integrated from the impact speed.
  if (own_kinematics) {
    out.velocity_down_m_s = trace.velocity_down_m_s;
    out.depth_m = trace.depth_m;
    m.vc_m_s = interp_at(t, out.velocity_down_m_s, m.t_start_s);
    // One depth reference for DEM drops and lab records: the collision start (the paper's
    // processing integrates its records' depth from there). The surface's is kept beside it.
    m.start_depth_m = interp_at(t, trace.depth_m, m.t_start_s);
    for (double& z : out.depth_m) z -= m.start_depth_m;
  } else {
    if (!o.impact_speed_m_s)
      throw std::invalid_argument(
          "no velocity in the trace and no impact velocity given: cannot integrate a into v and z");
    m.vc_m_s = *o.impact_speed_m_s;
    integrate_from_start(t, a, i_start, m.t_start_s, m.vc_m_s, out.velocity_down_m_s, out.depth_m);
    // At rest the integrated speed reads zero (trace_steps.h): what it reads is removed from v and z.
    const double end_tolerance_m_s = 0.5 * pass.end.step_height_m_s2 / fs;  // half a sample of the end step
    out.rest_speed_offset_m_s =
        bring_to_rest(t, rest_begin(i_end, w, n), m.t_start_s, end_tolerance_m_s, out.velocity_down_m_s, out.depth_m);
  }
  m.apeak_m_s2 = peak_acceleration(a, out.velocity_down_m_s, i_start, i_end, pass.start.step, pass.end.step, w,
                                   m.vc_m_s - out.rest_speed_offset_m_s, g);
  const std::size_t i_last_depth = own_kinematics ? n - 1 : i_end;  // trace_steps.h, rebound_of
  MetricOptions from_start = o;  // the floor's depth below the collision start, for the rebound flag
  if (from_start.fill_height_m) *from_start.fill_height_m -= m.start_depth_m;
  const Rebound rb = rebound_of(out.velocity_down_m_s, out.depth_m, i_start, i_end, i_last_depth, m.vc_m_s, from_start);
  m.zstop_m = rb.max_depth_m;  // Sect. 2.3: the maximum penetration depth
  m.zstop_surface_m = m.zstop_m + m.start_depth_m;
  if (o.end_rule == EndRule::depth) {
    const DepthEnd de = depth_end(t, out.depth_m, i_start, i_last_depth, kEndDepthFraction);
    m.t_end_s = de.t_end_s;
    m.tstop_s = m.t_end_s - m.t_start_s;
  }
  m.depth_at_end_m = interp_at(t, out.depth_m, m.t_end_s);
  m.final_depth_m = out.depth_m.back();
  m.rebound = rb.rebound;
  if (!rb.note.empty()) m.note += (m.note.empty() ? "" : "; ") + rb.note;
  out.i_start = i_start;
  out.i_end = i_end;
  return out;
}

Metrics compute_metrics(const Trace& trace, const MetricOptions& options) {
  return process_trace(trace, options).metrics;
}

}  // namespace gravsweep::results
