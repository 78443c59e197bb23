// Discovery (see discover.h): the ranking of candidate terms and the verdict (residuals along
// axes: residuals.cpp).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "results/model/generated.h"
#include "results/model/cross_validation.h"
#include "results/model/discover.h"
#include "results/model/fit.h"
#include "results/model/model_spec.h"
#include "results/model/residual_axes.h"
#include "results/model/model_internal.h"

namespace gravsweep::results {

using namespace detail;

// ---------------------------------------------------------------------------------------------
// Discovery

namespace {

/// The most structured axis of the residuals (the tests of residual_axes), described as "along
/// <axis> (eta^2, split-half r, bin means)"; false when none is.
bool structured(const std::vector<AxisResidual>& axes, std::string& where) {
  const AxisResidual* best = nullptr;
  for (const auto& a : axes) {
    if (a.axis == "gravity_m_s2" || a.axis == "impact_speed_m_s" || a.axis == "fill_height_m") {
      if (a.eta2 >= 0.25 && (!best || a.eta2 > best->eta2)) best = &a;
      continue;
    }
    const bool monotone = a.eta2 >= 0.15 && a.slope_sign_trials_p < 1e-4;
    const bool reproducible = a.eta2 >= 0.05 && a.split_half_r >= 0.9;
    if ((monotone || reproducible) && (!best || a.eta2 > best->eta2)) best = &a;
  }
  if (!best) return false;
  std::string bins;
  for (std::size_t i = 0; i < best->bin_center.size(); ++i)
    bins += fmt::format("{}{:.3g}:{:+.3f}", i ? ", " : "", best->bin_center[i], best->bin_mean_r_over_g[i]);
  where = fmt::format("along {} (eta^2 = {:.2f}, split-half r = {:.2f}; mean residual/g by bin: {})", best->axis,
                      best->eta2, best->split_half_r, bins);
  return true;
}

/// The state axis (depth, speed, time since contact) whose within-trial residual slope has the same
/// sign in the most trials, when the sign test says p < kConsistentTrendP; empty otherwise.
std::string consistent_trend(const std::vector<AxisResidual>& axes) {
  const AxisResidual* best = nullptr;
  for (const auto& a : axes)
    if ((a.axis == "depth_m" || a.axis == "speed_m_s" || a.axis == "time_since_contact_s") &&
        a.slope_sign_trials_p < kConsistentTrendP && (!best || a.slope_sign_trials_p < best->slope_sign_trials_p))
      best = &a;
  if (!best) return "";
  const bool up = best->trials_positive >= best->trials_negative;
  return fmt::format(
      "along {}: the residual {} with it in {} of {} trials (sign test p = {:.2g}), but weakly (eta^2 = {:.3f})",
      best->axis, up ? "grows" : "falls", up ? best->trials_positive : best->trials_negative,
      best->trials_positive + best->trials_negative, best->slope_sign_trials_p, best->eta2);
}

/// The state axis (depth, speed, time since contact) along which the residual varies most.
std::string strongest_axis(const std::vector<AxisResidual>& axes) {
  const AxisResidual* best = nullptr;
  for (const auto& a : axes)
    if (a.axis == "depth_m" || a.axis == "speed_m_s" || a.axis == "time_since_contact_s")
      if (!best || a.eta2 > best->eta2) best = &a;
  if (!best) return "along no axis the binned residuals show";
  return fmt::format(
      "along {} (eta^2 = {:.2f}, split-half r = {:.2f}; shown by the held-out test below, not by the "
      "binned residuals alone)",
      best->axis, best->eta2, best->split_half_r);
}

/// How the force of a term shared by all levels goes with gravity at Froude-similar states (the
/// same z/D and Fr = v / sqrt(g D), D = 10 cm, m = 1 kg): the power p of g in the ratio of its
/// force at 9.81 and 0.0981 m/s2 (1: Froude-scaled, it follows g; 0: it does not).
double force_power_of_g(const ModelTerm& mt) {
  constexpr double kG1 = 9.81, kG2 = 0.0981, kD = 0.1;
  const auto force = [&](double g) {
    TermContext c;
    c.g_m_s2 = g;
    c.diameter_m = kD;
    c.mass_kg = 1.0;
    c.fill_height_m = 2 * kD;
    c.z_m = 0.3 * kD;
    c.v_m_s = c.vc_m_s = std::sqrt(g * kD);
    const FittedModel one = [&] {
      FittedModel m;
      m.spec.terms = {mt};
      m.gravity_levels = {g};
      m.coef = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(mt.term->params.size()));
      return m;
    }();
    return one.force(c);
  };
  const double f1 = force(kG1), f2 = force(kG2);
  return f1 != 0 && f2 / f1 > 0 ? std::log(f2 / f1) / std::log(kG2 / kG1) : NAN;
}

/// The power q of g that makes a term shared by all levels Froude-scaled: with its constant carried
/// by (g / 9.81 m/s2)^q its force goes as g at Froude-similar states (q = 1 - force_power_of_g;
/// Sunday et al. 2021 II: the drag of a Froude-similar collision scales as m g). A viscous drag
/// b v needs q = 1/2 (v goes as sqrt(g D)); a depth friction k z needs q = 1; a v^2 drag needs 0.
/// Rounded to hundredths, as a spec writes it; NaN when the force does not go as a power of g.
double froude_power(const ModelTerm& shared) {
  const double p = force_power_of_g(shared);
  return std::isfinite(p) ? std::round(100.0 * (1.0 - p)) / 100.0 : NAN;
}

/// The named terms to try beside `current`, each in the sharing it is tried in. Per level: every
/// registered term not in `current` (baselines aside) in its own sharing. Gravity-scaled (a
/// baseline that is one law for all levels): every such term as one law for all levels too, a
/// per-level term in its two forms, its constant shared by all levels ("depth_friction:shared":
/// does not follow g) and carried by g ("immersion_drag:g^1"; where a registered term is that form,
/// TermInfo::gravity_form, it stands in for it, and a term whose g-form is a baseline is not tried),
/// and every term also in its Froude-scaled form when that is another (froude_power: a viscous
/// drag's constant carried by g^0.5). A term identifiable only across projectile diameters is
/// tried when `several_diameters`; a form carried by a power of g only when `several_levels` (at one
/// gravity level it is the shared form again, and would only cost the others Bonferroni power).
std::vector<ModelTerm> named_candidates(const ModelSpec& current, bool gravity_scaled, bool several_diameters,
                                        bool several_levels) {
  std::vector<ModelTerm> named;
  for (const auto& term : term_registry()) {
    if (current.has(term.name) || term.baseline_only) continue;
    if (term.across_diameters && !several_diameters) continue;
    if (!gravity_scaled) {
      named.push_back({&term, term.per_gravity, 1.0});
      continue;
    }
    if (term.per_gravity && !term.gravity_form.empty() && find_term(term.gravity_form).baseline_only) continue;
    named.push_back({&term, false, 1.0});
    if (!several_levels) continue;
    if (term.per_gravity && term.gravity_form.empty()) named.push_back({&term, false, 1.0, 1.0});
    // Its Froude-scaled form where that is neither the shared form (q = 0) nor the one carried
    // by g (q = 1, tried above for a per-level term; for a shared constant force it is the
    // baseline's phi m g): one constant for all levels cannot act alike at every level when the
    // term's force does not follow g (a viscous drag: b v with one b is 100 times weaker, against
    // m g, at 9.81 than at 0.001 m/s2 in Froude-similar collisions).
    const double q = froude_power({&term, false, 1.0});
    if (std::isfinite(q) && std::abs(q) > 0.02 && std::abs(q - 1.0) > 0.02) named.push_back({&term, false, 1.0, q});
  }
  return named;
}

/// Each candidate added to `current` on its own, ranked by held-out improvement over `current`
/// (grouped CV, whole trials out; a one-sided signed-rank test over trials, Bonferroni over the
/// candidates at level alpha, and at least min_improvement mean relative gain). Named and
/// generated candidates are judged the same way.
std::vector<Candidate> rank_candidates(const ModelSpec& current, const Campaign& c,
                                       const std::vector<ModelTerm>& candidates, int folds, double alpha,
                                       double min_improvement) {
  const HeldOut h0 = cross_validate(current, c, folds, 1, false);
  std::vector<Candidate> cands;
  for (const auto& mt : candidates) {
    ModelSpec s = current;
    s.terms.push_back(mt);
    const HeldOut h1 = cross_validate(s, c, folds, 1, false);
    Candidate cd;
    cd.term = ModelSpec{{mt}}.name();
    cd.form = mt;
    double sum = 0;
    std::vector<double> rel_all;
    cd.trial_rel_gain.assign(c.trials.size(), NAN);
    for (std::size_t i = 0; i < c.trials.size(); ++i) {
      if (!std::isfinite(h0.trace_mse[i]) || !std::isfinite(h1.trace_mse[i]) || h0.trace_mse[i] <= 0) continue;
      const double rel = (h0.trace_mse[i] - h1.trace_mse[i]) / h0.trace_mse[i];
      cd.trial_rel_gain[i] = rel;
      rel_all.push_back(rel);
      sum += rel;
      ++cd.trials;
      if (rel > 0) ++cd.trials_better;
    }
    cd.mean_rel_improvement = cd.trials ? sum / cd.trials : 0;
    cd.p_value = signed_rank_p(rel_all);
    cands.push_back(cd);
  }
  const double level = alpha / std::max<std::size_t>(1, cands.size());
  for (auto& cd : cands) cd.significant = cd.p_value < level && cd.mean_rel_improvement >= min_improvement;
  std::stable_sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) {
    if (a.significant != b.significant) return a.significant;
    return a.mean_rel_improvement > b.mean_rel_improvement;
  });
  return cands;
}

