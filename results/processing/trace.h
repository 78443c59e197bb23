// A projectile trace and the paper's processing of it (Sunday et al. 2021 Sect. 2.3). The same
// code processes DEM traces (results of `gravsweep run`) and laboratory accelerometer records.
//
// Conventions: depth z positive DOWN (a DEM trace's from the bed's mean surface, a processed
// trace's from the collision start, as the paper's processing of its records); velocity positive down;
// acceleration as the accelerometer format (docs/formats/measurements.md section 3.2): the
// projectile's vertical kinematic acceleration, positive UP, so free fall reads -g and rest
// reads 0. (Equivalently accel_up = -dv_down/dt.)
#pragma once
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "results/processing/trace_source.h"

namespace gravsweep::results {

struct Trace {
  /// Lab: a sensor record (its constant bias is removed from free fall and rest). DEM: no sensor,
  /// no bias, own velocity and depth required. Never inferred from the columns present.
  TraceSource source = TraceSource::lab;
  std::vector<double> t_s;
  std::vector<double> accel_up_m_s2;
  /// Optional (DEM traces have them; lab records usually not): same length as t_s when present.
  std::vector<double> depth_m;
  std::vector<double> velocity_down_m_s;
  /// DEM records only: the time of the engine's first contact (the last sample before the
  /// projectile touched anything). When set, the collision starts there instead of where the
  /// filtered record leaves free fall: a DEM drop released 1 mm above the bed has 1-6 ms of free
  /// fall, which the 500 Hz filter's edge swallows (no sample reads -g before the peak). Lab
  /// records leave it empty and keep the paper's rule (Sect. 2.3).
  std::optional<double> contact_start_s;
};

/// The paper's processing (Sunday et al. 2021 Sect. 2.3) as it stands for its lab drops at 1 g:
/// a 500 Hz low-pass and an end held for 2 ms, for a D = 10 cm projectile at 9.81 m/s2.
inline constexpr double kPaperCutoff_hz = 500.0;
inline constexpr double kPaperEndHold_s = 0.002;
inline constexpr double kPaperGravity_m_s2 = 9.81;
inline constexpr double kPaperProjectileDiameter_m = 0.1;

/// The time scale the processing's times are set in.
/// froude: the drop's own time sqrt(D / g): the cut-off is kPaperCutoff_hz sqrt((g / D) / (9.81 /
///   0.1 m)) (50.5 sqrt(g / D)) and the hold kPaperEndHold_s over the same factor, so a drop at any
///   gravity is filtered with the same bandwidth in units of sqrt(g / D) as the paper's 1 g drop
///   (at 0.01 m/s2 a 500 Hz filter is 31 times wider in those units, and a projectile at rest read
///   0.1-0.6 g of grain contacts through it). At g = 9.81 m/s2 and D = 10 cm it is the paper's.
/// fixed: the paper's hertz and seconds at every gravity (the processing before the time scale).
/// Which one a trial gets: time_scale_for (results/measurements/trial.h).
enum class TimeScale { froude, fixed };
const char* to_string(TimeScale s);
/// Throws std::invalid_argument naming the expected values.
TimeScale time_scale_of(const std::string& s);

/// Which rule ends the collision (MetricOptions::end_rule).
/// paper: the acceleration below end_threshold_g g, held for the hold time (Sect. 2.3).
/// speed: the paper's, with the projectile's speed below end_speed_fraction vc too (a lull between
///   force-chain bursts does not end it); lab records searched back from the rest at the record's end.
/// depth: where the depth first reaches kEndDepthFraction of the collision's maximum depth (the
///   speed rule still places the rest that a lab record's bias and integration need). Independent
///   of the filter and of a sensor's noise, and in the drop's own scales by construction.
enum class EndRule { paper, speed, depth };
const char* to_string(EndRule r);
/// Throws std::invalid_argument naming the expected values.
EndRule end_rule_of(const std::string& s);
/// The depth rule's fraction of the maximum depth.
inline constexpr double kEndDepthFraction = 0.99;

struct MetricOptions {
  double gravity_m_s2 = 9.81;
  double cutoff_hz = kPaperCutoff_hz;  ///< 2nd-order Butterworth low-pass (paper: 500 Hz at 1 g)
  int filter_order = 2;
  double end_hold_s = kPaperEndHold_s;  ///< the end level must hold this long (paper: 2 ms at 1 g)
  EndRule end_rule = EndRule::speed;
  double end_threshold_g = 0.1;  ///< collision ends when |a| < 0.1 g (paper)
  /// ... and the projectile has lost this much of its collision speed: its downward speed is below
  /// end_speed_fraction * vc. A DEM projectile is stopped by bursts of force chains with lulls of
  /// near-zero acceleration between them (coasting at half its speed for 10-20 ms in a small bed);
  /// the paper's threshold alone would end the collision at the first lull. A lab record that
  /// stops as Eq. 1 does (speed to zero at the end) is not affected.
  double end_speed_fraction = 0.1;
  /// Records whose velocity is integrated (lab records): the end searched back from the rest at
  /// the record's end, at a level raised above the noise (trace_steps.h). false: the
  /// forward search alone, the earlier rule (kept to measure what the change does).
  bool end_from_rest = true;
  /// Speed at first contact, used to integrate a into v and z when the trace has none.
  std::optional<double> impact_speed_m_s;
  /// For the rebound flag: bed depth (the floor's depth below the surface, m: a lab trial's fill
  /// height, a DEM drop's measured surface height) and grain diameter (a projectile within one
  /// grain of the floor has "hit the bottom").
  std::optional<double> fill_height_m;
  std::optional<double> grain_diameter_m;
  double projectile_diameter_m = 0.1;
};

/// The paper's metrics of one collision.
struct Metrics {
  double vc_m_s = 0;      ///< collision velocity (speed at collision start)
  double apeak_m_s2 = 0;  ///< peak (upward) acceleration of the filtered trace
  double zstop_m = 0;     ///< penetration depth: the maximum depth of the collision, from its start (Sect. 2.3)
  /// Depth of the collision start below the bed's mean surface (DEM: the projectile's lowest point
  /// at first contact, negative above the surface; lab: 0, the depth is integrated from there).
  double start_depth_m = 0;
  double zstop_surface_m = 0;  ///< the maximum depth below the bed's mean surface: zstop_m + start_depth_m
  double depth_at_end_m = 0;   ///< depth at the collision end (below zstop_m after a rebound)
  double final_depth_m = 0;    ///< depth at the last sample of the record
  double tstop_s = 0;          ///< collision duration (end - start)
  double cutoff_hz = 0;        ///< the low-pass cut-off applied (MetricOptions, after the time scale)
  double end_hold_s = 0;       ///< the end's hold applied
  double t_start_s = 0;        ///< collision start: no longer in free fall
  double t_end_s = 0;          ///< collision end (MetricOptions::end_rule)
  bool rebound = false;        ///< rose back by more than 10 % of zstop after it (trace_steps::rebound_of)
  std::string note;            ///< why a metric could not be found, if so
};

/// A processed trace: the filtered, bias-corrected acceleration, the velocity and depth (the
/// trace's own, or integrated from the impact speed) and the metrics.
struct ProcessedTrace {
  Metrics metrics;
  std::vector<double> t_s;
  std::vector<double> accel_up_m_s2;      ///< filtered, bias removed
  std::vector<double> velocity_down_m_s;  ///< positive down
  std::vector<double> depth_m;            ///< positive down, 0 at the collision start
  double sample_rate_hz = 0;
  double bias_m_s2 = 0;               ///< removed sensor bias
  std::size_t free_fall_samples = 0;  ///< samples used for the bias from free fall
  std::size_t rest_samples = 0;       ///< samples used for the bias from rest
  /// Lab records integrated from the impact speed: the speed the integration still read at rest,
  /// removed from velocity and depth (trace_steps::bring_to_rest); 0 for a record with its own.
  double rest_speed_offset_m_s = 0;
  std::size_t i_start = 0;  ///< last sample before the collision start
  std::size_t i_end = 0;    ///< first sample after the collision end
};

/// Why a trace cannot be measured, and the sample the reason is about when there is one (the
/// first sample of a record that does not start in free fall, the out-of-range sample, the peak of
/// a record that never makes contact, the last sample of one that ends inside the collision), so
/// that a reader can name the line it came from. Callers may catch it as std::invalid_argument.
class TraceError : public std::invalid_argument {
 public:
  /// `bad_value`: the sample's acceleration value itself is the reason (a reader names its column).
  explicit TraceError(const std::string& what, std::optional<std::size_t> sample = std::nullopt, bool bad_value = false)
      : std::invalid_argument(what), sample_(sample), bad_value_(bad_value) {}
  [[nodiscard]] std::optional<std::size_t> sample() const { return sample_; }
  [[nodiscard]] bool bad_value() const { return bad_value_; }

 private:
  std::optional<std::size_t> sample_;
  bool bad_value_ = false;
};

/// Largest |acceleration| a record may hold, m/s2 (1e5 g: beyond the range of shock
/// accelerometers; granular impacts reach 1e2-1e3 g). A larger sample is a corrupt record, and
/// one near 1e308 would overflow the filter.
inline constexpr double kMaxAccel_m_s2 = 1e6;
/// Zero-phase (forward-backward) Butterworth low-pass of order `order` at `cutoff_hz`.
std::vector<double> butterworth_lowpass(const std::vector<double>& x, double sample_rate_hz, double cutoff_hz,
                                        int order = 2);

/// Computes the metrics as the paper does; throws TraceError with the reason (and the sample) when
/// the trace is too short, holds a sample beyond kMaxAccel_m_s2, does not start in free fall,
/// never makes contact, ends inside the collision or has non-increasing time.
Metrics compute_metrics(const Trace& trace, const MetricOptions& options);

/// The same processing, returning the processed arrays with the metrics (same errors).
ProcessedTrace process_trace(const Trace& trace, const MetricOptions& options);

}  // namespace gravsweep::results
