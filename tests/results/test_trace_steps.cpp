// The seams of process_trace (results/processing/trace_steps.h), each on a record built for it:
// filter, contact peak, bias, collision start, collision end and its edge, rest segment,
// integration, peak, rebound. The whole chain is tested in test_trace.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "results/processing/trace_steps.h"

using namespace gravsweep::results;
using namespace gravsweep::results::trace_steps;

namespace {

constexpr double kG = 9.81;

std::vector<double> times(std::size_t n, double fs) {
  std::vector<double> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / fs;
  return t;
}

}  // namespace

TEST(TraceSteps, FilterIsTheButterworthOrSaysWhyNot) {
  std::vector<double> x(100, 0.0);
  x[50] = 1.0;
  MetricOptions o;
  std::string note;
  EXPECT_EQ(filter_acceleration(x, 1400, o, note), butterworth_lowpass(x, 1400, 500, 2));
  EXPECT_TRUE(note.empty());
  EXPECT_EQ(filter_acceleration(x, 800, o, note), x);  // 500 Hz is above the 400 Hz Nyquist
  EXPECT_NE(note.find("not filtered"), std::string::npos) << note;
}

TEST(TraceSteps, EdgeWidthAndHoldFollowTheRates) {
  EXPECT_EQ(edge_width(1400, 500), 4u);  // 1 + ceil(2.8)
  EXPECT_EQ(edge_width(10000, 500), 21u);
  EXPECT_EQ(end_hold_samples(1400, 0.002), 3u);  // 2 ms is 2.8 samples: at least 3
  EXPECT_EQ(end_hold_samples(10000, 0.002), 20u);
}

TEST(TraceSteps, ContactPeakIsTheMaximumAndFreeFallOnlyNeverMakesContact) {
  std::vector<double> a(50, -kG);
  EXPECT_THROW(contact_peak(a, kG), std::invalid_argument);
  a[30] = 20.0;
  a[31] = 25.0;
  EXPECT_EQ(contact_peak(a, kG), 31u);
}

TEST(TraceSteps, InitialBiasIsTheMedianOfTheHeadAboveMinusG) {
  std::vector<double> a(90, 0.0);
  for (std::size_t i = 0; i < 60; ++i) a[i] = -kG + 0.3 + (i == 5 ? 50.0 : 0.0);  // one spike
  EXPECT_NEAR(initial_bias(a, 60, kG), 0.3, 1e-12);
  // A slow collision that peaks late: only the first samples are free fall, the rest of the
  // first third is collision; the head alone sets the bias.
  std::vector<double> late(300, 0.7);
  for (std::size_t i = 0; i < 14; ++i) late[i] = -kG + 0.3;
  late[250] = 2.0;
  EXPECT_NEAR(initial_bias(late, 250, kG), 0.3, 1e-12);
}

TEST(TraceSteps, ContactStartIsTheLastSampleBefore) {
  const auto t = times(20, 1000);
  const CollisionStart s = contact_start(t, 0.0105);
  EXPECT_EQ(s.i_start, 10u);
  EXPECT_DOUBLE_EQ(s.t_start_s, 0.0105);
  EXPECT_FALSE(s.step);
  EXPECT_EQ(contact_start(t, -1.0).i_start, 0u);
}

