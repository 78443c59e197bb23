// Angle-of-repose pile: grains poured through a small outlet onto a rough base of fixed grains
// (the piling test of Sunday et al. 2020 that calibrated Chrono's mu_r = 0.09 against 1 mm glass
// beads; Sunday et al. 2021 Table 2 gives pkdgrav's angles). Grains that roll off the base are
// removed; the angle of repose is the slope of the heap's flank. Engine frame: z up, base centred
// on the z axis, base grains resting on z = 0.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include "engine/scenario/bed.h"

namespace gravsweep {

struct PileSpec {
  GrainSpec grains;             ///< poured grains (default: Table 1 glass beads)
  double base_radius_m = 0.15;  ///< radius of the rough base (fixed grains of the mean size)
  std::size_t grains_poured = 2000;
  double pour_rate_per_s = 1000;       ///< grains released per second (at most)
  double outlet_radius_m = 0.02;       ///< grains are released at random points of this disk
  double release_gap_m = 0.03;         ///< outlet height above the resting grains below it
  double release_speed_m_s = 0.1;      ///< downward speed at release
  double settle_rms_speed_m_s = 1e-3;  ///< after the pour: run until the grains are this slow
  double settle_max_speed_m_s = 1e-2;
  double max_settle_time_s = 2.0;
  std::uint64_t seed = 7;
  std::uint8_t grain_material = 0;  ///< for the poured and the base grains
};

struct PileResult {
  double angle_deg = 0;            ///< slope of the flank (least squares of height against radius)
  double apex_height_m = 0;        ///< highest grain top above the base
  std::size_t grains_on_base = 0;  ///< free grains left on the heap
  std::size_t flank_bins = 0;      ///< surface bins used by the slope fit
  double rms_speed_m_s = 0;        ///< at the measurement
  double simulated_time_s = 0;
};

/// progress(fraction in [0, 1], detail)
using PileProgress = std::function<void(double, const std::string&)>;

/// Builds the base, pours, settles and measures. `sys` must hold no particles or walls; its
/// config (law, materials, dt) is used as is, except the domain, which is set to hold the pile.
PileResult pour_pile(System& sys, const PileSpec& spec, const PileProgress& progress = {});

/// The angle of the heap now in `sys`: the top of the free grains above `base_top_m` on a square
/// grid of 1.5 grain diameters, then a least-squares line of top height against distance from the
/// axis over the bins between 20 % and 80 % of the apex height (apex and toe left out), inside
/// the base radius. Fills every field but simulated_time_s.
PileResult measure_pile(const System& sys, double base_top_m, double base_radius_m);

}  // namespace gravsweep
