// Least-squares fits of collision models to a campaign's traces (see fit.h).
#include "results/model/model_spec.h"
#include "results/model/fit.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "engine/core/error.h"
#include "results/model/model_internal.h"

namespace gravsweep::results {

// ---------------------------------------------------------------------------------------------
// Columns and fits

namespace {

struct Layout {
  std::vector<int> offset;  ///< first column of each term
  int cols = 0;
  int G = 0;
};

Layout layout(const ModelSpec& s, int G) {
  Layout L;
  L.G = G;
  for (const auto& t : s.terms) {
    L.offset.push_back(L.cols);
    L.cols += static_cast<int>(t.term->params.size()) * (t.per_gravity ? G : 1);
  }
  return L;
}

/// Writes the full feature row (zeros for other gravity levels).
void feature_row(const ModelSpec& s, const Layout& L, int gi, const TermContext& c, double* row) {
  std::fill(row, row + L.cols, 0.0);
  double f[8];
  for (std::size_t i = 0; i < s.terms.size(); ++i) {
    const auto& t = s.terms[i];
    t.term->features(c, f);
    const int np = static_cast<int>(t.term->params.size());
    const double g_factor = t.g_scaled() ? std::pow(c.g_m_s2 / kGPowerReference_m_s2, t.g_power) : 1.0;
    for (int j = 0; j < np; ++j) f[j] *= g_factor;
    for (int j = 0; j < np; ++j) {
      const int col = L.offset[i] + (t.per_gravity ? j * L.G + gi : j);
      row[col] = f[j];
    }
  }
}

}  // namespace

namespace detail {

TermContext context(const MeasuredTrial& t, std::size_t k) {
  const auto& p = t.processed;
  TermContext c;
  c.z_m = p.depth_m[k];
  c.v_m_s = p.velocity_down_m_s[k];
  c.g_m_s2 = t.info.gravity_m_s2;
  c.t_since_contact_s = p.t_s[k] - p.metrics.t_start_s;
  c.fill_height_m = t.info.fill_height_m;
  c.diameter_m = t.info.projectile_diameter_m;
  c.mass_kg = t.info.projectile_mass_kg;
  if (t.info.grain_diameter_m > 0) c.grain_diameter_m = t.info.grain_diameter_m;
  c.vc_m_s = p.metrics.vc_m_s;
  return c;
}

TermContext context(const Trial& i) {
  TermContext c;
  c.g_m_s2 = i.gravity_m_s2;
  c.fill_height_m = i.fill_height_m;
  c.diameter_m = i.projectile_diameter_m;
  c.mass_kg = i.projectile_mass_kg;
  if (i.grain_diameter_m > 0) c.grain_diameter_m = i.grain_diameter_m;
  c.vc_m_s = i.impact_speed_m_s;
  c.v_m_s = i.impact_speed_m_s;
  return c;
}

}  // namespace detail

using namespace detail;

int FittedModel::gravity_index(double g) const {
  for (std::size_t i = 0; i < gravity_levels.size(); ++i)
    if (same_gravity_level(gravity_levels[i], g)) return static_cast<int>(i);
  return -1;
}

double FittedModel::force(const TermContext& c) const {
  int gi = gravity_index(c.g_m_s2);
  // A law without a parameter per gravity level holds at any g, a level it was not fitted on
  // included (the prediction of a held-out level); one with per-level parameters does not.
  if (gi < 0 && !one_law_for_all_levels(spec))
    throw std::invalid_argument(fmt::format("model has no gravity level {} m/s2", c.g_m_s2));
  gi = std::max(gi, 0);
  const Layout L = layout(spec, static_cast<int>(gravity_levels.size()));
  std::vector<double> row(static_cast<std::size_t>(L.cols));
  feature_row(spec, L, gi, c, row.data());
  double r = 0;
  for (int j = 0; j < L.cols; ++j) r += coef(j) * row[static_cast<std::size_t>(j)];
  return r;
}

FittedModel fit_model(const ModelSpec& spec, const Campaign& c) {
  return fit_model(spec, c, std::vector<bool>(c.trials.size(), true));
}

FittedModel fit_model(const ModelSpec& spec, const Campaign& c, const std::vector<bool>& mask) {
  std::vector<int> count(mask.size());
  std::transform(mask.begin(), mask.end(), count.begin(), [](bool b) { return b ? 1 : 0; });
  return fit_model(spec, c, count);
}

namespace {

/// The RMS of a_up + g over a trial's fit window (m/s2): the scale of its resisting force per
/// mass, to which the grain-scale fluctuations are proportional (force chains carry a share of the
/// force, not a fixed amount). Dividing each trial's residuals by it keeps a Froude 10 drop, whose
/// drag is 300 m g, from outweighing the quasi-static drops of every level in a fit of one law
/// for all levels; g when the window has no finite sample.
double trial_force_scale_m_s2(const MeasuredTrial& t) {
  double s = 0;
  std::size_t n = 0;
  for (std::size_t k = t.fit_begin; k < t.fit_end; ++k) {
    const double f = t.processed.accel_up_m_s2[k] + t.info.gravity_m_s2;
    if (std::isfinite(f)) s += f * f, ++n;
  }
  return n > 0 && s > 0 ? std::sqrt(s / static_cast<double>(n)) : t.info.gravity_m_s2;
}

/// The names of the fit's columns, in the order of layout(): term.param, with @g=<level> for a
/// term fitted per gravity level.
std::vector<std::string> column_names(const ModelSpec& spec, const std::vector<double>& gravity_levels) {
  std::vector<std::string> names;
  for (const auto& st : spec.terms)
    for (const auto& param : st.term->params) {
      // One parameter of a term as a term of its own (scaled_base.phi) is named once.
      const bool named =
          st.term->name.size() > param.size() &&
          st.term->name.compare(st.term->name.size() - param.size() - 1, std::string::npos, "." + param) == 0;
      const std::string column = named ? st.term->name : fmt::format("{}.{}", st.term->name, param);
      if (st.per_gravity)
        for (double g : gravity_levels) names.push_back(fmt::format("{}@g={}", column, g));
      else
        names.push_back(column);
    }
  return names;
}

/// The least-squares fit of fit_model, unchecked; `not_finite` gets the trials whose rows of the
/// problem (features or m (a_up + g)) hold a value that is not finite.
FittedModel fit_unchecked(const ModelSpec& spec, const Campaign& c, const std::vector<int>& count,
                          std::vector<int>& not_finite) {
  FittedModel m;
  m.spec = spec;
  m.gravity_levels = c.gravity_levels();
  const int G = static_cast<int>(m.gravity_levels.size());
  const Layout L = layout(spec, G);
  m.column_names = column_names(spec, m.gravity_levels);
  std::size_t rows = 0;
  std::vector<int> used;
  for (std::size_t ti = 0; ti < c.trials.size(); ++ti)
    if (count[ti] > 0 && c.trials[ti].fit_end > c.trials[ti].fit_begin) {
      rows += c.trials[ti].fit_end - c.trials[ti].fit_begin;
      used.push_back(static_cast<int>(ti));
    }
  Eigen::MatrixXd X(static_cast<Eigen::Index>(rows), L.cols);
  Eigen::VectorXd y(static_cast<Eigen::Index>(rows)), w(static_cast<Eigen::Index>(rows));
  std::vector<int> cluster(rows);
  Eigen::Index r = 0;
  std::vector<double> row(static_cast<std::size_t>(L.cols));
  const bool own_force = spec.residual_units == ResidualUnits::trial_force ||
                         (spec.residual_units == ResidualUnits::automatic && one_law_for_all_levels(spec));
  for (int ti : used) {
    const MeasuredTrial& t = c.trials[static_cast<std::size_t>(ti)];
    const int gi = m.gravity_index(t.info.gravity_m_s2);
    const double n_t = static_cast<double>(t.fit_end - t.fit_begin);
    // Trials weighted equally. A law for one gravity level at a time takes residuals in units of
    // g (its trials' forces span a few m g); one law for all levels takes each trial's residuals in
    // units of its own force (trial_force_scale_m_s2), as its trials span Froude 0.2-10 and forces
    // from m g to 300 m g (ModelSpec::residual_units).
    const double scale_m_s2 = own_force ? trial_force_scale_m_s2(t) : t.info.gravity_m_s2;
    const double wt = count[static_cast<std::size_t>(ti)] / (n_t * scale_m_s2 * scale_m_s2);
    for (std::size_t k = t.fit_begin; k < t.fit_end; ++k, ++r) {
      const TermContext ctx = context(t, k);
      feature_row(spec, L, gi, ctx, row.data());
      for (int j = 0; j < L.cols; ++j) X(r, j) = row[static_cast<std::size_t>(j)];
      y(r) = t.info.projectile_mass_kg * (t.processed.accel_up_m_s2[k] + t.info.gravity_m_s2);
      if ((!std::isfinite(y(r)) || !X.row(r).allFinite()) && (not_finite.empty() || not_finite.back() != ti))
        not_finite.push_back(ti);
      w(r) = wt;
      cluster[static_cast<std::size_t>(r)] = ti;
    }
  }
  m.trials_used = static_cast<int>(used.size());
  m.samples_used = rows;
  const Eigen::VectorXd sw = w.cwiseSqrt();
  Eigen::MatrixXd Xw = sw.asDiagonal() * X;
  const Eigen::VectorXd yw = sw.cwiseProduct(y);
  Eigen::VectorXd scale(L.cols);
  for (int j = 0; j < L.cols; ++j) {
    const double n = Xw.col(j).norm();
    scale(j) = n > 0 ? n : 1.0;
    Xw.col(j) /= scale(j);
  }
  const Eigen::VectorXd sol = Xw.completeOrthogonalDecomposition().solve(yw);
  m.coef = sol.cwiseQuotient(scale);
  // Cluster-robust covariance (trials as clusters): B M B with B = (X'WX)^+.
  const Eigen::MatrixXd B = (Xw.transpose() * Xw).completeOrthogonalDecomposition().pseudoInverse();
  const Eigen::VectorXd res = yw - Xw * sol;
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(L.cols, L.cols);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(L.cols);
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(rows); ++i) {
    u += Xw.row(i).transpose() * res(i);
    if (i + 1 == static_cast<Eigen::Index>(rows) ||
        cluster[static_cast<std::size_t>(i + 1)] != cluster[static_cast<std::size_t>(i)]) {
      meat += u * u.transpose();
      u.setZero();
    }
  }
  const double Gc = std::max(2.0, static_cast<double>(used.size()));
  const Eigen::MatrixXd covs = B * meat * B * (Gc / (Gc - 1.0));
  const Eigen::MatrixXd Sinv = scale.cwiseInverse().asDiagonal();
  m.cov = Sinv * covs * Sinv;
  return m;
}

/// The trials a non-finite fit comes from: those with non-finite rows, else each trial whose
/// leaving-out makes the fit finite.
std::vector<int> trials_behind(const ModelSpec& spec, const Campaign& c, const std::vector<int>& count,
                               std::vector<int> not_finite) {
  if (!not_finite.empty()) return not_finite;
  std::vector<int> out;
  for (std::size_t ti = 0; ti < c.trials.size(); ++ti) {
    if (count[ti] == 0) continue;
    std::vector<int> without = count;
    without[ti] = 0;
    std::vector<int> ignored;
    if (fit_unchecked(spec, c, without, ignored).coef.allFinite()) out.push_back(static_cast<int>(ti));
  }
  return out;
}

}  // namespace