TEST(TraceSteps, FreeFallStartAtTheThresholdForARampAndAtHalfHeightForAStep) {
  const double fs = 1400, thr = 0.03 * kG, jump_s = 0.8 / fs;  // unfiltered: a jump's 10-90 % rise
  const auto t = times(100, fs);
  std::vector<double> ramp(100, -kG), step(100, -kG);
  for (std::size_t i = 40; i < 100; ++i) ramp[i] = -kG + 0.05 * static_cast<double>(i - 40);
  for (std::size_t i = 40; i < 100; ++i) step[i] = 20.0;  // the jump between samples 39 and 40
  const CollisionStart r = free_fall_start(t, ramp, 99, kG, thr, 4, jump_s);
  EXPECT_EQ(r.i_start, 45u);  // -g + 0.25, the last sample below -g + thr
  EXPECT_NEAR(r.t_start_s, t[40] + (thr / 0.05) / fs, 1e-9);
  EXPECT_FALSE(r.step);
  const CollisionStart s = free_fall_start(t, step, 99, kG, thr, 4, jump_s);
  EXPECT_TRUE(s.step);
  EXPECT_EQ(s.i_start, 39u);
  EXPECT_NEAR(s.t_start_s, t[39] + 0.5 / fs, 1e-9);  // half height
  std::vector<double> none(100, 0.0);
  none[60] = 5.0;
  EXPECT_THROW(free_fall_start(t, none, 60, kG, thr, 4, jump_s), std::invalid_argument);
}

// On the filtered record (1400 Hz, 500 Hz), a step contact starts at its half height
// (the filter's ringing crosses the threshold about two samples early) and a contact that ramps
// in over 4 ms (a slow impact in high gravity) where its ramp begins, not 2 ms later at its half
// height.
TEST(TraceSteps, FilteredStartIsTheOnsetOfARampAndTheMiddleOfAStep) {
  const double fs = 1400, thr = 0.03 * kG, t_contact = 50.3 / fs, ramp_s = 0.004;
  const auto t = times(200, fs);
  std::vector<double> step(200), ramp(200);
  for (std::size_t i = 0; i < 200; ++i) {
    const double s = t[i] - t_contact;
    step[i] = s < 0 ? -kG : 8.0;
    ramp[i] = s < 0 ? -kG : -kG + (8.0 + kG) * std::min(1.0, s / ramp_s);
  }
  MetricOptions o;
  const double rise_s = filter_step_rise_s(fs, o);
  EXPECT_GT(rise_s, 0.8 / fs);  // the filter slows a jump down ...
  EXPECT_LT(rise_s, 2.0 / fs);  // ... to about a millisecond at 500 Hz
  const std::size_t w = edge_width(fs, o.cutoff_hz);
  const auto fstep = butterworth_lowpass(step, fs, o.cutoff_hz, o.filter_order);
  const auto framp = butterworth_lowpass(ramp, fs, o.cutoff_hz, o.filter_order);
  const CollisionStart s = free_fall_start(t, fstep, 120, kG, thr, w, rise_s);
  EXPECT_TRUE(s.step);
  EXPECT_NEAR(s.t_start_s, 50.5 / fs, 0.1 / fs);  // the jump lies between samples 50 and 51
  const CollisionStart r = free_fall_start(t, framp, 120, kG, thr, w, rise_s);
  EXPECT_FALSE(r.step);
  EXPECT_NEAR(r.t_start_s, t_contact, 0.2 / fs) << "the ramp's half height is at " << t_contact + ramp_s / 2;
  EXPECT_LE(t[r.i_start], r.t_start_s);
  EXPECT_GT(t[r.i_start + 1], r.t_start_s);
  // A noisy record's threshold (6 sigma, here 1.5 m/s2) is crossed 0.34 ms after the foot; the
  // ramp extrapolated back finds the foot.
  const double thr_noisy = 1.5, lag_s = thr_noisy / ((8.0 + kG) / ramp_s);
  const CollisionStart q = free_fall_start(t, framp, 120, kG, thr_noisy, w, rise_s);
  EXPECT_NEAR(q.t_start_s, t_contact, 0.25 * lag_s) << "the threshold is crossed at " << t_contact + lag_s;
}