/// The held-out trials cannot tell `a` from `b` (cannot_tell_apart on the per-trial differences
/// of their relative gains, over the trials where both are finite).
bool held_out_equal(const Candidate& a, const Candidate& b) {
  std::vector<double> worse;
  for (std::size_t i = 0; i < a.trial_rel_gain.size() && i < b.trial_rel_gain.size(); ++i)
    if (std::isfinite(a.trial_rel_gain[i]) && std::isfinite(b.trial_rel_gain[i]))
      worse.push_back(a.trial_rel_gain[i] - b.trial_rel_gain[i]);
  return cannot_tell_apart(worse);
}

/// The other significant candidates of a ranked round that the held-out trials cannot tell apart
/// from its winner (the first): per trial, how much less each gains than the winner.
std::vector<std::string> equivalent_to_winner(const std::vector<Candidate>& ranked) {
  std::vector<std::string> out;
  for (std::size_t j = 1; j < ranked.size() && ranked[j].significant; ++j)
    if (held_out_equal(ranked[0], ranked[j])) out.push_back(ranked[j].term);
  return out;
}

/// The best generated form added to `current` (where the round's named winner was added), as
/// "c * <form>", when it is significant held out and the trials cannot tell it from the winner
/// (neither fits significantly better: a form that fits better is left to the search beyond the
/// named library, which reports it as structure left);
/// empty otherwise. Its form is chosen in sample, which favours it: an equal verdict is an upper
/// bound on what the trials can tell apart, never a reason to drop the named term.
std::string generated_equivalent_to(const Candidate& winner, const ModelSpec& current, const Campaign& c,
                                    bool gravity_scaled, int folds, double alpha, double min_improvement) {
  const TermInfo* form = detail::best_generated_form(current, c, !gravity_scaled);
  if (!form) return "";
  const auto ranked = rank_candidates(current, c, {{form, !gravity_scaled, 1.0}}, folds, alpha, min_improvement);
  if (ranked.empty() || !ranked.front().significant) return "";
  return held_out_equal(winner, ranked.front()) ? "c * " + form->name : "";
}

