// The paper's method, Table 3 (Sect. 4, Eqs. 2-5).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <utility>
#include <stdexcept>

#include "results/model/cross_validation.h"
#include "results/model/predict.h"
#include "results/model/table3.h"
#include "results/model/model_internal.h"

namespace gravsweep::results {

using namespace detail;

// ---------------------------------------------------------------------------------------------
// The paper's method: Table 3

namespace {

/// Eq. 2 fitted to apeak(vc^2) of the trials `pick` (indices into ts): f0 (N) and 1/d1 (1/m).
std::pair<double, double> eq2_fit(const std::vector<const MeasuredTrial*>& ts, const std::vector<std::size_t>& pick,
                                  double g, double mass) {
  const auto n = static_cast<Eigen::Index>(pick.size());
  Eigen::MatrixXd X(n, 2);
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& m = ts[pick[static_cast<std::size_t>(i)]]->processed.metrics;
    X(i, 0) = 1.0;
    X(i, 1) = m.vc_m_s * m.vc_m_s;
    y(i) = m.apeak_m_s2;
  }
  const Eigen::Vector2d b = X.colPivHouseholderQr().solve(y);
  return {mass * (b(0) + g), b(1)};
}

/// Bootstrap standard errors of f0 and 1/d1 over whole drops (each drop resampled with its own
/// site and scatter): with a site per drop they carry the site-to-site scatter that the OLS
/// errors, which assume independent residuals about one line, leave out when sites repeat.
void bootstrap_eq2(const std::vector<const MeasuredTrial*>& ts, double g, double mass, Table3Row& r) {
  std::mt19937_64 rng(kTable3BootstrapSeed);
  std::uniform_int_distribution<std::size_t> pick_one(0, ts.size() - 1);
  std::vector<double> f0, inv_d1;
  std::vector<std::size_t> pick(ts.size());
  for (int b = 0; b < kTable3BootstrapResamples; ++b) {
    double vmin = INFINITY, vmax = 0;
    for (auto& k : pick) {
      k = pick_one(rng);
      vmin = std::min(vmin, ts[k]->processed.metrics.vc_m_s);
      vmax = std::max(vmax, ts[k]->processed.metrics.vc_m_s);
    }
    if (!(vmax >= kTable3MinSpeedRatio * vmin)) continue;  // one speed cannot separate f0 from 1/d1
    const auto [f, d] = eq2_fit(ts, pick, g, mass);
    f0.push_back(f);
    inv_d1.push_back(d);
  }
  auto sd = [](const std::vector<double>& x) {
    if (x.size() < 2) return std::numeric_limits<double>::quiet_NaN();
    const double mean = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
    double s2 = 0;
    for (double v : x) s2 += (v - mean) * (v - mean);
    return std::sqrt(s2 / static_cast<double>(x.size() - 1));
  };
  r.f0_boot_se_N = sd(f0);
  r.inv_d1_boot_se_1_m = sd(inv_d1);
}

/// Ordinary least squares: coefficients and their covariance.
void ols(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::Vector2d& beta, Eigen::Matrix2d& cov) {
  beta = A.colPivHouseholderQr().solve(b);
  const double dof = std::max<double>(1.0, static_cast<double>(A.rows()) - 2.0);
  const double s2 = (b - A * beta).squaredNorm() / dof;
  cov = s2 * (A.transpose() * A).inverse();
}

/// Eq. 2 on the level's trials `ts` (apeak usable): f0, 1/d1, vt and their errors.
void fit_eq2(const std::vector<const MeasuredTrial*>& ts, double g, Table3Row& r) {
  const auto n = static_cast<Eigen::Index>(ts.size());
  Eigen::MatrixXd X(n, 2);
  Eigen::VectorXd y(n);
  double mass = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& m = ts[static_cast<std::size_t>(i)]->processed.metrics;
    mass += ts[static_cast<std::size_t>(i)]->info.projectile_mass_kg / static_cast<double>(n);
    X(i, 0) = 1.0;
    X(i, 1) = m.vc_m_s * m.vc_m_s;
    y(i) = m.apeak_m_s2;  // Eq. 2: apeak = f0/m + vc^2/d1 - g
  }
  Eigen::Vector2d b;
  Eigen::Matrix2d cv;
  ols(X, y, b, cv);
  r.f0_N = mass * (b(0) + g);
  r.f0_se_N = mass * std::sqrt(cv(0, 0));
  r.inv_d1_1_m = b(1);
  r.inv_d1_se_1_m = std::sqrt(cv(1, 1));
  if (r.f0_N > 0 && r.inv_d1_1_m > 0) {
    // Eq. 5: vt = sqrt(d1 f0 / m); delta method with the covariance of (f0, 1/d1).
    r.vt_m_s = std::sqrt(r.f0_N / (mass * r.inv_d1_1_m));
    const double var = 0.25 * r.vt_m_s * r.vt_m_s *
                       (std::pow(r.f0_se_N / r.f0_N, 2) + std::pow(r.inv_d1_se_1_m / r.inv_d1_1_m, 2) -
                        2 * mass * cv(0, 1) / (r.f0_N * r.inv_d1_1_m));
    r.vt_se_m_s = std::sqrt(std::max(0.0, var));
  }
  bootstrap_eq2(ts, g, mass, r);
}

