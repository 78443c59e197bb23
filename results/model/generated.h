// The generated family of candidate terms: forms outside the named library, each
// a linear-in-parameter force c * phi(z, |v|) whose formula is its name, for the search that
// `model rank` runs when the named terms leave the residuals structured (discover.cpp).
//
// Grammar of a name:   factor ("*" factor)*
//   factor := "z^" a              depth z (m, positive down) to the power a >= 0
//           | "v^" b              speed |v| (m/s) to the power b >= 0
//           | "exp(-z/" l ")"     decaying with depth over l (m)
//           | "(1-exp(-z/" l "))" saturating with depth over l (m)
// e.g. "z^1*v^1", "(1-exp(-z/0.01))", "v^2*exp(-z/0.02)". Numbers are written as fmt's {:g}, so a
// form has one canonical name. A generated term is named by its formula and described in words of
// its mathematics only: it is never given a physical name it has not earned.
#pragma once
#include <string>
#include <vector>

#include "results/model/term.h"

namespace gravsweep::results {

/// The reference state of a generated term's typical value: scale 1 (`synth`) means the term adds
/// m g at this depth and speed.
inline constexpr double kGeneratedRefDepth_m = 0.02;
inline constexpr double kGeneratedRefSpeed_m_s = 0.5;

/// The term of a generated form (stable address, built once per name); nullptr when `name` is not
/// written in the grammar above. Throws ConfigError when it is, but a number is out of
/// range (a negative power, a length l <= 0), naming the factor.
const TermInfo* generated_term(const std::string& name);

/// The canonical name of a form (fmt {:g} numbers, factors as written): "z^1.0*v^1" -> "z^1*v^1".
/// Empty when `name` is not a generated form.
std::string canonical_generated_name(const std::string& name);

/// A form in words of its mathematics ("depth to the power 1 times speed to the power 1"); empty
/// when `name` is not a generated form.
std::string generated_words(const std::string& name);

/// The family the search explores (50 forms), by canonical name: z^a |v|^b on a grid (a in {0,
/// 0.5, 1, 1.5, 2, 3}, b in {0, 0.5, 1, 2}); with l in {2.5, 5, 10, 20, 40} mm, 1 - exp(-z/l),
/// v^2 exp(-z/l), and z and |v| times exp(-z/l) or 1 - exp(-z/l). Forms the named library already
/// has (a constant, z, |v|, v^2) are left out, and so are forms base makes equivalent to one kept
/// (exp(-z/l) beside its constant, v^2 (1 - exp(-z/l)) beside its v^2): named terms come first.
const std::vector<std::string>& generated_family();

}  // namespace gravsweep::results
