// Froude-number collapse (see collapse.h).
#include "results/model/collapse.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "results/measurements/trial.h"
#include "results/model/froude.h"
#include "results/model/stats.h"

namespace gravsweep::results {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Point {
  double level_m_s2, x, y;  ///< gravity level, ln Fr, ln(metric)
};

/// Least-squares polynomial in x of the given degree (coefficients, lowest first).
Eigen::VectorXd poly_fit(const std::vector<Point>& pts, int degree) {
  const auto n = static_cast<Eigen::Index>(pts.size());
  Eigen::MatrixXd A(n, degree + 1);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Point& p = pts[static_cast<std::size_t>(i)];
    for (int k = 0; k <= degree; ++k) A(i, k) = std::pow(p.x, k);
    b(i) = p.y;
  }
  return A.colPivHouseholderQr().solve(b);
}

double poly_at(const Eigen::VectorXd& c, double x) {
  double y = 0;
  for (Eigen::Index k = c.size() - 1; k >= 0; --k) y = y * x + c(k);
  return y;
}

/// The design's Froude number of each point (froude_groups): repeats of one point differ by their
/// measured impact speeds, and a curve must not bend between them.
std::vector<int> froude_groups_of(const std::vector<Point>& pts) {
  std::vector<double> x;
  for (const auto& p : pts) x.push_back(p.x);
  return froude_groups(x);
}

/// Distinct Froude numbers of the design among the points.
int distinct_x(const std::vector<Point>& pts) {
  const std::vector<int> g = froude_groups_of(pts);
  return g.empty() ? 0 : *std::max_element(g.begin(), g.end()) + 1;
}

double pct(double ln_scatter) { return 100 * (std::exp(ln_scatter) - 1); }

struct LevelCurve {
  Eigen::VectorXd coef;
  double x_lo = 0, x_hi = 0;
};

/// Root-mean-square difference of two levels' curves over their common ln Fr range (NaN: none).
double overlap_rms(const LevelCurve& a, const LevelCurve& b, double& weight) {
  const double lo = std::max(a.x_lo, b.x_lo), hi = std::min(a.x_hi, b.x_hi);
  weight = 0;
  if (!(hi > lo)) return kNaN;
  constexpr int kGrid = 21;
  double s2 = 0;
  for (int i = 0; i < kGrid; ++i) {
    const double x = lo + (hi - lo) * i / (kGrid - 1);
    const double d = poly_at(a.coef, x) - poly_at(b.coef, x);
    s2 += d * d;
  }
  weight = 1;
  return s2 / kGrid;
}

/// The nested analysis of variance of CollapseRow (level within Froude number, repeats within cell).
void level_effect(const std::vector<Point>& pts, CollapseRow& r) {
  const std::vector<int> group = froude_groups_of(pts);  // over all levels
  // cells[(group, level)] -> the points' y
  std::map<std::pair<int, double>, std::vector<double>> cells;
  for (std::size_t i = 0; i < pts.size(); ++i) cells[{group[i], pts[i].level_m_s2}].push_back(pts[i].y);
  std::map<int, int> levels_at;
  for (const auto& [key, ys] : cells) ++levels_at[key.first];
  double ss_within = 0, ss_between = 0, n_sum = 0;
  int df_within = 0, df_between = 0, n_cells = 0;
  std::map<int, std::pair<double, double>> group_sum;  // group -> (sum y, n), shared Froude numbers only
  for (const auto& [key, ys] : cells) {
    double mean = 0;
    for (double y : ys) mean += y;
    mean /= static_cast<double>(ys.size());
    for (double y : ys) ss_within += (y - mean) * (y - mean);
    df_within += static_cast<int>(ys.size()) - 1;
    if (levels_at[key.first] < 2) continue;
    group_sum[key.first].first += mean * static_cast<double>(ys.size());
    group_sum[key.first].second += static_cast<double>(ys.size());
  }
  for (const auto& [key, ys] : cells) {
    if (levels_at[key.first] < 2) continue;
    double mean = 0;
    for (double y : ys) mean += y;
    mean /= static_cast<double>(ys.size());
    const double g_mean = group_sum[key.first].first / group_sum[key.first].second;
    ss_between += static_cast<double>(ys.size()) * (mean - g_mean) * (mean - g_mean);
    n_sum += static_cast<double>(ys.size());
    ++n_cells;
  }
  for (const auto& [g, n] : levels_at)
    if (n >= 2) df_between += n - 1;
  r.cells = n_cells;
  r.level_df = df_between;
  r.repeat_df = df_within;
  if (df_between < 1 || df_within < 1) {
    r.level_scatter_pct = r.repeat_scatter_pct = r.level_f = r.level_p = kNaN;
    return;
  }
  const double ms_between = ss_between / df_between, ms_within = ss_within / df_within;
  const double n_per_cell = n_sum / n_cells;
  r.repeat_scatter_pct = pct(std::sqrt(ms_within));
  r.level_scatter_pct = pct(std::sqrt(std::max(0.0, (ms_between - ms_within) / n_per_cell)));
  r.level_f = ms_within > 0 ? ms_between / ms_within : kNaN;
  r.level_p = f_upper_p(r.level_f, df_between, df_within);
}