/// What the sharing of a term tried in the scaled mode says about gravity.
std::string sharing_words(const ModelTerm& mt) {
  if (mt.per_gravity) return "";
  const double p = force_power_of_g(mt);
  const std::string how = !std::isfinite(p)        ? ""
                          : std::abs(p - 1) < 0.05 ? ": its force follows g (Froude-scaled)"
                          : std::abs(p) < 0.05     ? ": its force does not follow g"
                                                   : fmt::format(": its force goes as g^{:.2g}", p);
  return (mt.g_scaled() ? fmt::format("; one constant for all gravity levels times (g / 9.81 m/s2)^{:g}", mt.g_power)
                        : std::string("; one constant for all gravity levels")) +
         how;
}

/// ", or equally well a and b (...)" when the trials cannot tell other terms from a winner.
std::string equivalent_words(const std::vector<std::string>& names) {
  if (names.empty()) return "";
  std::string list;
  for (std::size_t i = 0; i < names.size(); ++i)
    list += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return fmt::format(", or equally well {} (the held-out trials cannot tell {} apart: signed-rank p >= {})", list,
                     names.size() == 1 ? "the two" : "them", kEquivalentLevel);
}

std::string improvement_words(const Candidate& cd) {
  return fmt::format(
      "held-out trace error down {:.0f} % on average, better on {} of {} trials (signed-rank test "
      "over trials p = {:.1e})",
      100 * cd.mean_rel_improvement, cd.trials_better, cd.trials, cd.p_value);
}