/// zstop ~ H^alpha on the level's trials `ts` (zstop usable), H = drop height + zstop (Fig. 10).
void fit_alpha(const std::vector<const MeasuredTrial*>& ts, double g, Table3Row& r) {
  if (ts.size() < 2) return;
  const auto n = static_cast<Eigen::Index>(ts.size());
  Eigen::MatrixXd Xl(n, 2);
  Eigen::VectorXd yl(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& m = ts[static_cast<std::size_t>(i)]->processed.metrics;
    const auto& info = ts[static_cast<std::size_t>(i)]->info;
    const double drop = info.drop_height_m > 0 ? info.drop_height_m : m.vc_m_s * m.vc_m_s / (2 * g);
    Xl(i, 0) = 1.0;
    Xl(i, 1) = std::log(drop + m.zstop_m);
    yl(i) = std::log(std::max(m.zstop_m, 1e-9));
  }
  Eigen::Vector2d bl;
  Eigen::Matrix2d cvl;
  ols(Xl, yl, bl, cvl);
  r.alpha = bl(1);
  r.alpha_se = std::sqrt(cvl(1, 1));
}

std::vector<Table3Row> table3_of(const Campaign& c, const std::vector<bool>& mask) {
  std::vector<Table3Row> rows;
  for (double g : c.gravity_levels()) {
    // A clipped record's apeak is a lower bound: out of Eq. 2; its zstop out of alpha when the
    // clip moved it (clip_exclusion).
    std::vector<const MeasuredTrial*> ts, tz;
    int clipped = 0;
    for (std::size_t i = 0; i < c.trials.size(); ++i) {
      if (!mask[i] || !same_gravity_level(c.trials[i].info.gravity_m_s2, g)) continue;
      const bool apeak_ok = clip_exclusion(c.trials[i], ClippedMetric::apeak).empty();
      clipped += !apeak_ok;
      if (apeak_ok) ts.push_back(&c.trials[i]);
      if (clip_exclusion(c.trials[i], ClippedMetric::zstop).empty()) tz.push_back(&c.trials[i]);
    }
    Table3Row r;
    r.g_m_s2 = g;
    r.trials = static_cast<int>(ts.size());
    const std::string left_out =
        clipped ? fmt::format("{} clipped trial{} left out (apeak a lower bound)", clipped, clipped == 1 ? "" : "s")
                : "";
    double vmin = INFINITY, vmax = 0;
    for (const auto* t : ts) {
      vmin = std::min(vmin, t->processed.metrics.vc_m_s);
      vmax = std::max(vmax, t->processed.metrics.vc_m_s);
    }
    if (r.trials < kTable3MinTrials || !(vmax >= kTable3MinSpeedRatio * vmin)) {
      r.note = ts.empty() ? "no trials"
                          : fmt::format(
                                "not fitted: Eq. 2 needs >= {} trials over a vc range of x{} (found {}, vc "
                                "{:.3g}-{:.3g} m/s)",
                                kTable3MinTrials, kTable3MinSpeedRatio, r.trials, vmin, vmax);
      if (!left_out.empty()) r.note += "; " + left_out;
      rows.push_back(r);
      continue;
    }
    fit_eq2(ts, g, r);
    fit_alpha(tz, g, r);
    r.note = left_out;
    rows.push_back(r);
  }
  return rows;
}

}  // namespace

std::vector<Table3Row> table3(const Campaign& c) { return table3_of(c, std::vector<bool>(c.trials.size(), true)); }

Prediction predict_paper(const Table3Row& row, double m, double vc) {
  Prediction p;
  const double g = row.g_m_s2, f0 = row.f0_N, inv_d1 = row.inv_d1_1_m;
  p.apeak_m_s2 = f0 / m + vc * vc * inv_d1 - g;  // Eq. 2
  if (!(f0 > m * g) || !(inv_d1 > 0)) return p;
  const double d1 = 1.0 / inv_d1;
  p.zstop_m = 0.5 * d1 * std::log(1.0 + m * vc * vc / (d1 * (f0 - m * g)));                       // Eq. 3
  p.tstop_s = std::atan(vc * std::sqrt(m / (d1 * (f0 - m * g)))) / std::sqrt((f0 / m - g) / d1);  // Eq. 4
  p.stopped = true;
  return p;
}

HeldOut cross_validate_paper(const Campaign& c, int folds, unsigned seed) {
  return over_folds(c, folds, seed, [&](const std::vector<bool>& train, HeldOut& h) {
    const auto rows = table3_of(c, train);
    for (std::size_t i = 0; i < train.size(); ++i) {
      if (train[i]) continue;
      const auto& t = c.trials[i];
      for (const auto& r : rows) {
        if (r.g_m_s2 != t.info.gravity_m_s2) continue;
        h.pred[i] = predict_paper(r, t.info.projectile_mass_kg, t.processed.metrics.vc_m_s);
        // Trace residual of Eq. 1 with the Table 3 f0, d1 (per gravity level).
        double s = 0;
        std::size_t n = 0;
        for (std::size_t q = t.fit_begin; q < t.fit_end; ++q, ++n) {
          const double v = t.processed.velocity_down_m_s[q];
          const double a_model = r.f0_N / t.info.projectile_mass_kg + r.inv_d1_1_m * v * v - r.g_m_s2;
          s += std::pow(t.processed.accel_up_m_s2[q] - a_model, 2);
        }
        if (n) h.trace_mse[i] = s / static_cast<double>(n);
      }
    }
  });
}

}  // namespace gravsweep::results
