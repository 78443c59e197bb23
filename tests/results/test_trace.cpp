// Trace processing (results/processing/trace.h) on analytic Poncelet traces: Sunday et al. 2021
// Eqs. 2-4 / docs/physics/force-laws.md section 2.3 A give apeak, zstop and tstop exactly; the
// paper's processing (500 Hz Butterworth, free-fall start, 0.1 g end, integration from vc) must
// recover them.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "poncelet.h"
#include "results/processing/trace.h"

using namespace gravsweep::results;
using gravsweep::testing::Poncelet;

namespace {

Trace sample(const Poncelet& p, double fs, double t_contact, double noise_g, double bias_g, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  Trace tr;
  const double T = t_contact + p.tstop() + 0.08;
  for (int i = 0; i * (1.0 / fs) < T; ++i) {
    const double t = i / fs;
    tr.t_s.push_back(t);
    tr.accel_up_m_s2.push_back(p.accel_up(t - t_contact) + bias_g * p.g + noise_g * p.g * n01(rng));
  }
  return tr;
}

void expect_recovered(const Poncelet& p, double fs, double noise_g, double bias_g, unsigned seed) {
  const double t_contact = 0.0213457;  // deliberately between samples
  const Trace tr = sample(p, fs, t_contact, noise_g, bias_g, seed);
  MetricOptions o;
  o.gravity_m_s2 = p.g;
  o.impact_speed_m_s = p.v0;
  const Metrics m = compute_metrics(tr, o);
  SCOPED_TRACE(::testing::Message() << "fs=" << fs << " g=" << p.g << " v0=" << p.v0 << " noise=" << noise_g
                                    << " seed=" << seed);
  EXPECT_NEAR(m.zstop_m, p.zstop(), 0.02 * p.zstop());
  EXPECT_NEAR(m.tstop_s, p.tstop(), 0.02 * p.tstop());
  EXPECT_NEAR(m.apeak_m_s2, p.apeak(), 0.02 * p.apeak());
  EXPECT_DOUBLE_EQ(m.vc_m_s, p.v0);
  EXPECT_NEAR(m.t_start_s, t_contact, 2.0 / fs);
  EXPECT_FALSE(m.rebound);
}

}  // namespace

TEST(Butterworth, PassesDcAndRemovesNyquistAndHasUnitGainAtLowFrequency) {
  const double fs = 1400, fc = 500;
  std::vector<double> dc(200, 3.5), nyq(200), slow(400);
  for (int i = 0; i < 200; ++i) nyq[i] = (i % 2 ? 1.0 : -1.0);
  for (int i = 0; i < 400; ++i) slow[i] = std::sin(2 * std::numbers::pi * 20.0 * i / fs);
  for (double y : butterworth_lowpass(dc, fs, fc)) EXPECT_NEAR(y, 3.5, 1e-9);
  const auto yn = butterworth_lowpass(nyq, fs, fc);
  for (int i = 30; i < 170; ++i) EXPECT_LT(std::abs(yn[i]), 1e-4);
  const auto ys = butterworth_lowpass(slow, fs, fc);
  for (int i = 0; i < 400; ++i) EXPECT_NEAR(ys[i], slow[i], 2e-3);
}

TEST(Butterworth, HalfPowerAtCutoffPerPassSoQuarterPowerZeroPhase) {
  // Forward-backward squares |H|: at the cut-off each pass gives 1/sqrt(2), together 1/2.
  const double fs = 10000, fc = 500;
  std::vector<double> x(4000);
  for (int i = 0; i < 4000; ++i) x[i] = std::sin(2 * std::numbers::pi * fc * i / fs);
  const auto y = butterworth_lowpass(x, fs, fc, 2);
  double px = 0, py = 0;
  for (int i = 500; i < 3500; ++i) px += x[i] * x[i], py += y[i] * y[i];
  EXPECT_NEAR(std::sqrt(py / px), 0.5, 0.01);
  // Zero phase: the filtered sine peaks where the input does.
  for (int i = 1000; i < 1020; ++i)
    if (x[i] > x[i - 1] && x[i] > x[i + 1]) {
      EXPECT_GT(y[i], y[i - 1]);
      EXPECT_GT(y[i], y[i + 1]);
    }
}

TEST(Butterworth, RejectsCutoffAboveNyquist) {
  std::vector<double> x(10, 1.0);
  EXPECT_THROW(butterworth_lowpass(x, 800, 500), std::invalid_argument);
}