/// The sentence for users (humble where the named terms leave structure).
std::string verdict_of(const Discovery& d, const std::string& where_named, const std::string& where_generated) {
  std::string v;
  if (d.added.empty()) {
    if (!d.structure_left && d.consistent_trend.empty())
      return "no missing effect found: no candidate term improves the held-out trials significantly and the "
             "residuals show no structure";
    if (!d.structure_left)
      return "no missing effect found: no candidate term improves the held-out trials significantly" +
             std::string(d.generated_searched ? ", nor a form of the generated family" : "") +
             "; the residuals trend consistently " + d.consistent_trend +
             ": a term that helps some trials hurts others held out (different regimes? rank each gravity level "
             "or speed range with --where)";
    v = "structure left that no named term explains, " + where_named;
  } else {
    const auto& first = d.rounds.front().front();
    const TermInfo& w = *first.form.term;
    v = fmt::format("{} {} ({}{}){}; {}; references: {}",
                    d.structure_left ? "partly explained by" : "missing effect:", first.term, w.meaning,
                    sharing_words(first.form), equivalent_words(d.equivalent.front()), improvement_words(first),
                    w.references);
    for (std::size_t i = 1; i < d.added.size(); ++i) {
      const ModelTerm& t = d.rounds[i].front().form;
      v += fmt::format("; then {} ({}{}){}", d.added[i], t.term->meaning, sharing_words(t),
                       equivalent_words(d.equivalent[i]));
    }
    if (d.structure_left) v += "; structure left " + where_named;
  }
  if (!d.structure_left && d.generated_worsens_metrics)
    return v + fmt::format(
                   "; beyond the named library the best generated form, c * {}, fits the trace better held out "
                   "({}) but predicts zstop {:.1f} -> {:.1f} % and tstop {:.1f} -> {:.1f} %: not named",
                   d.generated_test.term, improvement_words(d.generated_test), d.errors_without_generated.zstop_rel_pct,
                   d.errors_with_generated.zstop_rel_pct, d.errors_without_generated.tstop_rel_pct,
                   d.errors_with_generated.tstop_rel_pct);
  if (!d.structure_left) return v;
  if (d.generated.empty() && d.generated_worsens_metrics)
    return v + fmt::format(
                   "; no form of the generated family ({} forms) explains it: the best, {}, fits the trace better "
                   "held out ({}) but predicts zstop {:.1f} -> {:.1f} % and tstop {:.1f} -> {:.1f} %",
                   generated_family().size(), d.generated_test.term, improvement_words(d.generated_test),
                   d.errors_without_generated.zstop_rel_pct, d.errors_with_generated.zstop_rel_pct,
                   d.errors_without_generated.tstop_rel_pct, d.errors_with_generated.tstop_rel_pct);
  if (d.generated.empty())
    return v + fmt::format("; no form of the generated family ({} forms) explains it significantly (best {}: {})",
                           generated_family().size(), d.generated_test.term, improvement_words(d.generated_test));
  const Candidate& g = d.generated_test;
  const TermInfo& t = find_term(g.term.substr(0, g.term.find(':')));
  const auto& b = d.errors_without_generated;
  const auto& a = d.errors_with_generated;
  v += fmt::format(
      "; beyond the named library, a generated form fits it: c * {}{} ({}), {}; held-out errors without -> with "
      "it: trace {:.1f} -> {:.1f} %, zstop {:.1f} -> {:.1f} %, tstop {:.1f} -> {:.1f} %, apeak {:.1f} -> {:.1f} %; "
      "fit it with --model '{}'",
      t.name, g.term.find(":shared") != std::string::npos ? " (shared by the gravity levels)" : "",
      generated_words(t.name), improvement_words(g), b.trace_rel_pct, a.trace_rel_pct, b.zstop_rel_pct, a.zstop_rel_pct,
      b.tstop_rel_pct, a.tstop_rel_pct, b.apeak_rel_pct, a.apeak_rel_pct, d.generated_model);
  if (!d.generated_equivalent.empty()) {
    std::string list;
    for (std::size_t i = 0; i < d.generated_equivalent.size() && i < 5; ++i)
      list += (i ? ", " : "") + d.generated_equivalent[i];
    if (d.generated_equivalent.size() > 5) list += fmt::format(" and {} more", d.generated_equivalent.size() - 5);
    v += fmt::format("; forms these trials cannot tell apart from it (signed-rank p >= 0.05): {}", list);
  }
  if (d.structure_left_after_generated) v += "; structure still left " + where_generated;
  return v;
}

}  // namespace