CollapseRow collapse_of(const std::string& metric, const std::vector<Point>& pts) {
  CollapseRow r;
  r.metric = metric;
  r.trials = static_cast<int>(pts.size());
  std::map<double, std::vector<Point>> by_level;
  for (const auto& p : pts) by_level[p.level_m_s2].push_back(p);
  r.levels = static_cast<int>(by_level.size());
  if (pts.size() < 3) {
    r.common_scatter_pct = r.within_scatter_pct = r.between_levels_pct = r.collapse_ratio = kNaN;
    r.level_scatter_pct = r.repeat_scatter_pct = r.level_f = r.level_p = kNaN;
    return r;
  }
  const Eigen::VectorXd common = poly_fit(pts, std::min(kCollapseDegree, distinct_x(pts) - 1));
  double ss_common = 0, ss_within = 0;
  for (const auto& p : pts) ss_common += std::pow(p.y - poly_at(common, p.x), 2);
  std::vector<LevelCurve> curves;
  int dof_within = 0;
  for (const auto& [g, lp] : by_level) {
    const int degree = std::max(0, std::min(kCollapseDegree, distinct_x(lp) - 1));
    LevelCurve c;
    c.coef = poly_fit(lp, degree);
    c.x_lo = c.x_hi = lp.front().x;
    for (const auto& p : lp) {
      ss_within += std::pow(p.y - poly_at(c.coef, p.x), 2);
      c.x_lo = std::min(c.x_lo, p.x);
      c.x_hi = std::max(c.x_hi, p.x);
    }
    dof_within += static_cast<int>(lp.size()) - (degree + 1);
    curves.push_back(c);
  }
  const int dof_common = static_cast<int>(pts.size()) - static_cast<int>(common.size());
  const double s_common = std::sqrt(ss_common / std::max(1, dof_common));
  const double s_within = dof_within > 0 ? std::sqrt(ss_within / dof_within) : kNaN;
  double between = 0, pairs = 0;
  for (std::size_t i = 0; i < curves.size(); ++i)
    for (std::size_t j = i + 1; j < curves.size(); ++j) {
      double w = 0;
      const double ms = overlap_rms(curves[i], curves[j], w);
      if (w > 0) between += ms, pairs += w;
    }
  r.common_scatter_pct = pct(s_common);
  r.within_scatter_pct = pct(s_within);
  r.between_levels_pct = pairs > 0 ? pct(std::sqrt(between / pairs)) : kNaN;
  r.collapse_ratio = s_within > 0 ? s_common / s_within : kNaN;
  level_effect(pts, r);
  return r;
}

}  // namespace

std::vector<ScaledTrial> scaled_trials(const Campaign& c) {
  std::vector<ScaledTrial> out;
  for (const auto& t : c.trials) {
    const double g = t.info.gravity_m_s2, D = t.info.projectile_diameter_m;
    const auto& m = t.processed.metrics;
    if (!(g > 0) || !(D > 0)) continue;
    ScaledTrial s;
    s.gravity_m_s2 = g;
    s.froude = m.vc_m_s / std::sqrt(g * D);
    // A clipped record's apeak (and a zstop the clip moved) is NaN here: out of the collapse.
    s.zstop_over_D = clip_exclusion(t, ClippedMetric::zstop).empty() ? m.zstop_m / D : kNaN;
    s.tstop_sqrt_g_over_D = m.tstop_s * std::sqrt(g / D);
    s.apeak_over_g = clip_exclusion(t, ClippedMetric::apeak).empty() ? m.apeak_m_s2 / g : kNaN;
    out.push_back(s);
  }
  return out;
}

std::vector<CollapseRow> collapse(const Campaign& c) {
  const auto st = scaled_trials(c);
  const std::vector<double> levels = c.gravity_levels();
  auto level_of = [&](double g) {
    for (double l : levels)
      if (same_gravity_level(g, l)) return l;
    return g;
  };
  std::vector<CollapseRow> rows;
  const std::pair<const char*, double ScaledTrial::*> metrics[] = {
      {"zstop_over_D", &ScaledTrial::zstop_over_D},
      {"tstop_sqrt_g_over_D", &ScaledTrial::tstop_sqrt_g_over_D},
      {"apeak_over_g", &ScaledTrial::apeak_over_g}};
  for (const auto& [name, field] : metrics) {
    std::vector<Point> pts;
    for (const auto& s : st)
      if (s.froude > 0 && s.*field > 0)
        pts.push_back({level_of(s.gravity_m_s2), std::log(s.froude), std::log(s.*field)});
    rows.push_back(collapse_of(name, pts));
  }
  return rows;
}

}  // namespace gravsweep::results