TEST(TraceSteps, EndSampleNeedsTheLevelHeldAndTheSpeedDown) {
  std::vector<double> a(40, 5.0), v(40, 0.5);
  for (std::size_t i = 25; i < 40; ++i) a[i] = 0.0, v[i] = 0.0;
  a[12] = 0.0;  // a one-sample dip inside the collision does not end it
  EndCriteria c;
  c.end_level_m_s2 = 0.1 * kG;
  c.hold = 3;
  EXPECT_EQ(end_sample(a, 5, c), 25u);
  for (std::size_t i = 12; i < 16; ++i) a[i] = 0.0;  // a lull of 4 samples ...
  EXPECT_EQ(end_sample(a, 5, c), 12u);
  c.speed = &v;  // ... is not the end while the projectile still moves
  c.v_end_m_s = 0.05;
  EXPECT_EQ(end_sample(a, 5, c), 25u);
  for (std::size_t i = 25; i < 40; ++i) v[i] = 0.2;
  EXPECT_FALSE(end_sample(a, 5, c).has_value());
}

TEST(TraceSteps, EndEdgeIsAStepWhenTheLevelFallsWithinTheEdgeWidth) {
  const auto t = times(60, 1400);
  std::vector<double> a(60, 0.0);
  for (std::size_t i = 0; i < 30; ++i) a[i] = 10.0;
  a[30] = 5.0;  // half height at sample 30
  const CollisionEnd e = end_edge(t, a, 31, 5, 4, 0.1 * kG);
  EXPECT_TRUE(e.step);
  EXPECT_EQ(e.i_end, 31u);
  EXPECT_NEAR(e.t_end_s, t[30], 1e-9);
  std::vector<double> slow(60, 0.0);  // a gradual fall: the threshold crossing
  for (std::size_t i = 0; i < 60; ++i) slow[i] = std::max(0.0, 1.5 - 0.05 * static_cast<double>(i));
  const std::size_t j = 11;  // first sample below 0.981
  const CollisionEnd g = end_edge(t, slow, j, 0, 4, 0.1 * kG);
  EXPECT_FALSE(g.step);
  EXPECT_NEAR(g.t_end_s, t[10] + (1.0 - 0.981) / 0.05 / 1400, 1e-9);
}

TEST(TraceSteps, RestIsTheLastThreeQuartersAfterTheEdge) {
  EXPECT_EQ(rest_begin(100, 4, 205), 105u + 25u);
  EXPECT_EQ(rest_begin(200, 4, 203), 203u);  // nothing after the end
}

TEST(TraceSteps, BiasFromFreeFallAndRestWeightedBySamples) {
  std::vector<double> af(100, 0.2);                        // rest reads the bias 0.2
  for (std::size_t i = 0; i < 20; ++i) af[i] = -kG + 0.5;  // free fall reads -g + 0.5
  const BiasEstimate b = bias_from_segments(af, kG, 20, 60);
  EXPECT_TRUE(b.any);
  EXPECT_NEAR(b.bias_m_s2, (20 * 0.5 + 40 * 0.2) / 60.0, 1e-12);
  EXPECT_EQ(b.free_fall_samples, 20u);
  EXPECT_EQ(b.rest_samples, 40u);
  ASSERT_TRUE(b.sigma_free_fall_m_s2.has_value());
  EXPECT_NEAR(*b.sigma_free_fall_m_s2, 0.0, 1e-12);
  const BiasEstimate none = bias_from_segments(af, kG, 2, 95);  // 2 and 5 samples: too few
  EXPECT_FALSE(none.any);
  EXPECT_FALSE(none.sigma_free_fall_m_s2.has_value());
}

TEST(TraceSteps, IntegrationIsExactForConstantDeceleration) {
  const double fs = 1000, A = 4.0, v0 = 0.8, t0 = 0.0203;
  const auto t = times(200, fs);
  std::vector<double> a(200), v, z;
  for (std::size_t i = 0; i < 200; ++i) a[i] = A;  // constant upward acceleration
  integrate_from_start(t, a, 20, t0, v0, v, z);
  for (std::size_t k : {0u, 19u, 21u, 100u, 199u}) {
    const double s = t[k] - t0;
    EXPECT_NEAR(v[k], v0 - A * s, 1e-12) << k;
    EXPECT_NEAR(z[k], v0 * s - 0.5 * A * s * s, 1e-12) << k;
  }
}

