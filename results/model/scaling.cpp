// The scaling check (see scaling.h).
#include "results/model/model_spec.h"
#include "results/model/fit.h"
#include "results/model/scaling.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "results/model/froude.h"
#include "results/model/stats.h"

namespace gravsweep::results {

namespace {

/// One freed constant's values per level in a fit of the law with that constant per level.
struct Freed {
  std::vector<double> value, se;
};

Freed freed_values(const FittedModel& m, std::size_t constant) {
  // Every constant before the freed one is shared (one column each); the freed one has a column
  // per level, in the order of m.gravity_levels.
  Freed f;
  const std::size_t G = m.gravity_levels.size();
  for (std::size_t gi = 0; gi < G; ++gi) {
    const auto col = static_cast<Eigen::Index>(constant + gi);
    f.value.push_back(m.coef(col));
    f.se.push_back(std::sqrt(std::max(0.0, m.cov(col, col))));
  }
  return f;
}

/// Weighted least-squares slope of ln c against ln(g): weights (c / se)^2, the inverse variance
/// of ln c. NaN when a value is not positive.
double power_of(const std::vector<double>& g, const Freed& f) {
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (!(f.value[i] > 0)) return NAN;
    const double rel = f.se[i] > 0 ? f.se[i] / f.value[i] : 1e-6;
    const double w = 1.0 / (rel * rel), x = std::log(g[i]), y = std::log(f.value[i]);
    sw += w, sx += w * x, sy += w * y, sxx += w * x * x, sxy += w * x * y;
  }
  const double det = sw * sxx - sx * sx;
  return det > 0 ? (sw * sxy - sx * sy) / det : NAN;
}

/// The power and its bootstrap interval of constant k (row.value filled from the full fit).
void bootstrap_power(const ModelSpec& freed, const Campaign& c, const std::vector<std::vector<std::size_t>>& by_level,
                     std::size_t k, int resamples, unsigned seed, ScalingRow& row) {
  std::mt19937 rng(seed + static_cast<unsigned>(k) * 7919u);
  std::vector<double> powers;
  for (int b = 0; b < resamples; ++b) {
    const std::vector<int> count = resample_within(by_level, c.trials.size(), rng);
    try {
      const double p = power_of(row.gravity_m_s2, freed_values(fit_model(freed, c, count), k));
      if (std::isfinite(p)) powers.push_back(p);
    } catch (const std::exception&) {  // a resample the fit cannot solve (NumericalFailure): skipped
    }
  }
  row.resamples_used = static_cast<int>(powers.size());
  if (powers.size() < 20) {
    row.note = fmt::format("only {} of {} resamples gave a power: no interval", powers.size(), resamples);
    return;
  }
  const double alpha = 0.5 * (1 - kScalingCoverage);
  row.power_lo = quantile(powers, alpha);
  row.power_hi = quantile(powers, 1 - alpha);
  double mean = 0, var = 0;
  for (double p : powers) mean += p / static_cast<double>(powers.size());
  for (double p : powers) var += (p - mean) * (p - mean) / static_cast<double>(powers.size() - 1);
  row.power_se = std::sqrt(var);
  row.differs = row.power_lo > 0 || row.power_hi < 0;
}

/// The law with every differing constant carried by g^p (its p added to any power it had).
std::string suggestion(const ModelSpec& split, const std::vector<ScalingRow>& rows) {
  ModelSpec s = split;
  bool any = false;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (!rows[k].differs) continue;
    ModelTerm& t = s.terms[k];
    const double p = (t.g_scaled() ? t.g_power : 0.0) + rows[k].power;
    t.g_power = std::round(p * 100) / 100;  // two decimals: the interval is wider than that
    t.per_gravity = false;
    any = true;
  }
  return any ? s.name() : "";
}