TEST(Metrics, PonceletAt1400HzAnd10kHzWithNoiseWithin2Percent) {
  for (double fs : {1400.0, 10000.0})
    for (double g : {9.81, 1.2})
      for (double v0 : {0.3, 0.6, 1.0})
        for (unsigned seed : {1u, 2u}) {
          // At 1.4 kHz the edges are located to about a third of a sample (0.25 ms), so a 2 %
          // duration needs a collision longer than ~25 samples: the 1 g, 0.3 m/s case (19 ms,
          // 27 samples) is at the limit and is checked at 10 kHz only.
          if (fs < 2000 && g > 5 && v0 < 0.5) continue;
          Poncelet p;
          p.g = g;
          p.f0 = 2.5 * p.m * g;  // friction above weight, as in Table 3's 1 g row
          p.v0 = v0;
          EXPECT_NO_FATAL_FAILURE(expect_recovered(p, fs, 0.01, 0.02, seed)) << fs << " Hz";
        }
}

TEST(Metrics, PaperTable3ExperimentRowAt1g) {
  Poncelet p;                           // f0 = 25 N, 1/d1 = 25 1/m, m = 1 kg (Table 3, Exp. 10 mm)
  for (double v0 : {0.7, 0.85, 1.0}) {  // 0.4-0.6 m/s (24-34 ms) give apeak within 3 %
    p.v0 = v0;
    EXPECT_NO_FATAL_FAILURE(expect_recovered(p, 1400, 0.015, -0.01, 7)) << "v0 " << v0;
  }
}

TEST(Metrics, UsesTraceVelocityAndDepthWhenPresent) {
  Poncelet p;
  Trace tr = sample(p, 10000, 0.01, 0.0, 0.0, 1);
  tr.source = TraceSource::dem;
  for (double t : tr.t_s) {
    const double tc = std::clamp(t - 0.01, -1.0, p.tstop());
    double v, z;
    p.state(tc, v, z);
    tr.velocity_down_m_s.push_back(v);
    tr.depth_m.push_back(z);
  }
  MetricOptions o;
  const Metrics m = compute_metrics(tr, o);
  EXPECT_NEAR(m.vc_m_s, p.v0, 0.01);
  EXPECT_NEAR(m.zstop_m, p.zstop(), 0.01 * p.zstop());
}

TEST(Metrics, RejectsBadTracesWithReasons) {
  Poncelet p;
  MetricOptions o;
  o.impact_speed_m_s = p.v0;
  Trace short_tr;
  short_tr.t_s = {0, 1, 2};
  short_tr.accel_up_m_s2 = {0, 0, 0};
  EXPECT_THROW(compute_metrics(short_tr, o), std::invalid_argument);

  Trace tr = sample(p, 1400, 0.02, 0.0, 0.0, 1);
  Trace back = tr;
  back.t_s[10] = back.t_s[9];
  try {
    compute_metrics(back, o);
    FAIL() << "non-increasing time accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sample 10"), std::string::npos) << e.what();
  }
  Trace freefall = tr;
  for (double& a : freefall.accel_up_m_s2) a = -p.g;
  EXPECT_THROW(compute_metrics(freefall, o), std::invalid_argument);
  // Cut in the middle of the collision: the end is never reached.
  Trace cut = tr;
  const std::size_t keep = static_cast<std::size_t>((0.02 + 0.5 * p.tstop()) * 1400);
  cut.t_s.resize(keep);
  cut.accel_up_m_s2.resize(keep);
  EXPECT_THROW(compute_metrics(cut, o), std::invalid_argument);
  // No velocity anywhere.
  MetricOptions nov;
  EXPECT_THROW(compute_metrics(tr, nov), std::invalid_argument);
}

TEST(Metrics, ReachingTheFloorIsNotedNotFlaggedWithoutARise) {
  Poncelet p;
  MetricOptions o;
  o.impact_speed_m_s = p.v0;
  o.fill_height_m = p.zstop() + 0.005;
  o.grain_diameter_m = 0.01;
  const Metrics near_floor = compute_metrics(sample(p, 1400, 0.02, 0.0, 0.0, 1), o);
  EXPECT_FALSE(near_floor.rebound) << near_floor.note;
  EXPECT_NE(near_floor.note.find("within one grain of the floor"), std::string::npos) << near_floor.note;
  o.fill_height_m = 0.2;
  const Metrics deep = compute_metrics(sample(p, 1400, 0.02, 0.0, 0.0, 1), o);
  EXPECT_FALSE(deep.rebound);
  EXPECT_EQ(deep.note.find("floor"), std::string::npos) << deep.note;
}

