// Distribution functions the model verbs' tests of significance need, written from their
// definitions (Abramowitz & Stegun 26.5, 26.6): the regularised incomplete beta function and the
// upper tail of Fisher's F distribution.
#pragma once

namespace gravsweep::results {

/// I_x(a, b), the regularised incomplete beta function, for a, b > 0 and 0 <= x <= 1 (A&S 26.5.1),
/// by its continued fraction (A&S 26.5.8) evaluated with the modified Lentz method, on the side
/// of x where it converges fast (I_x(a, b) = 1 - I_{1-x}(b, a)). NaN outside the domain.
double regularized_beta(double a, double b, double x);

/// P(F > f) for Fisher's F with d1 and d2 degrees of freedom (A&S 26.6.2:
/// I_{d2 / (d2 + d1 f)}(d2 / 2, d1 / 2)); 1 for f <= 0, NaN for d1 or d2 not positive.
double f_upper_p(double f, double d1, double d2);

}  // namespace gravsweep::results
