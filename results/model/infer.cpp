#include "results/model/infer.h"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <random>
#include <stdexcept>

#include "results/model/model.h"
#include "results/model/stats.h"

namespace gravsweep::results {

namespace {

constexpr double kZ95 = 1.959964;
/// The proposal of the second stage: the pilot's posterior widened by this factor in standard
/// deviation, mixed with the prior at this share (a defensive mixture: no region of the prior
/// is left unsampled when the pilot missed it).
constexpr double kProposalWidening = 2.0;
constexpr double kProposalPriorShare = 0.2;
/// Rounds of the second stage at most, and the effective sample size (a share of --samples) at
/// which they stop.
constexpr int kInferRounds = 4;
constexpr double kInferTargetEffectiveShare = 0.1;
/// A metric measured with no error of its own, at a Froude number where the law has no form
/// error, gets this relative sigma, %.
constexpr double kInferFallbackSigmaPct = 10.0;

/// The prior of one constant in its sampling variable u: u = ln(value) for a positive constant,
/// the value itself otherwise; normal in u with mean `mean` and standard deviation `sd`.
struct PriorAxis {
  bool log_scale = true;
  double mean = 0, sd = 1;
  [[nodiscard]] double value(double u) const { return log_scale ? std::exp(u) : u; }
};

std::vector<PriorAxis> prior_of(const SavedLaw& law, double width) {
  std::vector<PriorAxis> axes;
  for (std::size_t i = 0; i < law.values.size(); ++i) {
    const double v = law.values[i];
    PriorAxis a;
    a.log_scale = v > 0;
    a.mean = a.log_scale ? std::log(v) : v;
    const double se = std::sqrt(std::max(0.0, law.covariance[i][i]));
    a.sd = a.log_scale ? std::log(width) : std::max((width - 1) * std::abs(v), se);
    if (!(a.sd > 0)) a.sd = 1.0;  // a constant fitted to exactly zero with no spread
    axes.push_back(a);
  }
  return axes;
}

/// The metrics by index k (0 zstop, 1 tstop, 2 apeak), as law.h's form_error_at numbers them.
constexpr std::array<const char*, 3> kName{"zstop_m", "tstop_s", "apeak_m_s2"};

/// The measured metrics with their log-normal sigma (relative, as a fraction).
struct Observed {
  int metric = 0;  ///< 0 zstop, 1 tstop, 2 apeak
  double value = NAN, sigma = NAN;
};

std::vector<Observed> observed_of(const SavedLaw& law, double froude, const InferMeasurement& m) {
  const std::array<double, 3> value{m.zstop_m, m.tstop_s, m.apeak_m_s2};
  const std::array<double, 3> own{m.zstop_error_pct, m.tstop_error_pct, m.apeak_error_pct};
  std::vector<Observed> out;
  for (int k = 0; k < 3; ++k) {
    if (std::isnan(value[k])) continue;
    if (!(value[k] > 0) || !std::isfinite(value[k]))
      throw std::invalid_argument(fmt::format("{} = {}: expected a positive measured value", kName[k], value[k]));
    const double form = form_error_at(law.form_error, froude, k);
    double pct = std::hypot(std::isfinite(form) ? form : 0.0, own[k]);
    if (!(pct > 0)) pct = kInferFallbackSigmaPct;
    out.push_back({k, value[k], pct / 100});
  }
  if (out.empty()) throw std::invalid_argument("nothing measured: give at least the stopping depth");
  return out;
}

double metric_of(const Prediction& p, int k) { return k == 0 ? p.zstop_m : k == 1 ? p.tstop_s : p.apeak_m_s2; }

/// Draws from the prior and the law's predictions at them.
struct Sample {
  Eigen::VectorXd u;
  Prediction pred;
  double log_like = -INFINITY;
};

class Posterior {
 public:
  Posterior(const SavedLaw& law, const LawCase& c, std::vector<PriorAxis> prior, std::vector<Observed> obs)
      : model_(law_model(law)), ctx_(law_case_context(law, c)), prior_(std::move(prior)), obs_(std::move(obs)) {}

  [[nodiscard]] std::size_t dims() const { return prior_.size(); }
  [[nodiscard]] const std::vector<PriorAxis>& prior() const { return prior_; }

  Sample evaluate(const Eigen::VectorXd& u) {
    Sample s;
    s.u = u;
    for (std::size_t i = 0; i < dims(); ++i) model_.coef[static_cast<Eigen::Index>(i)] = prior_[i].value(u[i]);
    s.pred = predict(model_, ctx_);
    if (!s.pred.stopped) return s;
    double ll = 0;
    for (const auto& o : obs_) {
      const double p = metric_of(s.pred, o.metric);
      if (!(p > 0) || !std::isfinite(p)) return s;
      const double r = (std::log(o.value) - std::log(p)) / o.sigma;
      ll -= 0.5 * r * r;
    }
    s.log_like = ll;
    return s;
  }