// The integrated speed at rest reads zero. A reported impact speed 1 % high shifts v
// by 0.01 vc from the contact on and makes zstop deep by 0.01 vc tstop; brought to rest, both are
// as the true motion's, except for the part a step at the end explains (end_tolerance).
TEST(TraceSteps, BringToRestRemovesAConstantSpeedOffsetFromVAndZ) {
  const double fs = 1000, A = 2.0, vc = 0.8, t0 = 0.0203, tstop = vc / A;
  const auto t = times(600, fs);
  std::vector<double> v(600), z(600);
  auto truth = [&](double tk, double& vk, double& zk) {
    const double s = std::clamp(tk - t0, 0.0, tstop);
    vk = vc - A * s;
    zk = vc * s - 0.5 * A * s * s;
  };
  const double c = 0.01 * vc;  // the offset of a reported speed 1 % high
  for (std::size_t k = 0; k < 600; ++k) {
    truth(t[k], v[k], z[k]);
    if (t[k] > t0) v[k] += c, z[k] += c * (t[k] - t0);
  }
  const std::size_t rb = 500;  // rest from t = 0.5 s (the stop is at 0.42 s)
  auto v1 = v, z1 = z;
  EXPECT_NEAR(bring_to_rest(t, rb, t0, 0.0, v1, z1), c, 1e-12);
  for (std::size_t k : {100u, 300u, 450u, 599u}) {
    double vk, zk;
    truth(t[k], vk, zk);
    EXPECT_NEAR(v1[k], vk, 1e-12) << k;
    EXPECT_NEAR(z1[k], zk, 1e-12) << k;
  }
  auto v2 = v, z2 = z;  // an end step could explain 0.006 of it: only the rest is removed
  EXPECT_NEAR(bring_to_rest(t, rb, t0, 0.006, v2, z2), c - 0.006, 1e-12);
  EXPECT_NEAR(v2[599], 0.006, 1e-12);
  auto v3 = v, z3 = z;  // under kMinRestSamples of rest: unchanged
  EXPECT_EQ(bring_to_rest(t, 600 - kMinRestSamples + 1, t0, 0.0, v3, z3), 0.0);
  EXPECT_EQ(v3, v);
  EXPECT_EQ(z3, z);
}

TEST(TraceSteps, PeakLeavesOutTheRingingAndExtrapolatesAStepContactToVc) {
  // a = c0 + c1 v^2 along the collision; the samples next to the step contact ring.
  const std::size_t n = 80, w = 4;
  std::vector<double> a(n, 0.0), v(n, 0.0);
  const double c0 = 15, c1 = 25, vc = 1.0;
  for (std::size_t k = 10; k < 60; ++k) {
    v[k] = vc * (1.0 - static_cast<double>(k - 10) / 50.0);
    a[k] = c0 + c1 * v[k] * v[k];
  }
  a[11] = 100.0;  // ringing inside 2w of the start
  const double p = peak_acceleration(a, v, 10, 60, true, false, w, vc, kG);
  EXPECT_NEAR(p, c0 + c1 * vc * vc, 1e-6);
  // A gradual contact: the largest sample of the collision, ringing included.
  EXPECT_DOUBLE_EQ(peak_acceleration(a, v, 10, 60, false, false, w, vc, kG), 100.0);
}

