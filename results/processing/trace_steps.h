// The seams of process_trace (trace.h), one function each so that each is tested on its own
// (tests/results/test_trace_steps.cpp): filter, contact peak, sensor bias, collision start,
// collision end (threshold and step edge), rest segment, integration, peak, rebound. Conventions
// as trace.h: z and v positive down, acceleration positive up (free fall -g, rest 0).
// Not an interface for callers outside results/processing/ and its tests: use process_trace.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "results/processing/trace.h"

namespace gravsweep::results::trace_steps {

/// Linear interpolation of the time where y crosses `level` between samples i and i + 1.
double crossing_time(const std::vector<double>& t, const std::vector<double>& y, std::size_t i, double level);
/// y(tq) by linear interpolation, held constant beyond the ends.
double interp_at(const std::vector<double>& t, const std::vector<double>& y, double tq);
double mean_of(const std::vector<double>& x, std::size_t b, std::size_t e);    ///< of [b, e)
double stddev_of(const std::vector<double>& x, std::size_t b, std::size_t e);  ///< sample std of [b, e)

/// The options' low-pass of the raw acceleration; unfiltered (and `note` says why) when the
/// cut-off is not below the Nyquist frequency.
std::vector<double> filter_acceleration(const std::vector<double>& accel_up_m_s2, double fs_hz, const MetricOptions& o,
                                        std::string& note);

/// Edge width in samples: a zero-phase Butterworth spreads (and rings around) a step over about
/// fs/fc samples on each side.
std::size_t edge_width(double fs_hz, double cutoff_hz);

/// The sample of the largest filtered acceleration; throws std::invalid_argument when it does not
/// stand clear of free fall (above -g/2): the projectile never makes contact.
std::size_t contact_peak(const std::vector<double>& af, double g_m_s2);

/// First guess of the sensor bias (m/s2): the record's head reads -g + bias (it starts in free
/// fall); its median over the samples check_starts_in_free_fall probes (up to
/// kFreeFallProbeSamples, at most a third of the way to the peak). Not the whole first third: a
/// slow low-gravity collision peaks late, and that third held more collision than free fall
/// (measured: the bias came out 1.4 m/s2 at 1.2 m/s2 and the start was placed inside the collision).
double initial_bias(const std::vector<double>& af, std::size_t ipk, double g_m_s2);

/// A lab record starts in free fall and ends at rest: its first samples read about g below its
/// last ones, whatever the sensor bias. Throws TraceError (sample 0) when the head reads less than
/// kFreeFallMinDrop_g * g below the tail (a record that starts at rest or inside the collision).
/// Head and tail: up to kFreeFallProbeSamples samples, and at most a third of the way to the peak.
inline constexpr double kFreeFallMinDrop_g = 0.5;
inline constexpr std::size_t kFreeFallProbeSamples = 10;
void check_starts_in_free_fall(const std::vector<double>& t, const std::vector<double>& af, std::size_t ipk,
                               double g_m_s2);

/// The collision start: the last sample before it and its time, and whether it is a step edge
/// (faster than the filter, located at half height).
struct CollisionStart {
  std::size_t i_start = 0;
  double t_start_s = 0;
  bool step = false;
};
/// DEM records: the engine's first contact (Trace::contact_start_s).
CollisionStart contact_start(const std::vector<double>& t, double t_contact_s);
/// The time (s) y takes to rise from 10 to 90 % of the way from foot to top, searched forward
/// over [b, e] (linear interpolation between samples; t[e] for a level it does not reach).
double rise_10_90_s(const std::vector<double>& t, const std::vector<double>& y, std::size_t b, std::size_t e,
                    double foot, double top);
/// The 10-90 % rise time (s), up to its overshoot, of the options' low-pass on a unit step
/// sampled at fs_hz: the
/// fastest an edge can rise in the filtered record (unfiltered: 0.8 sample, a jump between two
/// samples read by linear interpolation).
double filter_step_rise_s(double fs_hz, const MetricOptions& o);
/// The paper's rule (Sect. 2.3): the last sample before the peak ipk still within the free-fall
/// band -g + thr, the start at the threshold crossing. An edge about as fast as the filter (the
/// ramp it is, the filter's own rise step_rise_s taken out of its 10-90 % rise, lasts no longer
/// than kStepRampRises times step_rise_s; its height reached within 2w samples) starts at its
/// onset instead: its half height less half that ramp. The filter's spread and ringing cross the threshold early there
/// (about two samples at 1.4 kHz); a contact that ramps in over several samples (a slow impact in high gravity, issue
/// 13) starts at its foot, the threshold crossing extrapolated back along the ramp (the crossings of thr and 2 thr),
/// not ms later at its half height. `step` says the half-height onset was used. Throws std::invalid_argument when no
/// sample before the peak reads -g. A contact ramp up to this many filter rises long counts as a step (2 ms at 500 Hz:
/// a 1 mm contact ramp at 0.5 m/s and faster), so that its peak is extrapolated as a step's, as a model's record of it
/// (with no ramp) is; noise moves a ramp of about one filter rise across the line.
inline constexpr double kStepRampRises = 2.0;
CollisionStart free_fall_start(const std::vector<double>& t, const std::vector<double>& a, std::size_t ipk,
                               double g_m_s2, double thr_m_s2, std::size_t w, double step_rise_s);

/// What the collision end is searched with.
struct EndCriteria {
  double end_level_m_s2 = 0;                   ///< end_threshold_g * g
  double v_end_m_s = 0;                        ///< end_speed_fraction * |vc|
  const std::vector<double>* speed = nullptr;  ///< downward speed per sample, when known
  std::size_t hold = 3;                        ///< samples the acceleration must stay below the level
};
/// Samples to hold the end level: hold_s (MetricOptions::end_hold_s), at least 3 samples.
std::size_t end_hold_samples(double fs_hz, double hold_s);
/// The depth rule's end (EndRule::depth): the time at which z first reaches `fraction` of its
/// maximum over [i_start, i_last] after t_start_s (interpolated), with the sample after it.
struct DepthEnd {
  std::size_t i_end = 0;
  double t_end_s = 0;
};
DepthEnd depth_end(const std::vector<double>& t, const std::vector<double>& z, std::size_t i_start, std::size_t i_last,
                   double fraction);
/// The first sample at or after the peak where the acceleration stays below the end level for
/// `hold` samples with the speed below v_end; nullopt when there is none.
std::optional<std::size_t> end_sample(const std::vector<double>& a, std::size_t ipk, const EndCriteria& c);

/// Robust standard deviation of x over [b, e): 1.4826 times the median absolute deviation (the
/// std of Gaussian noise, unmoved by a minority of outliers). 0 when fewer than 3 samples.
double robust_sigma(const std::vector<double>& x, std::size_t b, std::size_t e);

/// Noise-aware end level: the paper's end_threshold_g of the local g, raised to
/// kEndNoiseSigmas times the filtered record's noise where 0.1 g drowns in it (low gravity), so
/// that noise alone never reads as the projectile still decelerating.
inline constexpr double kEndNoiseSigmas = 5.0;
double end_level(double end_threshold_g, double g_m_s2, double noise_sigma_m_s2);

/// The filtered record's noise (m/s2): robust_sigma of its free-fall segment [0, ff_end) (at
/// least 5 samples) or else of its last quarter (rest). Not of a fixed share of the way to the
/// peak: a slow low-gravity collision peaks late, and that share held the collision's own
/// fluctuations, which read as noise 50 times the sensor's and raised the end level above them.
double record_noise(const std::vector<double>& af, std::size_t ff_end);

/// Lab records with an integrated velocity: the collision end searched back from the end of the
/// record, the paper's rule read as "the acceleration falls below the level and stays there": the
/// sample after the last one at or above `level` at or after ipk. A grain-scale dip inside the
/// collision cannot end it early, and the rest segment is everything after it. nullopt when fewer
/// than `hold` samples follow (the record ends inside the collision).
std::optional<std::size_t> last_exceedance_end(const std::vector<double>& a, std::size_t ipk, double level_m_s2,
                                               std::size_t hold);

/// The collision end: the first sample after it, its time (threshold crossing, or half height of
/// a step edge: a fall to half the level w samples earlier), whether it is a step edge.
struct CollisionEnd {
  std::size_t i_end = 0;
  double t_end_s = 0;
  bool step = false;
  double step_height_m_s2 = 0;  ///< a step's height (the level before it), 0 otherwise
};
CollisionEnd end_edge(const std::vector<double>& t, const std::vector<double>& a, std::size_t j, std::size_t i_start,
                      std::size_t w, double end_level_m_s2);

/// Rest segment [rest_begin, n): the last three quarters of what follows the collision end and
/// its edge, so that late settling stays out of it.
std::size_t rest_begin(std::size_t i_end, std::size_t w, std::size_t n);

/// Fewest samples of rest that the bias and bring_to_rest use.
inline constexpr std::size_t kMinRestSamples = 10;

/// The sensor bias from free fall [0, ff_end) (reads -g + bias) and rest [rest_begin, n) (reads
/// bias), weighted by sample count; segments under 3 (free fall) or kMinRestSamples (rest)
/// samples are unused.
struct BiasEstimate {
  double bias_m_s2 = 0;
  bool any = false;  ///< false: neither segment long enough (keep the previous bias)
  std::size_t free_fall_samples = 0, rest_samples = 0;
  std::optional<double> sigma_free_fall_m_s2;  ///< noise of the free-fall segment, when used
};
BiasEstimate bias_from_segments(const std::vector<double>& af, double g_m_s2, std::size_t ff_end,
                                std::size_t rest_begin);

/// Velocity (positive down) and depth from the acceleration (positive up), dv_down/dt = -a_up, by
/// trapezoids both ways from the collision start (v = v0, z = 0 at t_start, between samples
/// i_start and i_start + 1).
void integrate_from_start(const std::vector<double>& t, const std::vector<double>& a, std::size_t i_start,
                          double t_start_s, double v0_m_s, std::vector<double>& v, std::vector<double>& z);

/// Lab records: the integrated velocity brought to rest. After the collision the
/// projectile rests, so the speed integrated from the reported impact speed must read zero over
/// the rest segment [rest_begin, n). What it reads is, to first order, a constant offset from the
/// contact on: the reported speed's own error (0.5 % of vc is 5 % of zstop in low gravity, where
/// the collision lasts about ten times zstop / vc), a step contact located only to within a
/// sample, the part of the contact the zero-phase filter spreads before the start, g times an
/// error of the start. That offset is removed from v and, integrated from t_start, from z. One
/// part of the reading is not such an offset: a step at the end (Eq. 1 stops with a jump of the
/// deceleration) is located to within a sample too, which shifts v after the end only (up to
/// half a sample times its height, `end_tolerance_m_s`); that much of the reading is left alone.
/// Returns the offset removed (m/s); 0, and v and z unchanged, when the rest segment has fewer
/// than kMinRestSamples samples.
double bring_to_rest(const std::vector<double>& t, std::size_t rest_begin, double t_start_s, double end_tolerance_m_s,
                     std::vector<double>& v, std::vector<double>& z);

/// The peak: the largest filtered acceleration of the collision [i_start + 1, i_end], leaving out
/// the filter's ringing next to step edges; at a step-like contact the early samples beyond the
/// ringing (and clear of a step end's ringing) are extrapolated back to the contact speed vc by a
/// least-squares line in v^2.
double peak_acceleration(const std::vector<double>& a, const std::vector<double>& v, std::size_t i_start,
                         std::size_t i_end, bool step_start, bool step_end, std::size_t w, double vc_m_s,
                         double g_m_s2);

/// A rebound rises back by more than this fraction of the maximum depth after reaching it.
inline constexpr double kReboundRiseFraction = 0.1;

/// The deepest point in [i_start, i_last_depth] (the paper's zstop, Sect. 2.3: the maximum
/// penetration depth; the caller passes the record's last sample when the depth is the record's own,
/// as a DEM projectile may still sink slowly after the acceleration criterion ended the collision
/// at low gravity, and the collision end for a depth integrated from an accelerometer, which drifts
/// after it) and the one rebound rule: after its deepest point the projectile rose back
/// by more than kReboundRiseFraction of that depth (anywhere in the rest of the record). Moving up
/// fast and reaching within one grain of the floor are noted, not flagged by themselves.
struct Rebound {
  bool rebound = false;
  double max_depth_m = 0;
  std::size_t i_max_depth = 0;
  std::string note;  ///< "rose ... back up ...; moved up at ... m/s; reached ... m, within one grain of the floor ..."
};
Rebound rebound_of(const std::vector<double>& v, const std::vector<double>& z, std::size_t i_start, std::size_t i_end,
                   std::size_t i_last_depth, double vc_m_s, const MetricOptions& o);

}  // namespace gravsweep::results::trace_steps
