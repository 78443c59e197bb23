// Predictions of a fitted model (see model.h): Eq. 1 integrated by RK4 from the impact speed to
// the stop, and the metrics of a trial predicted the way the trial was measured (issue 13 item 2):
// the model's record on the trial's own sample grid, processed like the data, so that apeak is
// read off the filtered model record exactly as off the filtered measurement.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "results/model/model.h"
#include "results/model/model_internal.h"

namespace gravsweep::results {

using namespace detail;

namespace {

/// Integration step for Eq. 1 at gravity g (s): finer in high gravity, where collisions are short.
double rk4_step_s(double g) { return std::clamp(2e-5 * std::sqrt(9.81 / g), 1e-5, 2e-4); }

/// The downward acceleration g - R/m of the model at (z, v, t since contact).
struct Eq1 {
  const FittedModel& m;
  TermContext c;
  double operator()(double z, double v, double t) {
    c.z_m = z;
    c.v_m_s = v;
    c.t_since_contact_s = t;
    return c.g_m_s2 - m.force(c) / c.mass_kg;
  }
};

/// One RK4 step of (z, v) by dt from time t.
void rk4(Eq1& acc, double& z, double& v, double t, double dt) {
  const double k1v = acc(z, v, t), k1z = v;
  const double k2v = acc(z + 0.5 * dt * k1z, v + 0.5 * dt * k1v, t + 0.5 * dt), k2z = v + 0.5 * dt * k1v;
  const double k3v = acc(z + 0.5 * dt * k2z, v + 0.5 * dt * k2v, t + 0.5 * dt), k3z = v + 0.5 * dt * k2v;
  const double k4v = acc(z + dt * k3z, v + dt * k3v, t + dt), k4z = v + dt * k3v;
  v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
  z += dt / 6 * (k1z + 2 * k2z + 2 * k3z + k4z);
}

}  // namespace

Prediction predict(const FittedModel& m, const Trial& info) { return predict(m, context(info)); }

Prediction predict(const FittedModel& m, const TermContext& c0, double t_max_s) {
  // RK4 on (z, v), z down: dv/dt = g - R/m (Eq. 1), from z = 0, v = vc.
  Prediction p;
  const double dt = rk4_step_s(c0.g_m_s2);
  Eq1 acc{m, c0};
  double z = 0, v = c0.vc_m_s, t = 0;
  double apeak = -acc(0, v, 0);
  while (t < t_max_s) {
    double zn = z, vn = v;
    rk4(acc, zn, vn, t, dt);
    if (vn <= 0) {
      const double f = v / (v - vn);
      p.tstop_s = t + f * dt;
      p.zstop_m = z + f * (zn - z);
      p.stopped = true;
      apeak = std::max(apeak, -acc(p.zstop_m, 0.0, p.tstop_s));
      p.apeak_m_s2 = apeak;
      return p;
    }
    z = zn;
    v = vn;
    t += dt;
    apeak = std::max(apeak, -acc(z, v, t));
    if (z > 10.0 * std::max(c0.fill_height_m, c0.diameter_m)) break;
  }
  p.apeak_m_s2 = apeak;
  return p;
}

Trace model_record(const FittedModel& m, const MeasuredTrial& t) {
  const auto& grid = t.raw.t_s;
  const double t0 = t.processed.metrics.t_start_s;  // contact, as measured
  TermContext c0 = context(t.info);
  c0.vc_m_s = c0.v_m_s = t.processed.metrics.vc_m_s;
  Eq1 acc{m, c0};
  const double g = c0.g_m_s2, dt = rk4_step_s(g);
  Trace rec;
  rec.source = t.info.source;
  rec.t_s = grid;
  rec.contact_start_s = t.raw.contact_start_s;
  const bool own = !t.raw.velocity_down_m_s.empty() && !t.raw.depth_m.empty();
  double z = 0, v = c0.vc_m_s, tc = 0;
  bool stopped = false;
  for (const double ts : grid) {
    const double target = ts - t0;
    double a_up = 0;
    if (target < 0) {  // free fall before contact
      a_up = -g;
      if (own) {
        rec.velocity_down_m_s.push_back(c0.vc_m_s + g * target);
        rec.depth_m.push_back(c0.vc_m_s * target + 0.5 * g * target * target);
      }
    } else {
      while (!stopped && tc < target) {
        const double h = std::min(dt, target - tc);
        double zn = z, vn = v;
        rk4(acc, zn, vn, tc, h);
        if (vn <= 0) {
          const double f = v / (v - vn);
          z += f * (zn - z);
          v = 0;
          stopped = true;
          break;
        }
        z = zn, v = vn, tc += h;
      }
      a_up = stopped ? 0.0 : -acc(z, v, tc);
      if (own) {
        rec.velocity_down_m_s.push_back(v);
        rec.depth_m.push_back(z);
      }
    }
    rec.accel_up_m_s2.push_back(a_up);
  }
  return rec;
}

Prediction predict(const FittedModel& m, const MeasuredTrial& t) {
  Prediction p = predict(m, t.info);
  // apeak as measured: the model's record processed like the trial's (filter, start, peak). When
  // the model's record cannot be measured (it does not stop within the record), the unfiltered
  // peak stays.
  try {
    const ProcessedTrace pt = process_trace(model_record(m, t), metric_options(t.info));
    p.apeak_m_s2 = pt.metrics.apeak_m_s2;
  } catch (const std::invalid_argument&) {
  }
  return p;
}

}  // namespace gravsweep::results
