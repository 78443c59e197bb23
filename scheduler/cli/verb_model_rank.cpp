// `gravsweep model rank` (alias discover): which effect is missing. The baseline's residuals, the
// registered terms ranked by held-out improvement, the generated forms, and a verdict
// (results::discover).
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "results/model/discover.h"
#include "results/io/table.h"
#include "scheduler/cli/model_inputs.h"
#include "scheduler/cli/verbs.h"

namespace gravsweep::cli {

namespace {

using results::num;

struct RankOptions {
  ModelInputs in;
  std::string baseline = "base";
  int folds = 6;
  double alpha = 0.01;
  double min_improvement = 0.03;
};

/// How many screened forms the ranking shows: the first six in `table`, all otherwise.
std::size_t screened_shown(const results::Discovery& d, const std::string& format) {
  return format == "table" ? std::min<std::size_t>(6, d.generated_screened.size()) : d.generated_screened.size();
}

/// The candidates of every round, the generated form's test and the screened forms shown.
results::Table ranking_table(const results::Discovery& d, const std::string& format) {
  results::Table t(
      {"round", "rank", "term", "mean_rel_improvement_pct", "trials_better", "trials", "p_signed_rank", "significant"});
  for (std::size_t r = 0; r < d.rounds.size(); ++r)
    for (std::size_t i = 0; i < d.rounds[r].size(); ++i) {
      const auto& c = d.rounds[r][i];
      t.add({std::to_string(r + 1), std::to_string(i + 1), c.term, num(100 * c.mean_rel_improvement, 3),
             std::to_string(c.trials_better), std::to_string(c.trials), num(c.p_value, 2),
             c.significant ? "yes" : "no"});
    }
  // The search beyond the named library: the nested-CV test of choosing a form, then the forms by
  // in-sample improvement (screening only: no test of their own).
  if (d.generated_searched) {
    const auto& g = d.generated_test;
    t.add({"generated", "1", g.term, num(100 * g.mean_rel_improvement, 3), std::to_string(g.trials_better),
           std::to_string(g.trials), num(g.p_value, 2), g.significant ? "yes" : "no"});
  }
  for (std::size_t i = 0; i < screened_shown(d, format); ++i) {
    const auto& c = d.generated_screened[i];
    t.add({"screened", std::to_string(i + 1), c.term, num(100 * c.mean_rel_improvement, 3), "-", "-", "-", "-"});
  }
  return t;
}

void print_ranking(const results::Discovery& d, const std::string& format) {
  ranking_table(d, format).print(format);
  const std::size_t shown = screened_shown(d, format);
  if (format == "table" && shown < d.generated_screened.size())
    fmt::print(
        "(round 'generated': the held-out test of choosing a form, nested CV; 'screened': in-sample gain of "
        "each form, {} more with --format csv)\n",
        d.generated_screened.size() - shown);
}

void run_rank(const RankOptions& o) {
  const bool table = o.in.format == "table";
  const auto c = load_model_campaign(o.in);
  const auto d = results::discover(c, model_of(o.baseline), o.folds, o.alpha, o.min_improvement);
  if (o.in.format == "json") {  // one document: the two tables and the verdict
    const nlohmann::json out = {{"baseline", d.baseline},
                                {"residual_axes", residual_axes_table(d.residual_before).json_value()},
                                {"candidates", ranking_table(d, o.in.format).json_value()},
                                {"verdict", d.verdict}};
    std::fputs((out.dump(2) + "\n").c_str(), stdout);
    return;
  }
  if (table) fmt::print("Where {} fails (residual a_meas - a_model in units of g):\n", d.baseline);
  print_residual_axes(d.residual_before, o.in.format);
  if (table) fmt::print("\nCandidate terms by held-out improvement:\n");
  print_ranking(d, o.in.format);
  if (table)
    fmt::print("\nVerdict: {}\n", d.verdict);
  else
    std::fprintf(stderr, "verdict: %s\n", d.verdict.c_str());
}

}  // namespace

void setup_model_rank(CLI::App& model) {
  auto o = std::make_shared<RankOptions>();
  auto* sub = model.add_subcommand(
      "rank",
      "Which effect is missing: fit the baseline, show where it fails (residuals against depth,\n"
      "speed, time since contact, gravity, impact speed, fill height), then rank every other\n"
      "registered term by its held-out improvement with whole trials left out (grouped CV) and\n"
      "a Wilcoxon signed-rank test over trials (not samples), Bonferroni over candidates. Adds the winner and\n"
      "repeats while a term is significant, then says which effect is missing, 'no missing\n"
      "effect found', 'partly explained by X; structure left along <axis>', or 'structure left\n"
      "that no named term explains' with where it lies. A significant term the held-out trials cannot\n"
      "tell apart from the winner (neither one-sided signed-rank test, worse or better, has p < 0.05),\n"
      "and the best generated form added in its place when it is such a term, are named beside it:\n"
      "'X, or equally well Y and c * z^1*(1-exp(-z/0.0025))'. When a term was added, structure is left, or\n"
      "the residual's within-trial slope has the same sign in nearly every trial (sign test p < 1e-6,\n"
      "however weak: 'the residuals trend consistently along <axis>'), the same test runs\n"
      "over a generated family of forms (z^a |v|^b, exp(-z/l), 1-exp(-z/l) and their products with\n"
      "z, |v|, v^2; each per gravity level or shared) and a significant one is reported by its\n"
      "formula, never by a physical name, with the held-out errors without and with it; fit it\n"
      "like a named term: --model 'base+z^1*v^1'. --format json prints one document:\n"
      "{baseline, residual_axes: [...], candidates: [...], verdict}.\n\n"
      "Examples:\n  gravsweep model rank ../shared/data/measurements/depth-friction-dev\n"
      "  gravsweep model rank campaign.db          # the drops of `gravsweep submit` + `work`\n"
      "  gravsweep model rank data/reproduction/chrono_1g --where 'impact_speed_m_s<0.5'  # one regime\n"
      "  gravsweep model rank data/gravity_sweep/g9.81 data/gravity_sweep/g1.62 --scaled  # one law for all g");
  sub->alias("discover");
  add_model_inputs(sub, o->in);
  sub->add_option("--baseline", o->baseline, "starting model")->capture_default_str();
  sub->add_flag_callback(
      "--scaled", [o]() { o->baseline = "scaled_base"; },
      "scaled mode: start from one gravity-scaled law for every level (scaled_base: phi m g + m v^2/d1) and "
      "rank only terms that are one law for all levels too: each with one constant for every g, a per-level "
      "term also with its constant carried by g, and each also in its Froude-scaled form, whose force goes as "
      "m g at equal Froude number (viscous_drag:g^0.5), so an effect whose size does not follow g "
      "(e.g. cohesion) is found instead of absorbed level by level; same as --baseline scaled_base");
  sub->add_option("--folds", o->folds, "cross-validation folds")->check(CLI::Range(2, 100))->capture_default_str();
  sub->add_option("--alpha", o->alpha, "family-wise significance level")->capture_default_str();
  sub->add_option("--min-improvement", o->min_improvement, "minimum mean relative improvement")->capture_default_str();
  sub->callback([o]() { run_rank(*o); });
}

}  // namespace gravsweep::cli