/// A DEM record (10 kHz, own v and z) that stops at depth v0^2 / (2 A) under a constant kinematic
/// deceleration A, is pushed back up by the floor (up at A for rise_s, then braked at A), and
/// rests: it rises A rise_s^2 back from its deepest point.
Trace bouncing_dem_trace(double v0, double A, double rise_s) {
  const double g = 9.81, dt = 1e-4, t_contact = 0.01;
  Trace tr;
  tr.source = TraceSource::dem;
  double v = v0 - g * t_contact, z = -(v0 * t_contact - 0.5 * g * t_contact * t_contact), t_stop = -1;
  for (int i = 0; i * dt < 0.2; ++i) {
    const double t = i * dt;
    double a = -g;  // free fall, then the collision's phases
    if (t >= t_contact) {
      if (t_stop < 0 && v <= 0) t_stop = t;
      if (t_stop < 0 || t < t_stop + rise_s)
        a = A;
      else if (t < t_stop + 2 * rise_s)
        a = -A;
      else
        a = 0, v = 0;
    }
    tr.t_s.push_back(t);
    tr.accel_up_m_s2.push_back(a);
    tr.velocity_down_m_s.push_back(v);
    tr.depth_m.push_back(z);
    v -= a * dt;
    z += v * dt;
  }
  return tr;
}

TEST(Metrics, ZstopIsTheMaximumDepthAndARiseIsARebound) {
  // The paper's zstop (Sect. 2.3) is the maximum penetration depth: a drop that bounces off the
  // floor and comes to rest 6 mm higher keeps the depth it reached (the depth at the collision's
  // end, the old zstop, was 5.4 mm of 8.3 here), and a rise of more than 10 % of it flags a rebound.
  const double v0 = 1.0, A = 60.0;
  const Metrics m = compute_metrics(bouncing_dem_trace(v0, A, 0.01), MetricOptions{});
  const double zmax = v0 * v0 / (2 * A);
  EXPECT_NEAR(m.zstop_m, zmax, 0.03 * zmax) << m.note;
  EXPECT_LT(m.depth_at_end_m, 0.9 * zmax) << m.note;  // the old zstop under-reported it
  EXPECT_NEAR(m.final_depth_m, zmax - A * 0.01 * 0.01, 0.1 * zmax);
  EXPECT_TRUE(m.rebound) << m.note;
  EXPECT_NE(m.note.find("back up from its deepest point"), std::string::npos) << m.note;
  // A rise of under 10 % (elastic recovery of the bed) is no rebound; zstop is still the deepest.
  const Metrics small = compute_metrics(bouncing_dem_trace(v0, A, 0.002), MetricOptions{});
  EXPECT_FALSE(small.rebound) << small.note;
  EXPECT_NEAR(small.zstop_m, zmax, 0.03 * zmax);
}

TEST(Metrics, SimulatedTracesGetNoBiasAndShortDipsDoNotEndTheCollision) {
  // A DEM-like trace at 10 kHz (own velocity and depth): a 1 ms dip below 0.1 g in the middle of
  // the collision must not end it, and settling bursts after the stop must not be taken for a
  // sensor bias (simulations have none).
  Poncelet p;
  Trace tr = sample(p, 10000, 0.01, 0.0, 0.0, 1);
  tr.source = TraceSource::dem;
  for (std::size_t i = 0; i < tr.t_s.size(); ++i) {
    const double t = tr.t_s[i];
    const double tc = std::clamp(t - 0.01, -1.0, p.tstop());
    double v, z;
    p.state(tc, v, z);
    tr.velocity_down_m_s.push_back(v);
    tr.depth_m.push_back(z);
    const double after = t - 0.01 - p.tstop();
    if (t - 0.01 > 0.5 * p.tstop() && t - 0.01 < 0.5 * p.tstop() + 0.001) tr.accel_up_m_s2[i] = 0.0;
    if (after > 0.005 && after < 0.015) tr.accel_up_m_s2[i] = 0.5 * p.g * std::sin(6.28 * after / 0.01);
  }
  const ProcessedTrace out = process_trace(tr, MetricOptions{});
  EXPECT_EQ(out.bias_m_s2, 0.0);
  EXPECT_NEAR(out.metrics.tstop_s, p.tstop(), 0.02 * p.tstop());
  EXPECT_NEAR(out.metrics.zstop_m, p.zstop(), 0.02 * p.zstop());
}

