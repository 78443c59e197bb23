// Figures of one drop, drawn by results/report/plots.py from data prepared here:
//  - Fig. 2 of Sunday et al. 2021: acceleration, velocity and depth against time, raw and
//    processed as the paper does (500 Hz Butterworth; velocity and depth re-integrated from the
//    filtered acceleration, the paper's green line), vc, apeak, zstop and tstop marked. A DEM
//    trace.h5 or a lab record (traces/<trial>.csv of a campaign folder), with another record of
//    either kind laid over it.
//  - Fig. 1: the container cut through its axis, the grains coloured by their initial radial
//    position, the projectile at release and at rest.
// Bad input (a missing or unreadable file, a record without contact) throws ConfigError naming the
// file and the reason (the CLI's exit code 2).
#pragma once
#include <string>

#include "results/processing/trace.h"

#include "results/measurements/campaign.h"
#include "results/model/law.h"

namespace gravsweep::results {

struct Fig2Request {
  std::string record;   ///< trace.h5, or a lab trace CSV inside a campaign folder
  std::string compare;  ///< optional: another record laid over the first
  std::string out;      ///< PNG
};

/// Draws Fig. 2; returns the metrics of `record` (processed exactly as the campaign does).
Metrics draw_fig2(const Fig2Request& request);

struct Fig1Request {
  std::string bed;        ///< bed.h5
  std::string trace;      ///< optional trace.h5: the projectile at release / at rest
  std::string at;         ///< "release", "rest" or "" (both, when a trace is given)
  std::string snapshots;  ///< optional snapshots.h5 of the drop: the grains at rest (default: next to the trace)
  std::string out;        ///< PNG
};

/// Draws Fig. 1; returns a one-line description of what was drawn.
std::string draw_fig1(const Fig1Request& request);

/// The Froude-number collapse (results/model/collapse.h): zstop/D, tstop sqrt(g/D), apeak/g against
/// Fr, one colour per gravity level, each panel titled with its collapse numbers. `out`: PNG.
void draw_collapse(const Campaign& campaign, const std::string& out, const std::string& title = "");

/// One point of a saved law's prediction against gravity: the curve it belongs to (a fixed speed
/// or a fixed Froude number) and the prediction (with its interval and range flag).
struct LawCurvePoint {
  std::string curve;
  double gravity_m_s2 = NAN;
  LawPrediction p;
};

/// zstop, tstop and apeak of a saved law against g (log axes), one curve per fixed speed or Froude
/// number with its 95 % band; the fitted gravity range unshaded, extrapolated points dashed,
/// refused ones (predicted with --extrapolate) dotted. `out`: PNG.
void draw_law_against_gravity(const std::vector<LawCurvePoint>& points, const LawRange& fitted_gravity,
                              const std::string& out, const std::string& title);

}  // namespace gravsweep::results
