// Predictions of a fitted model (see predict.h): Eq. 1 integrated by RK4 from the impact speed to
// the stop, and the metrics of a trial predicted the way the trial was measured:
// the model's record on the trial's own sample grid, processed like the data, so that apeak is
// read off the filtered model record exactly as off the filtered measurement.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "results/model/fit.h"
#include "results/model/predict.h"
#include "results/model/model_internal.h"

namespace gravsweep::results {

using namespace detail;

namespace {

/// Integration step for Eq. 1 at gravity g (s): finer in high gravity, where collisions are short
/// (2e-5 s at 9.81 m/s2, 2e-4 s at 0.1, 2e-3 s at 0.001 m/s2: about 1/5000 of sqrt(D/g) for D = 0.1 m
/// at every level, and 1/15 of the drag's time d1 / v at the sweep's fastest 1.2 m/s, where RK4's
/// error is of order (1/15)^4).
double rk4_step_s(double g) { return std::clamp(2e-5 * std::sqrt(9.81 / g), 1e-5, 2e-3); }

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

double prediction_horizon_s(const TermContext& c) {
  return std::max(kPredictHorizonMin_s, kPredictHorizonScaled * std::sqrt(c.diameter_m / c.g_m_s2));
}

Prediction predict(const FittedModel& m, const TermContext& c0, double t_max_s) {
  return integrate_motion(m, c0, std::isnan(t_max_s) ? prediction_horizon_s(c0) : t_max_s, nullptr);
}

namespace detail {

Prediction integrate_motion(const FittedModel& m, const TermContext& c0, double t_max_s, const MotionVisitor& visit) {
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
      if (visit) visit(t, z, v, f * dt);
      p.tstop_s = t + f * dt;
      p.zstop_m = z + f * (zn - z);
      p.stopped = true;
      apeak = std::max(apeak, -acc(p.zstop_m, 0.0, p.tstop_s));
      p.apeak_m_s2 = apeak;
      return p;
    }
    if (visit) visit(t, z, v, dt);
    z = zn;
    v = vn;
    t += dt;
    apeak = std::max(apeak, -acc(z, v, t));
    if (z > 10.0 * std::max(c0.fill_height_m, c0.diameter_m)) break;
  }
  p.apeak_m_s2 = apeak;
  return p;
}

}  // namespace detail

namespace {

/// model_record, with the samples where the model's projectile is in the collision marked.
Trace model_record_marked(const FittedModel& m, const MeasuredTrial& t, std::vector<bool>& in_collision) {
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
  in_collision.assign(grid.size(), false);
  const bool own = !t.raw.velocity_down_m_s.empty() && !t.raw.depth_m.empty();
  double z = 0, v = c0.vc_m_s, tc = 0;
  bool stopped = false;
  for (std::size_t k = 0; k < grid.size(); ++k) {
    const double target = grid[k] - t0;
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
      in_collision[k] = !stopped;
      if (own) {
        rec.velocity_down_m_s.push_back(v);
        rec.depth_m.push_back(z);
      }
    }
    rec.accel_up_m_s2.push_back(a_up);
  }
  return rec;
}

}  // namespace

Trace model_record(const FittedModel& m, const MeasuredTrial& t) {
  std::vector<bool> in_collision;
  return model_record_marked(m, t, in_collision);
}

std::vector<double> relative_residuals(const FittedModel& m, const MeasuredTrial& t) {
  std::vector<double> r;
  const double mass = t.info.projectile_mass_kg, g = t.info.gravity_m_s2;
  for (std::size_t k = t.fit_begin; k < t.fit_end; ++k) {
    const double r_over_m = m.force(context(t, k)) / mass;  // a_model + g
    if (!(r_over_m > 0)) continue;
    const double a_model = r_over_m - g;
    r.push_back(std::clamp((t.processed.accel_up_m_s2[k] - a_model) / r_over_m, -1.0, 1.0));
  }
  return r;
}

Prediction predict(const FittedModel& m, const MeasuredTrial& t, const std::vector<const std::vector<double>*>& fluct) {
  Prediction p = predict(m, t.info);
  // apeak as measured: the model's record processed like the trial's (filter, start, peak), with
  // each of the other trials' fluctuations about the model laid over its collision in turn, and
  // the mean of what is read off. A record that cannot be measured (the model does not stop
  // within it) is left out; when none can be, the unfiltered peak stays.
  std::vector<bool> in_collision;
  const Trace clean = model_record_marked(m, t, in_collision);
  const MetricOptions& o = t.options;
  const double g = t.info.gravity_m_s2;
  double sum = 0;
  int n = 0;
  auto measure = [&](const Trace& rec) {
    try {
      sum += process_trace(rec, o).metrics.apeak_m_s2;
      ++n;
    } catch (const std::invalid_argument&) {
    }
  };
  for (const std::vector<double>* r : fluct) {
    if (r == nullptr || r->size() < kMinFluctuationSamples) continue;
    Trace rec = clean;
    std::size_t q = 0;
    for (std::size_t k = 0; k < rec.accel_up_m_s2.size(); ++k)
      if (in_collision[k]) rec.accel_up_m_s2[k] += (rec.accel_up_m_s2[k] + g) * (*r)[q++ % r->size()];
    measure(rec);
  }
  if (n == 0) measure(clean);
  if (n > 0) p.apeak_m_s2 = sum / n;
  return p;
}

Prediction predict(const FittedModel& m, const MeasuredTrial& t) { return predict(m, t, {}); }

std::vector<const std::vector<double>*> same_level_fluctuations(const Campaign& c,
                                                                const std::vector<std::vector<double>>& fluct,
                                                                std::size_t i) {
  std::vector<const std::vector<double>*> out;
  for (std::size_t j = 0; j < fluct.size() && out.size() < kMaxFluctuationTrials; ++j)
    if (j != i && !fluct[j].empty() && same_gravity_level(c.trials[j].info.gravity_m_s2, c.trials[i].info.gravity_m_s2))
      out.push_back(&fluct[j]);
  return out;
}

}  // namespace gravsweep::results
