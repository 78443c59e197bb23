// A synthetic impact laboratory: writes measurement campaigns (docs/formats/measurements.md)
// from any model spec plus a noise model, so analyses can be tested on data with a known hidden
// effect (docs/physics/force-laws.md section 2.4, step 4).
#pragma once
#include <string>
#include <vector>

#include "results/model/fit.h"
#include "results/model/model_spec.h"

namespace gravsweep::results {

struct SynthOptions {
  std::vector<double> gravity_m_s2{9.81, 1.2, 0.1};
  std::vector<double> impact_speed_m_s{0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 1.0, 1.2};
  std::vector<double> fill_height_m{0.21};  ///< cycled over the trials in order
  int repeats = 3;
  double mass_kg = 1.0;
  double diameter_m = 0.1;
  double grain_diameter_m = 0.01;
  double bulk_density_kg_m3 = 1450;
  double sample_rate_hz = 1400;
  // Noise model
  double sensor_noise_g = 0.015;  ///< white sensor noise, in units of the trial's g (see below)
  double sensor_bias_g = 0.01;    ///< std of the constant per-trial bias, in g (see below)
  /// true: noise and bias scale with the trial's g (an accelerometer range chosen for each
  /// level); false: they are in units of the standard 9.81 m/s2 at every level (one sensor for
  /// all, so 0.1 g of a low-gravity level drowns in it).
  bool noise_scales_with_g = true;
  double rest_tail_s = 0.1;  ///< record length after the projectile comes to rest
  /// The accelerometer's range: a reading beyond +/- this saturates at it (0: no limit), as a
  /// sensor too small for the fastest impacts does (a flat top, measurements import flags it).
  double sensor_range_m_s2 = 0;
  double force_fluct = 0.2;  ///< multiplicative grain-scale fluctuation (std)
  double force_fluct_tau_s = 1.5e-3;
  double bed_spread_f0 = 0.08;    ///< per-trial relative spread of friction-like terms
  double bed_spread_drag = 0.05;  ///< per-trial relative spread of 1/d1
  double speed_spread = 0.005;    ///< relative scatter of the reported impact speed
  double contact_ramp_m = 1e-3;   ///< force ramps in over the first millimetre
  unsigned seed = 1;
  /// Trial names are this followed by a number (S001, ...): campaigns read together need their own.
  std::string trial_prefix = "S";
  /// Non-empty: the speeds by Froude number, v = Fr sqrt(g D) at each level, in place of
  /// impact_speed_m_s (the design of a gravity sweep).
  std::vector<double> froude;
  /// true: the drop's own times scale as sqrt(D / g) from their values at 9.81 m/s2 and D = 10 cm
  /// (the free fall before contact, the force fluctuation's correlation time, the rest after it
  /// and the longest collision), as in a Froude-scaled drop, where every time is a multiple of
  /// sqrt(D / g); the sensor's sample rate stays. false: fixed in seconds at every level.
  bool froude_times = false;
  /// RMS, in g, of the grain contacts' chatter on the record from contact on (a zero-mean white
  /// acceleration per sample, on top of the motion): at 9.81 m/s2 and D = 10 cm this value, and
  /// with froude_times sqrt(T / T_1g) times it (T = sqrt(D / g)), so that the chatter is the same
  /// white noise in the drop's own units at every level, band-limited by the grains' contact
  /// frequency (the sample rate here), which does not scale with g: a projectile resting on a bed
  /// at 0.001 m/s2 reads 0.1-0.6 g of contacts through a 500 Hz filter (a DEM drop). 0: none.
  double contact_chatter_g = 0;
};

/// The model with its terms' typical values (times each term's scale) at the given levels.
FittedModel truth_model(const ModelSpec& spec, const std::vector<double>& gravity_m_s2, double mass_kg,
                        double diameter_m);

/// The file of true metrics that write_synthetic_campaign puts beside trials.csv: trial_id,
/// zstop_m, tstop_s (contact to rest of the integrated motion, before noise and filtering) and
/// t_contact_s (the contact on the trace's clock).
inline constexpr const char* kSynthTruthFile = "truth.csv";

/// Writes <dir>/trials.csv, <dir>/traces/*.csv and <dir>/truth.csv (kSynthTruthFile); returns the
/// number of trials written.
int write_synthetic_campaign(const std::string& dir, const ModelSpec& truth, const SynthOptions& o);

}  // namespace gravsweep::results