std::string verdict_of(const ScalingCheck& r) {
  std::string v;
  for (const auto& row : r.rows) {
    if (!row.note.empty() && !std::isfinite(row.power)) {
      v += fmt::format("{}: {}. ", row.constant, row.note);
      continue;
    }
    if (!row.differs) continue;
    v += fmt::format(
        "{} does not scale as the law assumes: per level it goes as g^{:.2f} (95 %: {:.2f} to {:.2f}), where the "
        "law holds it the same at every level. ",
        row.constant, row.power, row.power_lo, row.power_hi);
  }
  if (v.empty())
    return fmt::format(
        "every constant of {} scales as the law assumes: the 95 % interval of each one's power of g holds 0 ({} "
        "levels, {} trials).",
        r.law, r.levels, r.trials);
  std::size_t differing = 0;
  for (const auto& row : r.rows) differing += row.differs ? 1 : 0;
  if (!r.carried.empty() && differing < r.rows.size())
    v += fmt::format("With {} carried by {}, the other constants scale as assumed. ", differing == 1 ? "it" : "them",
                     differing == 1 ? "its power of g" : "their powers of g");
  if (!r.suggested_model.empty()) v += fmt::format("Try --model '{}'.", r.suggested_model);
  if (!r.froude_note.empty()) v += " " + r.froude_note;
  return v;
}

/// When the levels reach different largest Froude numbers (the slowest level's top below
/// kFroudeRangeRatio of the fastest's), a form error of the law along Fr reads as a power of g:
/// the note says so and gives the filter of the range every level covers; else empty.
constexpr double kFroudeRangeRatio = 0.8;
std::string froude_note(const Campaign& c, const std::vector<double>& levels) {
  std::vector<double> top(levels.size(), 0.0);
  for (const auto& t : c.trials) {
    const double fr = impact_froude(t);
    for (std::size_t gi = 0; gi < levels.size(); ++gi)
      if (same_gravity_level(levels[gi], t.info.gravity_m_s2) && std::isfinite(fr)) top[gi] = std::max(top[gi], fr);
  }
  const auto [lo, hi] = std::minmax_element(top.begin(), top.end());
  if (!(*lo < kFroudeRangeRatio * *hi)) return "";
  std::string ranges;
  for (std::size_t gi = 0; gi < levels.size(); ++gi)
    ranges += fmt::format("{}{} m/s2 to Fr {:.2g}", ranges.empty() ? "" : ", ", levels[gi], top[gi]);
  return fmt::format(
      "The levels reach different Froude numbers ({}): a form error of the law along Fr reads as a power of g. "
      "Check again on the range every level covers: --where 'impact_froude<={:.3g}'.",
      ranges, *lo * 1.05);
}

}  // namespace

ModelSpec split_parameters(const ModelSpec& law) {
  ModelSpec s;
  s.residual_units = law.residual_units;
  for (const ModelTerm& t : law.terms) {
    if (t.term->params.size() < 2) {
      s.terms.push_back(t);
      continue;
    }
    for (const std::string& p : t.term->params) {
      ModelTerm one = t;
      one.term = &find_term(t.term->name + "." + p);
      s.terms.push_back(one);
    }
  }
  return s;
}