// A DEM projectile is stopped by bursts of force chains with lulls between them in which it coasts
// (acceleration ~0, speed still half of vc). The collision must end at the final stop, not at the
// first lull, which the paper's 0.1 g threshold alone would pick (bug seen in the demo campaign:
// zstop 0.1 cm of a 3 cm penetration). Both a DEM trace (v and z given) and a lab-style record
// (v and z integrated from the impact speed).
TEST(Metrics, ALullBetweenBurstsDoesNotEndTheCollision) {
  const double g = 9.81, fs = 10000, dt = 1.0 / fs, v0 = 0.75, burst = 40.0;
  const double t_contact = 0.02, t_lull = t_contact + 0.005, t_resume = t_lull + 0.015;
  Trace tr;
  tr.source = TraceSource::dem;
  double v = v0 - g * t_contact, z = -(v0 * t_contact - 0.5 * g * t_contact * t_contact);
  double t_rest = -1, z_rest = 0;
  for (int i = 0; i * dt < 0.2; ++i) {
    const double t = i * dt;
    double a_up = -g;  // free fall
    if (t >= t_contact) a_up = (t < t_lull || t >= t_resume) ? burst : 0.0;
    if (t_rest >= 0 || (t >= t_resume && v <= 0)) {
      a_up = 0, v = 0;
      if (t_rest < 0) t_rest = t, z_rest = z;
    }
    tr.t_s.push_back(t);
    tr.accel_up_m_s2.push_back(a_up);
    tr.velocity_down_m_s.push_back(v);
    tr.depth_m.push_back(z);
    z += v * dt - 0.5 * a_up * dt * dt;
    v = std::max(0.0, v - a_up * dt);
  }
  ASSERT_GT(t_rest, t_resume);
  MetricOptions o;
  o.gravity_m_s2 = g;
  const Metrics dem = compute_metrics(tr, o);
  EXPECT_NEAR(dem.zstop_m, z_rest, 0.02 * z_rest);
  EXPECT_NEAR(dem.tstop_s, t_rest - t_contact, 0.02 * (t_rest - t_contact));
  // With the paper's threshold alone (no speed condition) the collision would end in the lull.
  MetricOptions threshold_only = o;
  threshold_only.end_speed_fraction = 1e9;
  const Metrics early = compute_metrics(tr, threshold_only);
  EXPECT_LT(early.tstop_s, 0.5 * (t_rest - t_contact));
  EXPECT_LT(early.depth_at_end_m, 0.5 * z_rest);
  EXPECT_NEAR(early.zstop_m, z_rest, 0.02 * z_rest);  // the deepest point does not depend on the end
  // The same record as an accelerometer gives it: no v, no z; the impact speed is known.
  Trace lab;
  lab.t_s = tr.t_s;
  lab.accel_up_m_s2 = tr.accel_up_m_s2;
  o.impact_speed_m_s = v0;
  const Metrics m = compute_metrics(lab, o);
  EXPECT_NEAR(m.tstop_s, t_rest - t_contact, 0.03 * (t_rest - t_contact));
  EXPECT_NEAR(m.zstop_m, z_rest, 0.03 * z_rest);
}

namespace {

/// A DEM-like record of the Poncelet law (Trace with its own v and z) whose free fall before
/// contact lasts only t_contact seconds.
Trace dem_record(const Poncelet& p, double fs, double t_contact) {
  Trace tr;
  tr.source = TraceSource::dem;
  const double T = t_contact + p.tstop() + 0.08;
  for (int i = 0; i * (1.0 / fs) < T; ++i) {
    const double t = i / fs, tc = std::min(t - t_contact, p.tstop());
    double v, z;
    p.state(tc, v, z);
    tr.t_s.push_back(t);
    tr.accel_up_m_s2.push_back(p.accel_up(t - t_contact));
    tr.velocity_down_m_s.push_back(t - t_contact >= p.tstop() ? 0.0 : v);
    tr.depth_m.push_back(z);
  }
  return tr;
}

}  // namespace