  [[nodiscard]] double log_prior(const Eigen::VectorXd& u) const {
    double lp = 0;
    for (std::size_t i = 0; i < dims(); ++i) {
      const double r = (u[i] - prior_[i].mean) / prior_[i].sd;
      lp -= 0.5 * r * r + std::log(prior_[i].sd);
    }
    return lp;
  }

  Eigen::VectorXd draw_prior(std::mt19937_64& rng) const {
    std::normal_distribution<double> n01;
    Eigen::VectorXd u(static_cast<Eigen::Index>(dims()));
    for (std::size_t i = 0; i < dims(); ++i) u[static_cast<Eigen::Index>(i)] = prior_[i].mean + prior_[i].sd * n01(rng);
    return u;
  }

 private:
  FittedModel model_;
  TermContext ctx_;
  std::vector<PriorAxis> prior_;
  std::vector<Observed> obs_;
};

/// Normalised weights from log-weights (the largest is 1 before normalisation).
std::vector<double> normalise(const std::vector<double>& log_w) {
  const double top = *std::max_element(log_w.begin(), log_w.end());
  std::vector<double> w(log_w.size(), 0.0);
  if (!std::isfinite(top)) return w;
  double sum = 0;
  for (std::size_t i = 0; i < w.size(); ++i) sum += (w[i] = std::exp(log_w[i] - top));
  for (double& x : w) x /= sum;
  return w;
}

/// The weighted mean and covariance of the samples' u, the covariance floored on its diagonal
/// by a hundredth of the prior's variance (a pilot that found one sample only).
void weighted_moments(const std::vector<Sample>& s, const std::vector<double>& w, const std::vector<PriorAxis>& prior,
                      Eigen::VectorXd& mean, Eigen::MatrixXd& cov) {
  const auto n = static_cast<Eigen::Index>(prior.size());
  mean = Eigen::VectorXd::Zero(n);
  for (std::size_t k = 0; k < s.size(); ++k) mean += w[k] * s[k].u;
  cov = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t k = 0; k < s.size(); ++k) {
    const Eigen::VectorXd d = s[k].u - mean;
    cov += w[k] * d * d.transpose();
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const double sd = prior[static_cast<std::size_t>(i)].sd;
    cov(i, i) = std::max(cov(i, i), 1e-2 * sd * sd);
  }
}

/// Log density of N(mean, cov) at u given cov's Cholesky factor.
double log_normal_density(const Eigen::VectorXd& u, const Eigen::VectorXd& mean,
                          const Eigen::LLT<Eigen::MatrixXd>& llt) {
  const Eigen::VectorXd z = llt.matrixL().solve(u - mean);
  const Eigen::MatrixXd l = llt.matrixL();
  return -0.5 * z.squaredNorm() - l.diagonal().array().log().sum();
}

/// One round of the second stage: samples from a mixture of the widened posterior so far and the
/// prior, each with its log-weight prior x likelihood / proposal (unnormalised: rounds pool).
std::vector<double> importance_stage(Posterior& post, const Eigen::VectorXd& mean, const Eigen::MatrixXd& cov, int n,
                                     std::mt19937_64& rng, std::vector<Sample>& out) {
  const Eigen::MatrixXd wide = kProposalWidening * kProposalWidening * cov;
  const Eigen::LLT<Eigen::MatrixXd> llt(wide);
  const Eigen::MatrixXd l = llt.matrixL();
  // log_prior and log_normal_density leave out the same 2 pi terms.
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> u01;
  std::vector<double> log_w;
  for (int k = 0; k < n; ++k) {
    Eigen::VectorXd u;
    if (u01(rng) < kProposalPriorShare) {
      u = post.draw_prior(rng);
    } else {
      Eigen::VectorXd z(mean.size());
      for (Eigen::Index i = 0; i < z.size(); ++i) z[i] = n01(rng);
      u = mean + l * z;
    }
    Sample s = post.evaluate(u);
    const double lp = post.log_prior(u);
    const double a = std::log(kProposalPriorShare) + lp;
    const double b = std::log(1 - kProposalPriorShare) + log_normal_density(u, mean, llt);
    const double q = std::max(a, b) + std::log1p(std::exp(-std::abs(a - b)));
    log_w.push_back(std::isfinite(s.log_like) && std::isfinite(q) ? lp + s.log_like - q : -INFINITY);
    out.push_back(std::move(s));
  }
  return log_w;
}

double effective_samples(const std::vector<double>& w) {
  double w2 = 0;
  for (double x : w) w2 += x * x;
  return w2 > 0 ? 1 / w2 : 0;
}

ConstantPosterior constant_posterior(const std::string& name, double campaign, const PriorAxis& a,
                                     const std::vector<Sample>& s, const std::vector<double>& w, std::size_t i) {
  ConstantPosterior c;
  c.name = name;
  c.campaign = campaign;
  c.log_scale = a.log_scale;
  c.prior_lo = a.value(a.mean - kZ95 * a.sd);
  c.prior_hi = a.value(a.mean + kZ95 * a.sd);
  std::vector<double> u;
  u.reserve(s.size());
  for (const auto& x : s) u.push_back(x.u[static_cast<Eigen::Index>(i)]);
  const double lo = weighted_quantile(u, w, 0.025), hi = weighted_quantile(u, w, 0.975);
  c.median = a.value(weighted_quantile(u, w, 0.5));
  c.lo = a.value(lo);
  c.hi = a.value(hi);
  c.shrink = 1 - (hi - lo) / (2 * kZ95 * a.sd);
  c.constrained = c.shrink >= 1 - kInferConstrainedShare;
  return c;
}

MetricPosterior metric_posterior(int k, const InferMeasurement& m, const std::vector<Observed>& obs,
                                 const LawPrediction& campaign, const std::vector<Sample>& s,
                                 const std::vector<double>& w) {
  MetricPosterior r;
  r.name = kName[k];
  r.measured = k == 0 ? m.zstop_m : k == 1 ? m.tstop_s : m.apeak_m_s2;
  for (const auto& o : obs)
    if (o.metric == k) r.sigma_pct = 100 * o.sigma;
  r.campaign = k == 0 ? campaign.zstop_m : k == 1 ? campaign.tstop_s : campaign.apeak_m_s2;
  std::vector<double> v;
  v.reserve(s.size());
  for (const auto& x : s) v.push_back(metric_of(x.pred, k));
  r.median = weighted_quantile(v, w, 0.5);
  r.lo = weighted_quantile(v, w, 0.025);
  r.hi = weighted_quantile(v, w, 0.975);
  return r;
}

}  // namespace

