// Collision models, fits, cross-validation, residual analysis and discovery (see model.h).
#include "results/model/model.h"

#include "results/model/model_internal.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>

#include "engine/core/error.h"
#include "spec/problems.h"
#include "spec/schemas.h"

namespace gravsweep::results {

// ---------------------------------------------------------------------------------------------
// Specs

std::string ModelSpec::name() const {
  std::string s;
  for (const auto& t : terms) {
    if (!s.empty()) s += "+";
    s += t.term->name;
    if (t.g_scaled())
      s += fmt::format(":g^{:g}", t.g_power);
    else if (t.per_gravity != t.term->per_gravity)
      s += t.per_gravity ? ":per_gravity" : ":shared";
  }
  return s;
}

bool ModelSpec::has(const std::string& term_name) const {
  return std::any_of(terms.begin(), terms.end(), [&](const ModelTerm& t) { return t.term->name == term_name; });
}

bool one_law_for_all_levels(const ModelSpec& spec) {
  return std::none_of(spec.terms.begin(), spec.terms.end(), [](const ModelTerm& t) { return t.per_gravity; });
}

namespace {

/// The terms of a model file (schemas/model.schema.json, checked by spec/schemas.h; then each name
/// looked up: a generated form's numbers must be in range). Throws spec::SpecError naming the file
/// and the JSON pointer of every problem.
std::vector<ModelTerm> model_file_terms(const std::string& file) {
  nlohmann::json j = spec::read_spec_file(file, spec::Schema::model);
  spec::Problems problems;
  spec::validator(spec::Schema::model).collect(j, problems.list());
  if (!problems.empty()) throw spec::SpecError(file, std::move(problems.list()));
  std::vector<ModelTerm> terms;
  for (std::size_t i = 0; i < j["terms"].size(); ++i) {
    const auto& e = j["terms"][i];
    const std::string name = e["name"].get<std::string>();
    ModelTerm mt;
    try {
      mt.term = &find_term(name);
    } catch (const ConfigError& ex) {
      problems.add(fmt::format("/terms/{}/name", i), e["name"], ex.what());
      continue;
    }
    mt.per_gravity = e.contains("shared") ? !e["shared"].get<bool>() : mt.term->per_gravity;
    if (e.contains("g_power")) {
      mt.g_power = e["g_power"].get<double>();
      mt.per_gravity = false;
    }
    mt.scale = e.value("scale", 1.0);
    terms.push_back(mt);
  }
  if (!problems.empty()) throw spec::SpecError(file, std::move(problems.list()));
  return terms;
}

/// ":g^p": one constant for all levels times (g / kGPowerReference_m_s2)^p.
void set_g_power(ModelTerm& mt, const std::string& mode, const std::string& text) {
  const std::string p = mode.substr(2);
  char* end = nullptr;
  const double x = std::strtod(p.c_str(), &end);
  if (p.empty() || end != p.c_str() + p.size() || !std::isfinite(x) || std::abs(x) > 4)
    throw std::invalid_argument(
        fmt::format("model '{}': '{}' after ':' must be g^<power> with a power between -4 and 4", text, mode));
  mt.g_power = x;
  mt.per_gravity = false;
}

}  // namespace

ModelSpec parse_model(const std::string& text) {
  ModelSpec spec;
  if (std::filesystem::exists(text) && std::filesystem::is_regular_file(text)) {
    spec.terms = model_file_terms(text);
  } else {
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, '+')) {
      if (item.empty()) continue;
      ModelTerm mt;
      std::string name = item;
      double scale = 1.0;
      // "*2.5" after a term is a synth scale; a '*' inside a generated form ("z^1*v^1") is not.
      if (auto p = name.rfind('*'); p != std::string::npos) {
        const std::string tail = name.substr(p + 1);
        char* end = nullptr;
        const double x = std::strtod(tail.c_str(), &end);
        if (!tail.empty() && end == tail.c_str() + tail.size()) {
          scale = x;
          name = name.substr(0, p);
        }
      }
      std::string mode;
      if (auto p = name.find(':'); p != std::string::npos) {
        mode = name.substr(p + 1);
        name = name.substr(0, p);
      }
      mt.term = &find_term(name);
      mt.per_gravity = mt.term->per_gravity;
      if (mode == "shared")
        mt.per_gravity = false;
      else if (mode == "per_gravity")
        mt.per_gravity = true;
      else if (mode.rfind("g^", 0) == 0)
        set_g_power(mt, mode, text);
      else if (!mode.empty())
        throw std::invalid_argument(fmt::format(
            "model '{}': '{}' after ':' must be shared, per_gravity or g^<power> (e.g. g^0.3)", text, mode));
      mt.scale = scale;
      spec.terms.push_back(mt);
    }
  }
  if (spec.terms.empty())
    throw std::invalid_argument(fmt::format("model '{}': no terms (example: base+depth_friction)", text));
  return spec;
}

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