// A DEM drop released 1 mm above the bed falls for 1-6 ms; the 500 Hz filter's edge
// leaves no -g sample before the peak, so the paper's free-fall rule finds no start. The engine's
// first contact gives it.
TEST(Metrics, ADemRecordWithAShortFreeFallStartsAtTheEnginesFirstContact) {
  Poncelet p;
  p.v0 = 0.2;
  const double fs = 10000, t_contact = 0.0015;
  Trace tr = dem_record(p, fs, t_contact);
  MetricOptions o;
  o.gravity_m_s2 = p.g;
  tr.contact_start_s = std::floor(t_contact * fs) / fs;  // last sample before contact
  const Metrics m = compute_metrics(tr, o);
  EXPECT_NEAR(m.t_start_s, t_contact, 1.0 / fs);
  EXPECT_NEAR(m.vc_m_s, p.v0, p.g / fs);
  EXPECT_NEAR(m.zstop_m, p.zstop(), 0.02 * p.zstop());
  EXPECT_NEAR(m.tstop_s, p.tstop(), 0.03 * p.tstop());
  EXPECT_FALSE(m.rebound);
}

// With a long free fall the first-contact start and the paper's rule agree on the metrics.
TEST(Metrics, FirstContactStartAgreesWithThePapersRuleAfterALongFreeFall) {
  Poncelet p;
  const double fs = 10000, t_contact = 0.03;
  Trace tr = dem_record(p, fs, t_contact);
  MetricOptions o;
  o.gravity_m_s2 = p.g;
  const Metrics paper = compute_metrics(tr, o);
  tr.contact_start_s = std::floor(t_contact * fs) / fs;
  const Metrics dem = compute_metrics(tr, o);
  EXPECT_NEAR(dem.zstop_m, paper.zstop_m, 0.01 * paper.zstop_m);
  EXPECT_NEAR(dem.tstop_s, paper.tstop_s, 0.03 * paper.tstop_s);
  EXPECT_NEAR(dem.apeak_m_s2, paper.apeak_m_s2, 0.03 * paper.apeak_m_s2);
  EXPECT_NEAR(dem.zstop_m, p.zstop(), 0.02 * p.zstop());
}

namespace {

/// The TraceError of processing `tr` (fails the test when it is measured or throws another type).
TraceError error_of(const Trace& tr, const MetricOptions& o) {
  try {
    compute_metrics(tr, o);
  } catch (const TraceError& e) {
    return e;
  }
  ADD_FAILURE() << "measured";
  return TraceError("measured");
}

}  // namespace

// No free fall, no contact, a 1e308 sample and a record that ends inside the collision: each has
// its own reason and sample, not one "trace shorter than the collision" for all.
TEST(Metrics, EachUnmeasurableRecordGetsItsOwnReasonAndSample) {
  Poncelet p;
  MetricOptions o;
  o.impact_speed_m_s = p.v0;
  const Trace tr = sample(p, 1400, 0.02, 0.01, 0.0, 1);
  const std::size_t contact = static_cast<std::size_t>(0.02 * 1400);

  Trace huge = tr;
  huge.accel_up_m_s2[40] = 1e308;
  TraceError e = error_of(huge, o);
  EXPECT_NE(std::string(e.what()).find("beyond any accelerometer's range"), std::string::npos) << e.what();
  EXPECT_EQ(e.sample(), 40u);
  EXPECT_TRUE(e.bad_value());

  Trace at_rest = tr;  // the record starts at rest instead of in free fall
  for (std::size_t i = 0; i < contact; ++i) at_rest.accel_up_m_s2[i] = 0.0;
  e = error_of(at_rest, o);
  EXPECT_NE(std::string(e.what()).find("does not start in free fall"), std::string::npos) << e.what();
  EXPECT_EQ(e.sample(), 0u);

  Trace bump = tr;  // free fall with a bump that never reaches -g/2
  for (double& a : bump.accel_up_m_s2) a = -p.g;
  bump.accel_up_m_s2[50] = -6.0;
  e = error_of(bump, o);
  EXPECT_NE(std::string(e.what()).find("never makes contact"), std::string::npos) << e.what();
  EXPECT_EQ(e.sample(), 50u);

  Trace cut = tr;  // ends inside the collision
  const std::size_t keep = contact + static_cast<std::size_t>(0.5 * p.tstop() * 1400);
  cut.t_s.resize(keep);
  cut.accel_up_m_s2.resize(keep);
  e = error_of(cut, o);
  EXPECT_NE(std::string(e.what()).find("shorter than the collision"), std::string::npos) << e.what();
  EXPECT_EQ(e.sample(), keep - 1);

  // A sensor bias of a few per cent of g is not mistaken for a missing free fall.
  EXPECT_NO_THROW(compute_metrics(sample(p, 1400, 0.02, 0.01, 0.05, 1), o));
}
