// The design's Froude numbers in a gravity sweep: drops whose impact Froude numbers Fr = vc /
// sqrt(g D) lie within kSameFroudeLn of each other in ln Fr are one speed of the design (repeats
// differ by their measured impact speeds). One grouping for the collapse's cells, the signed
// errors of leave-one-level-out and the regime map's crossovers.
#pragma once
#include <vector>

#include "results/measurements/campaign.h"

namespace gravsweep::results {

/// Froude numbers closer than this in ln Fr (5 %) are one speed of the design.
inline constexpr double kSameFroudeLn = 0.05;

/// The design point of each ln Fr value: runs of sorted values whose gaps are at most
/// kSameFroudeLn, numbered 0, 1, ... from the smallest Fr. Same size and order as `ln_froude`.
std::vector<int> froude_groups(const std::vector<double>& ln_froude);

/// A measured trial's impact Froude number vc / sqrt(g D), vc its measured collision speed and D
/// the projectile's diameter.
double impact_froude(const MeasuredTrial& t);

}  // namespace gravsweep::results