TEST(TraceSteps, ReboundIsARiseFromTheDeepestPointOthersAreNotes) {
  MetricOptions o;
  std::vector<double> v(20, 0.3), z(20, 0.05);
  for (std::size_t k = 0; k < 20; ++k) z[k] = 0.001 * static_cast<double>(k);  // deepest at the end
  const Rebound none = rebound_of(v, z, 2, 15, 15, 1.0, o);
  EXPECT_FALSE(none.rebound);
  EXPECT_EQ(none.i_max_depth, 15u);
  EXPECT_DOUBLE_EQ(none.max_depth_m, 0.015);
  v[10] = -0.2;  // moving up fast is noted, the rise decides
  const Rebound up = rebound_of(v, z, 2, 15, 15, 1.0, o);
  EXPECT_FALSE(up.rebound);
  EXPECT_NE(up.note.find("moved up at 0.200 m/s"), std::string::npos) << up.note;
  for (std::size_t k = 11; k < 20; ++k) z[k] = 0.008;  // deepest 0.010 at sample 10, then 2 mm up
  const Rebound rise = rebound_of(v, z, 2, 15, 15, 1.0, o);
  EXPECT_EQ(rebound_of(v, z, 2, 15, 19, 1.0, o).i_max_depth, 10u);  // the search may run past the end
  z[18] = 0.02;
  EXPECT_EQ(rebound_of(v, z, 2, 15, 19, 1.0, o).i_max_depth, 18u);
  EXPECT_TRUE(rise.rebound);
  EXPECT_EQ(rise.i_max_depth, 10u);
  EXPECT_NE(rise.note.find("back up"), std::string::npos) << rise.note;
  o.fill_height_m = 0.015;
  o.grain_diameter_m = 0.01;
  const Rebound floor = rebound_of(v, z, 2, 15, 15, 1.0, o);
  EXPECT_NE(floor.note.find("within one grain of the floor"), std::string::npos) << floor.note;
}

// The pieces of the collision end of lab records in low gravity.
TEST(TraceSteps, RobustSigmaIsTheNoiseWhateverAFewOutliers) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<double> x(4000);
  for (double& v : x) v = 2.0 + 0.05 * n01(rng);
  for (std::size_t i = 0; i < 200; ++i) x[i * 20] = 50.0;  // 5 % outliers
  EXPECT_NEAR(robust_sigma(x, 0, x.size()), 0.05, 0.006);
  EXPECT_EQ(robust_sigma(x, 0, 2), 0.0);
}

TEST(TraceSteps, EndLevelIsTheLocalTenthOfGRaisedAboveTheNoise) {
  EXPECT_DOUBLE_EQ(end_level(0.1, 9.81, 0.01), 0.981);        // quiet: the paper's 0.1 g
  EXPECT_DOUBLE_EQ(end_level(0.1, 0.1, 0.004), 5.0 * 0.004);  // 0.1 g of 0.1 m/s2 drowns in noise
  std::vector<double> af(100, 0.0);
  for (std::size_t i = 0; i < 30; ++i) af[i] = 0.01 * (static_cast<double>(i % 3) - 1.0) - 9.81;  // free fall
  for (std::size_t i = 30; i < 75; ++i) af[i] = 1.0 + 0.5 * static_cast<double>(i % 2);  // fluctuating collision
  EXPECT_NEAR(record_noise(af, 30), 0.01 * 1.4826, 1e-12);  // the free-fall segment's noise
  EXPECT_NEAR(record_noise(af, 2), 0.0, 1e-12);             // too little free fall: the quiet rest
}

TEST(TraceSteps, LastExceedanceEndIgnoresDipsInsideTheCollision) {
  // Deceleration 0.6 g with dips below 0.1 g (grain-scale lulls), then rest: the end is after the
  // last sample above the level, however many dips came before.
  const double level = 0.1 * kG;
  std::vector<double> a(200, 0.6 * kG);
  for (std::size_t i = 150; i < 200; ++i) a[i] = 0.0;
  for (std::size_t i : {40u, 41u, 42u, 43u, 90u, 91u, 92u}) a[i] = 0.0;
  EXPECT_EQ(last_exceedance_end(a, 10, level, 3), 150u);
  EndCriteria c;  // the forward search stops in the first dip
  c.end_level_m_s2 = level;
  EXPECT_EQ(end_sample(a, 10, c), 40u);
  a.resize(152);  // two samples of rest: the record does not hold the end
  EXPECT_FALSE(last_exceedance_end(a, 10, level, 3).has_value());
}