namespace {

/// One round: every constant of `law` freed in turn, its power of g beyond the law's own.
std::vector<ScalingRow> check_round(const ModelSpec& law, const Campaign& c,
                                    const std::vector<std::vector<std::size_t>>& by_level, int resamples,
                                    unsigned seed) {
  const std::vector<double> levels = c.gravity_levels();
  const FittedModel shared = fit_model(law, c);
  std::vector<ScalingRow> rows;
  for (std::size_t k = 0; k < law.terms.size(); ++k) {
    ModelSpec freed = law;
    freed.terms[k].per_gravity = true;
    ScalingRow row;
    row.constant = law.terms[k].term->name;
    row.law_value = shared.coef(static_cast<Eigen::Index>(k));
    row.gravity_m_s2 = levels;
    const Freed f = freed_values(fit_model(freed, c), k);
    row.value = f.value;
    row.value_se = f.se;
    row.power = power_of(levels, f);
    if (!std::isfinite(row.power)) {
      for (std::size_t gi = 0; gi < levels.size(); ++gi)
        if (!(f.value[gi] > 0))
          row.note +=
              fmt::format("{}not positive at {} m/s2 ({:.3g})", row.note.empty() ? "" : "; ", levels[gi], f.value[gi]);
      row.note += ": no power law of g";
    } else {
      bootstrap_power(freed, c, by_level, k, resamples, seed, row);
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

/// The differing constant to carry by g^p first: the largest |p| / SE (-1: none differs).
int most_significant(const std::vector<ScalingRow>& rows) {
  int best = -1;
  double best_z = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (!rows[k].differs) continue;
    const double z = std::abs(rows[k].power) / std::max(rows[k].power_se, 1e-12);
    if (z > best_z) best_z = z, best = static_cast<int>(k);
  }
  return best;
}

/// A row of the last round restated against the law as given: the constant's values per level as
/// they act (times the power of g the rounds gave it), its power and interval the total.
void restate(ScalingRow& row, double g_power, double law_value) {
  row.law_value = law_value;
  if (g_power == 0) return;
  for (std::size_t gi = 0; gi < row.gravity_m_s2.size(); ++gi) {
    const double factor = std::pow(row.gravity_m_s2[gi] / kGPowerReference_m_s2, g_power);
    row.value[gi] *= factor;
    row.value_se[gi] *= factor;
  }
  row.power += g_power;
  row.power_lo += g_power;
  row.power_hi += g_power;
  row.differs = row.power_lo > 0 || row.power_hi < 0;
}

}  // namespace

ScalingCheck scaling_check(const ModelSpec& law, const Campaign& c, int resamples, unsigned seed) {
  if (!one_law_for_all_levels(law))
    throw std::invalid_argument(fmt::format(
        "the scaling check frees the constants of one law for all gravity levels, and '{}' has a term with a value "
        "per level: give a law such as scaled_base+gravity_depth_friction (terms shared or :g^p)",
        law.name()));
  const std::vector<double> levels = c.gravity_levels();
  if (levels.size() < kScalingMinLevels)
    throw std::invalid_argument(fmt::format("the scaling check needs at least {} gravity levels; the campaign has {}",
                                            kScalingMinLevels, levels.size()));
  ScalingCheck r;
  r.law = law.name();
  r.levels = static_cast<int>(levels.size());
  r.trials = static_cast<int>(c.trials.size());
  r.resamples = resamples;
  ModelSpec current = split_parameters(law);
  current.residual_units = ResidualUnits::trial_force;
  const ModelSpec as_given = current;
  const FittedModel given = fit_model(as_given, c);
  const std::vector<std::vector<std::size_t>> by_level = c.trials_by_level();
  // Freed one at a time, a constant that does not scale as assumed drags the others along (they
  // absorb part of its g-dependence): carry the most significant one by its g^p, then check every
  // constant again against that law, until none differs (kScalingMaxRounds at most).
  std::vector<ScalingRow> rows;
  std::vector<double> extra(current.terms.size(), 0.0);
  for (int round = 0;; ++round) {
    rows = check_round(current, c, by_level, resamples, seed + static_cast<unsigned>(round) * 104729u);
    const int k = most_significant(rows);
    if (k < 0 || round + 1 >= kScalingMaxRounds) break;  // the rows describe the law carried so far
    ModelTerm& t = current.terms[static_cast<std::size_t>(k)];
    t.g_power = (t.g_scaled() ? t.g_power : 0.0) + rows[static_cast<std::size_t>(k)].power;
    extra[static_cast<std::size_t>(k)] += rows[static_cast<std::size_t>(k)].power;
    r.carried.push_back(t.term->name);
  }
  for (std::size_t k = 0; k < rows.size(); ++k) restate(rows[k], extra[k], given.coef(static_cast<Eigen::Index>(k)));
  r.rows = std::move(rows);
  r.suggested_model = suggestion(as_given, r.rows);
  if (!r.carried.empty()) r.froude_note = froude_note(c, levels);
  r.verdict = verdict_of(r);
  return r;
}

}  // namespace gravsweep::results