Discovery discover(const Campaign& c, const ModelSpec& baseline, int folds, double alpha, double min_improvement,
                   int max_rounds, bool search_generated) {
  Discovery d;
  d.baseline = baseline.name();
  ModelSpec current = baseline;
  d.residual_before = residual_axes(fit_model(current, c), c);
  // A gravity-scaled baseline (no parameter per gravity level, e.g. scaled_base) is tested only
  // against terms that are one law for all levels too: a per-level term would absorb, level by
  // level, the very effect whose size does not follow g that this mode is meant to find.
  d.gravity_scaled = one_law_for_all_levels(baseline);
  const bool several_diameters = std::any_of(c.trials.begin(), c.trials.end(), [&c](const MeasuredTrial& t) {
    return std::abs(t.info.projectile_diameter_m - c.trials.front().info.projectile_diameter_m) >
           1e-9 * t.info.projectile_diameter_m;
  });
  const bool several_levels = c.gravity_levels().size() > 1;
  for (int round = 0; round < max_rounds; ++round) {
    const auto cands =
        rank_candidates(current, c, named_candidates(current, d.gravity_scaled, several_diameters, several_levels),
                        folds, alpha, min_improvement);
    d.rounds.push_back(cands);
    if (cands.empty() || !cands.front().significant) break;
    d.equivalent.push_back(equivalent_to_winner(cands));
    if (search_generated) {
      const std::string form =
          generated_equivalent_to(cands.front(), current, c, d.gravity_scaled, folds, alpha, min_improvement);
      if (!form.empty()) d.equivalent.back().push_back(form);
    }
    current.terms.push_back(cands.front().form);
    d.added.push_back(cands.front().term);
  }
  d.named_model = current.name();
  const FittedModel named_fit = fit_model(current, c);
  d.residual_after = residual_axes(named_fit, c);
  std::string where_named, where_generated;
  d.structure_left = structured(d.residual_after, where_named);
  d.consistent_trend = consistent_trend(d.residual_after);
  // The residuals of the named winners are tested again by the held-out test itself: a form of the
  // generated family that improves them significantly (Bonferroni over the family) is structure the
  // named terms left, even where the binned axes alone do not show it.
  if (search_generated && (d.structure_left || !d.added.empty() || !d.consistent_trend.empty())) {
    const detail::GeneratedSearch g = detail::search_generated(current, c, folds, alpha, min_improvement);
    d.generated_searched = true;
    d.generated_test = g.test;
    d.generated_screened = g.screened;
    if (g.test.significant) {
      ModelSpec with = current;
      with.terms.push_back(g.chosen);
      d.errors_without_generated = summarize(c, cross_validate(current, c, folds, 1));
      d.errors_with_generated = summarize(c, cross_validate(with, c, folds, 1));
      // A form that fits the trace better but predicts the depth or the duration worse held out
      // does not explain the structure: it is named as tried, not as found.
      d.generated_worsens_metrics = d.errors_with_generated.zstop_rel_pct > d.errors_without_generated.zstop_rel_pct ||
                                    d.errors_with_generated.tstop_rel_pct > d.errors_without_generated.tstop_rel_pct;
      if (!d.generated_worsens_metrics) {
        d.generated = g.chosen.term->name;
        d.generated_equivalent = g.equivalent;
        d.generated_model = with.name();
        d.structure_left_after_generated = structured(residual_axes(fit_model(with, c), c), where_generated);
        if (!d.structure_left) {
          d.structure_left = true;
          where_named = strongest_axis(d.residual_after);
        }
      }
    }
  }
  d.verdict = verdict_of(d, where_named, where_generated);
  return d;
}

}  // namespace gravsweep::results