FittedModel fit_model(const ModelSpec& spec, const Campaign& c, const std::vector<int>& count) {
  std::vector<int> not_finite;
  FittedModel m = fit_unchecked(spec, c, count, not_finite);
  if (m.coef.allFinite()) return m;
  std::string params, trials;
  for (Eigen::Index j = 0; j < m.coef.size(); ++j)
    if (!std::isfinite(m.coef(j))) params += (params.empty() ? "" : ", ") + m.column_names[static_cast<std::size_t>(j)];
  for (int ti : trials_behind(spec, c, count, not_finite)) {
    const Trial& t = c.trials[static_cast<std::size_t>(ti)].info;
    trials += fmt::format("{}{} (mass {} kg, projectile diameter {} m, grain diameter {} m, gravity {} m/s2)",
                          trials.empty() ? "" : "; ", t.trial_id, t.projectile_mass_kg, t.projectile_diameter_m,
                          t.grain_diameter_m, t.gravity_m_s2);
  }
  throw NumericalFailure(
      fmt::format("model fit '{}': parameter(s) not finite: {}; {}", spec.name(), params,
                  trials.empty() ? "no single trial is responsible (several trials together, or the model)"
                                 : "the trial(s) responsible: " + trials),
      -1, -1);
}

double trial_trace_mse(const FittedModel& m, const MeasuredTrial& t) {
  double s = 0;
  std::size_t n = 0;
  for (std::size_t k = t.fit_begin; k < t.fit_end; ++k) {
    const TermContext ctx = context(t, k);
    const double a_model = m.force(ctx) / t.info.projectile_mass_kg - t.info.gravity_m_s2;
    const double r = t.processed.accel_up_m_s2[k] - a_model;
    s += r * r;
    ++n;
  }
  return n ? s / static_cast<double>(n) : NAN;
}

}  // namespace gravsweep::results