Inference infer_ground(const SavedLaw& law, const LawCase& c, const InferMeasurement& m, const InferOptions& o,
                       bool extrapolate) {
  if (!(o.prior_width > 1)) throw std::invalid_argument("the prior's width must be a factor above 1");
  if (o.samples < 100) throw std::invalid_argument("at least 100 samples");
  Inference r;
  r.campaign = predict_case(law, c);
  if (r.campaign.range == LawRangeFlag::refused) {
    if (!extrapolate) return r;
    const std::string note = r.campaign.note;
    r.campaign = predict_case(without_ranges(law), c);
    r.campaign.range = LawRangeFlag::refused;
    r.campaign.note = note + " (inferred: --extrapolate)";
  }
  const std::vector<Observed> obs = observed_of(law, r.campaign.froude, m);
  Posterior post(law, c, prior_of(law, o.prior_width), obs);
  std::mt19937_64 rng(o.seed);
  // Stage 1: a pilot from the prior.
  std::vector<Sample> pilot;
  std::vector<double> log_w;
  for (int k = 0; k < o.samples / 2; ++k) {
    pilot.push_back(post.evaluate(post.draw_prior(rng)));
    log_w.push_back(pilot.back().log_like);
  }
  if (!std::isfinite(*std::max_element(log_w.begin(), log_w.end())))
    throw std::invalid_argument(
        "no constants within the prior reproduce the measurement (the law's motion never stops, or stops nowhere "
        "near it): widen the prior (--prior-width)");
  Eigen::VectorXd mean;
  Eigen::MatrixXd cov;
  weighted_moments(pilot, normalise(log_w), post.prior(), mean, cov);
  // Stage 2: rounds of samples from a proposal refitted to all the rounds so far, pooled, until
  // the effective sample size reaches its target.
  std::vector<Sample> samples;
  std::vector<double> pooled, w;
  for (int round = 0; round < kInferRounds; ++round) {
    const std::vector<double> lw = importance_stage(post, mean, cov, o.samples / 2, rng, samples);
    pooled.insert(pooled.end(), lw.begin(), lw.end());
    w = normalise(pooled);
    r.effective_samples = effective_samples(w);
    if (r.effective_samples >= kInferTargetEffectiveShare * o.samples) break;
    weighted_moments(samples, w, post.prior(), mean, cov);
  }
  for (std::size_t i = 0; i < post.dims(); ++i)
    r.constants.push_back(constant_posterior(law.constants[i], law.values[i], post.prior()[i], samples, w, i));
  for (int k = 0; k < 3; ++k) r.metrics.push_back(metric_posterior(k, m, obs, r.campaign, samples, w));
  if (r.effective_samples < kInferMinEffectiveSamples)
    r.note =
        fmt::format("only {:.0f} effective samples: the intervals are rough (raise --samples)", r.effective_samples);
  return r;
}

}  // namespace gravsweep::results
