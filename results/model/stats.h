// Distribution functions the model verbs' tests of significance need, written from their
// definitions (Abramowitz & Stegun 26.5, 26.6): the regularised incomplete beta function and the
// upper tail of Fisher's F distribution.
#pragma once
#include <cstddef>
#include <random>
#include <vector>

namespace gravsweep::results {

/// The q-quantile (0 <= q <= 1) of the finite values of v, linear between order statistics; NaN
/// when there are none.
double quantile(std::vector<double> v, double q);

/// The q-quantile of values v carrying weights w (same length, w >= 0): the smallest value whose
/// cumulative weight reaches q of the total, linear between neighbours; NaN when no weight.
double weighted_quantile(const std::vector<double>& v, const std::vector<double>& w, double q);

/// A cluster bootstrap's draw: how many times each of n items is taken when each group (indices
/// into the n) is resampled with replacement to its own size (whole drops, within each level).
std::vector<int> resample_within(const std::vector<std::vector<std::size_t>>& groups, std::size_t n, std::mt19937& rng);

/// I_x(a, b), the regularised incomplete beta function, for a, b > 0 and 0 <= x <= 1 (A&S 26.5.1),
/// by its continued fraction (A&S 26.5.8) evaluated with the modified Lentz method, on the side
/// of x where it converges fast (I_x(a, b) = 1 - I_{1-x}(b, a)). NaN outside the domain.
double regularized_beta(double a, double b, double x);

/// P(F > f) for Fisher's F with d1 and d2 degrees of freedom (A&S 26.6.2:
/// I_{d2 / (d2 + d1 f)}(d2 / 2, d1 / 2)); 1 for f <= 0, NaN for d1 or d2 not positive.
double f_upper_p(double f, double d1, double d2);

}  // namespace gravsweep::results
