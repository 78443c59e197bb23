// The collision end of lab records found robustly in low gravity. Campaigns from
// `synth` (short rest tails, noise and bias scaled with g, grain-scale force fluctuations) at
// 9.81, 1.2, 0.4 and 0.1 m/s2: no trial that holds its collision may be lost, and the measured
// tstop and zstop must match synth's truth (truth.csv: the integrated motion before noise and
// filtering) within 10 % and 5 % at the 90th percentile of each gravity level, the collision
// start within a millisecond of the true contact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "results/model/model_spec.h"
#include "results/measurements/campaign.h"
#include "results/model/synth.h"
#include "results_helpers.h"

using namespace gravsweep::results;

namespace {

struct Truth {
  double zstop_m = NAN, tstop_s = NAN, t_contact_s = NAN;
};

std::map<std::string, Truth> read_truth(const std::filesystem::path& dir) {
  std::ifstream in(dir / kSynthTruthFile);
  std::map<std::string, Truth> out;
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "trial_id,zstop_m,tstop_s,t_contact_s");
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string id, z, t, tc;
    std::getline(s, id, ',');
    std::getline(s, z, ',');
    std::getline(s, t, ',');
    std::getline(s, tc, ',');
    out[id] = {std::stod(z), std::stod(t), std::stod(tc)};
  }
  return out;
}

double quantile(std::vector<double> x, double q) {
  std::sort(x.begin(), x.end());
  const double r = q * static_cast<double>(x.size() - 1);
  const std::size_t i = static_cast<std::size_t>(std::floor(r));
  const std::size_t j = std::min(x.size() - 1, i + 1);
  return x[i] + (r - static_cast<double>(i)) * (x[j] - x[i]);
}

struct LevelErrors {
  std::vector<double> tstop_rel, zstop_rel, start_ms;
};

/// Writes and imports synth campaigns of `model` over the seeds; per gravity level the relative
/// tstop and zstop errors of the kept trials; `lost` counts the trials not kept.
std::map<double, LevelErrors> errors_over_seeds(const std::string& model, SynthOptions so, int seeds, int& lost) {
  std::map<double, LevelErrors> by_g;
  lost = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    gravsweep::testing::TempDir d;
    so.seed = static_cast<unsigned>(seed);
    const int written = write_synthetic_campaign(d.str(), parse_model(model), so);
    const Campaign c = load_campaign(d.str());
    lost += written - static_cast<int>(c.trials.size());
    for (const auto& is : c.issues) ADD_FAILURE() << model << " seed " << seed << ": lost " << is.to_string();
    const auto truth = read_truth(d.path);
    for (const auto& t : c.trials) {
      const Truth& tr = truth.at(t.info.trial_id);
      const auto& m = t.processed.metrics;
      auto& e = by_g[t.info.gravity_m_s2];
      e.tstop_rel.push_back(std::abs(m.tstop_s - tr.tstop_s) / tr.tstop_s);
      e.zstop_rel.push_back(std::abs(m.zstop_m - tr.zstop_m) / tr.zstop_m);
      e.start_ms.push_back(1e3 * std::abs(m.t_start_s - tr.t_contact_s));
    }
  }
  return by_g;
}

void expect_accurate(const std::string& model, const SynthOptions& so, int seeds) {
  int lost = 0;
  const auto by_g = errors_over_seeds(model, so, seeds, lost);
  EXPECT_EQ(lost, 0) << model;
  std::cout << "model " << model << ", rest tail " << so.rest_tail_s << " s, noise " << so.sensor_noise_g << " g, "
            << seeds << " seeds; lost " << lost << "\n"
            << "  g_m_s2  trials  tstop_median_%  tstop_p90_%  zstop_median_%  zstop_p90_%  start_p90_ms\n";
  for (auto it = by_g.rbegin(); it != by_g.rend(); ++it) {
    const auto& e = it->second;
    const double t50 = 100 * quantile(e.tstop_rel, 0.5), t90 = 100 * quantile(e.tstop_rel, 0.9);
    const double z50 = 100 * quantile(e.zstop_rel, 0.5), z90 = 100 * quantile(e.zstop_rel, 0.9);
    const double s90 = quantile(e.start_ms, 0.9);
    std::cout << "  " << it->first << "  " << e.tstop_rel.size() << "  " << t50 << "  " << t90 << "  " << z50 << "  "
              << z90 << "  " << s90 << "\n";
    EXPECT_LT(t90, 10.0) << model << " at g = " << it->first;
    EXPECT_LT(z90, 5.0) << model << " at g = " << it->first;
    // The start within a millisecond of the contact (1.4 samples); a contact ramping in over 2-4 ms
    // used to start at its half height, 1-2 ms late.
    EXPECT_LT(s90, 1.0) << model << " at g = " << it->first;
  }
  EXPECT_EQ(by_g.size(), so.gravity_m_s2.size());
}

SynthOptions low_gravity_options() {
  SynthOptions so;
  so.gravity_m_s2 = {9.81, 1.2, 0.4, 0.1};
  so.repeats = 2;
  so.sensor_noise_g = 0.02;  // as the dev campaign
  so.rest_tail_s = 0.03;     // a short rest tail: ~40 samples at 1.4 kHz
  return so;
}

}  // namespace

TEST(EndAccuracy, SynthWritesTheTrueStopOfEachTrial) {
  gravsweep::testing::TempDir d;
  SynthOptions so;
  so.gravity_m_s2 = {9.81};
  so.impact_speed_m_s = {0.5};
  so.repeats = 1;
  so.rest_tail_s = 0.05;
  ASSERT_EQ(write_synthetic_campaign(d.str(), parse_model("base"), so), 1);
  const auto truth = read_truth(d.path);
  ASSERT_EQ(truth.count("S001"), 1u);
  EXPECT_GT(truth.at("S001").tstop_s, 0.005);
  EXPECT_GT(truth.at("S001").zstop_m, 0.001);
  // Contact after 10-30 ms of free fall; the record holds the rest tail after the stop.
  const Truth& tr = truth.at("S001");
  EXPECT_GE(tr.t_contact_s, 0.01);
  EXPECT_LE(tr.t_contact_s, 0.03);
  std::ifstream trace(d.path / "traces/S001.csv");
  std::string line, last;
  while (std::getline(trace, line)) last = line;
  const double t_end = std::stod(last.substr(0, last.find(',')));
  EXPECT_NEAR(t_end, tr.t_contact_s + tr.tstop_s + 0.05, 2.0 / so.sample_rate_hz);
}

TEST(EndAccuracy, NoTrialLostAndStopsWithinTolerancesDownToATenthOfAG) {
  EXPECT_NO_FATAL_FAILURE(expect_accurate("base", low_gravity_options(), 3));
}

TEST(EndAccuracy, TheSameWithAHiddenDepthFriction) {
  EXPECT_NO_FATAL_FAILURE(expect_accurate("base+depth_friction", low_gravity_options(), 2));
}
