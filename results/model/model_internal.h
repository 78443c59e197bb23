// Helpers shared by the files of results/model/ (model.cpp, table3.cpp, discover.cpp); not API.
#pragma once
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/term.h"

namespace gravsweep::results::detail {

/// The state of trial t at sample k.
TermContext context(const MeasuredTrial& t, std::size_t k);
/// The state at first contact (impact speed, no depth).
TermContext context(const Trial& i);
/// P(X >= k), X ~ Binomial(n, 1/2).
double binom_tail_half(int k, int n);
/// One-sided Wilcoxon signed-rank p-value that the per-trial values are centred above 0.
double signed_rank_p(const std::vector<double>& d);
/// Fold of each trial, stratified by gravity level (same_gravity_level).
std::vector<int> fold_of(const Campaign& c, int folds, unsigned seed);

}  // namespace gravsweep::results::detail