double binom_tail_half(int k, int n) {
  // P(X >= k), X ~ Binomial(n, 1/2)
  double p = 0;
  for (int i = k; i <= n; ++i)
    p += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) - n * std::log(2.0));
  return std::min(1.0, p);
}

/// One-sided Wilcoxon signed-rank test that the per-trial improvements d_i are centred above 0:
/// one value per trial, so n is the number of trials (never samples). Normal approximation with
/// continuity correction (n >= 10 here); ties get average ranks.
bool cannot_tell_apart(const std::vector<double>& other_worse) {
  std::vector<double> other_better(other_worse.size());
  std::transform(other_worse.begin(), other_worse.end(), other_better.begin(), [](double x) { return -x; });
  return signed_rank_p(other_worse) >= kEquivalentLevel && signed_rank_p(other_better) >= kEquivalentLevel;
}

double signed_rank_p(const std::vector<double>& d) {
  std::vector<std::pair<double, bool>> a;
  for (double x : d)
    if (x != 0.0 && std::isfinite(x)) a.push_back({std::abs(x), x > 0});
  const double n = static_cast<double>(a.size());
  if (a.size() < 5) return 1.0;
  std::sort(a.begin(), a.end());
  double wplus = 0;
  for (std::size_t i = 0; i < a.size();) {
    std::size_t j = i;
    while (j < a.size() && a[j].first == a[i].first) ++j;
    const double rank = 0.5 * (static_cast<double>(i + 1) + static_cast<double>(j));
    for (std::size_t k = i; k < j; ++k)
      if (a[k].second) wplus += rank;
    i = j;
  }
  const double mean = n * (n + 1) / 4, sd = std::sqrt(n * (n + 1) * (2 * n + 1) / 24);
  const double z = (wplus - mean - 0.5) / sd;
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

std::vector<int> fold_of(const Campaign& c, int folds, unsigned seed) {
  if (folds == kLeaveOneProjectileOut) return projectile_index(c);
  // Stratified by gravity level: shuffle within each level, deal round-robin.
  std::mt19937 rng(seed);
  std::vector<int> idx(c.trials.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::vector<double> key(idx.size());
  for (auto& k : key) k = std::uniform_real_distribution<double>(0, 1)(rng);
  const std::vector<double> levels = c.gravity_levels();  // descending
  std::vector<int> level(idx.size(), 0);
  for (std::size_t i = 0; i < idx.size(); ++i)
    while (!same_gravity_level(levels[static_cast<std::size_t>(level[i])], c.trials[i].info.gravity_m_s2)) ++level[i];
  std::sort(idx.begin(), idx.end(),
            [&](int a, int b) { return level[a] != level[b] ? level[a] < level[b] : key[a] < key[b]; });
  std::vector<int> f(idx.size());
  for (std::size_t r = 0; r < idx.size(); ++r) f[idx[r]] = static_cast<int>(r % folds);
  return f;
}

}  // namespace detail

using namespace detail;

std::vector<int> projectile_index(const Campaign& c, int* count) {
  std::vector<std::pair<double, double>> seen;
  std::vector<int> index;
  for (const auto& t : c.trials) {
    const std::pair<double, double> p{t.info.projectile_diameter_m, t.info.projectile_mass_kg};
    const auto it = std::find_if(seen.begin(), seen.end(), [&p](const auto& q) {
      return std::abs(q.first - p.first) <= 1e-9 * q.first && std::abs(q.second - p.second) <= 1e-9 * q.second;
    });
    index.push_back(static_cast<int>(it - seen.begin()));
    if (it == seen.end()) seen.push_back(p);
  }
  if (count) *count = static_cast<int>(seen.size());
  return index;
}

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
  const bool one_law = one_law_for_all_levels(spec) || spec.trial_force_units;
  for (int ti : used) {
    const MeasuredTrial& t = c.trials[static_cast<std::size_t>(ti)];
    const int gi = m.gravity_index(t.info.gravity_m_s2);
    const double n_t = static_cast<double>(t.fit_end - t.fit_begin);
    // Trials weighted equally. A law for one gravity level at a time takes residuals in units of
    // g (its trials' forces span a few m g); one law for all levels takes each trial's residuals in
    // units of its own force (trial_force_scale_m_s2), as its trials span Froude 0.2-10 and forces
    // from m g to 300 m g.
    const double scale_m_s2 = one_law ? trial_force_scale_m_s2(t) : t.info.gravity_m_s2;
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

std::vector<const std::vector<double>*> same_level_fluctuations(const Campaign& c,
                                                                const std::vector<std::vector<double>>& fluct,
                                                                std::size_t i) {
  std::vector<const std::vector<double>*> out;
  for (std::size_t j = 0; j < fluct.size() && out.size() < kMaxFluctuationTrials; ++j)
    if (j != i && !fluct[j].empty() && same_gravity_level(c.trials[j].info.gravity_m_s2, c.trials[i].info.gravity_m_s2))
      out.push_back(&fluct[j]);
  return out;
}

HeldOut cross_validate(const ModelSpec& spec, const Campaign& c, int folds, unsigned seed, bool with_predictions) {
  HeldOut h;
  h.trace_mse.assign(c.trials.size(), NAN);
  h.pred.assign(c.trials.size(), Prediction{});
  const auto f = fold_of(c, folds, seed);
  for (int k = 0; k < fold_count(f); ++k) {
    std::vector<bool> mask(c.trials.size());
    bool any = false;
    for (std::size_t i = 0; i < mask.size(); ++i) {
      mask[i] = f[i] != k;
      any = any || !mask[i];
    }
    if (!any) continue;
    const FittedModel m = fit_model(spec, c, mask);
    // The training trials' fluctuations about the model, for apeak as measured (model.h).
    std::vector<std::vector<double>> fluct(with_predictions ? c.trials.size() : 0);
    for (std::size_t j = 0; j < fluct.size(); ++j)
      if (mask[j]) fluct[j] = relative_residuals(m, c.trials[j]);
    for (std::size_t i = 0; i < mask.size(); ++i) {
      if (mask[i]) continue;
      h.trace_mse[i] = trial_trace_mse(m, c.trials[i]);
      if (with_predictions) h.pred[i] = predict(m, c.trials[i], same_level_fluctuations(c, fluct, i));
    }
  }
  return h;
}

HeldOut cross_validate(const ModelSpec& spec, const Campaign& c, int folds, unsigned seed) {
  return cross_validate(spec, c, folds, seed, true);
}

ErrorSummary summarize(const Campaign& c, const HeldOut& h) {
  ErrorSummary e;
  double st = 0, str = 0, sz = 0, szr = 0, stt = 0, sttr = 0, sa = 0, sar = 0;
  int nt = 0, nz = 0, ntt = 0, na = 0;
  for (std::size_t i = 0; i < c.trials.size(); ++i) {
    const auto& t = c.trials[i];
    const auto& m = t.processed.metrics;
    if (std::isfinite(h.trace_mse[i])) {
      double ref = 0;
      std::size_t n = 0;
      for (std::size_t k = t.fit_begin; k < t.fit_end; ++k, ++n)
        ref += std::pow(t.processed.accel_up_m_s2[k] + t.info.gravity_m_s2, 2);
      st += h.trace_mse[i];
      if (n && ref > 0) str += h.trace_mse[i] / (ref / static_cast<double>(n));
      ++nt;
    }
    const auto& p = h.pred[i];
    if (!p.stopped) continue;
    // A clipped record's apeak (a lower bound), and its zstop when the clip moved it, are no
    // measurement to hold a prediction against (clip_exclusion).
    if (clip_exclusion(t, ClippedMetric::zstop).empty()) {
      sz += std::pow(1e3 * (p.zstop_m - m.zstop_m), 2);
      szr += std::pow((p.zstop_m - m.zstop_m) / m.zstop_m, 2);
      ++nz;
    }
    stt += std::pow(1e3 * (p.tstop_s - m.tstop_s), 2);
    sttr += std::pow((p.tstop_s - m.tstop_s) / m.tstop_s, 2);
    ++ntt;
    if (clip_exclusion(t, ClippedMetric::apeak).empty()) {
      sa += std::pow(p.apeak_m_s2 - m.apeak_m_s2, 2);
      sar += std::pow((p.apeak_m_s2 - m.apeak_m_s2) / m.apeak_m_s2, 2);
      ++na;
    }
  }
  e.trials = nt;
  if (nt) {
    e.trace_rms_m_s2 = std::sqrt(st / nt);
    e.trace_rel_pct = 100 * std::sqrt(str / nt);
  }
  auto rms = [](double s, int n) { return n ? std::sqrt(s / n) : NAN; };
  e.zstop_rms_mm = rms(sz, nz);
  e.zstop_rel_pct = 100 * rms(szr, nz);
  e.tstop_rms_ms = rms(stt, ntt);
  e.tstop_rel_pct = 100 * rms(sttr, ntt);
  e.apeak_rms_m_s2 = rms(sa, na);
  e.apeak_rel_pct = 100 * rms(sar, na);
  return e;
}

}  // namespace gravsweep::results
