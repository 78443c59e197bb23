// Synthetic measurement campaigns (see synth.h).
#include "results/model/synth.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>

namespace gravsweep::results {

FittedModel truth_model(const ModelSpec& spec, const std::vector<double>& levels, double mass, double diameter) {
  FittedModel m;
  m.spec = spec;
  m.gravity_levels = levels;
  const int G = static_cast<int>(levels.size());
  std::vector<double> coef;
  for (const auto& t : spec.terms) {
    const int np = static_cast<int>(t.term->params.size());
    if (t.per_gravity) {
      for (int j = 0; j < np; ++j)
        for (int gi = 0; gi < G; ++gi) coef.push_back(t.scale * t.term->typical(levels[gi], mass, diameter)[j]);
    } else {
      const auto v = t.term->typical(levels.front(), mass, diameter);
      for (int j = 0; j < np; ++j) coef.push_back(t.scale * v[j]);
    }
  }
  m.coef = Eigen::Map<Eigen::VectorXd>(coef.data(), static_cast<Eigen::Index>(coef.size()));
  m.cov = Eigen::MatrixXd::Zero(m.coef.size(), m.coef.size());
  return m;
}

int write_synthetic_campaign(const std::string& dir, const ModelSpec& truth, const SynthOptions& o) {
  namespace fs = std::filesystem;
  fs::create_directories(fs::path(dir) / "traces");
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const FittedModel tm = truth_model(truth, o.gravity_m_s2, o.mass_kg, o.diameter_m);
  std::ofstream csv(fs::path(dir) / "trials.csv");
  if (!csv) throw std::runtime_error(fmt::format("{}: cannot write trials.csv", dir));
  // The required columns of the trial record, in the order of its field table (trial.h).
  std::string header;
  for (const auto& f : trial_fields())
    if (f.csv_required) header += (header.empty() ? "" : ",") + std::string(f.key);
  csv << header << "\n";
  std::ofstream truth_csv(fs::path(dir) / kSynthTruthFile);
  if (!truth_csv) throw std::runtime_error(fmt::format("{}: cannot write {}", dir, kSynthTruthFile));
  truth_csv << "trial_id,zstop_m,tstop_s,t_contact_s\n";
  // The sensor's unit: the trial's g, or the standard g for a fixed-range sensor.
  constexpr double kStandardGravity_m_s2 = 9.81;
  int id = 0;
  for (std::size_t gi = 0; gi < o.gravity_m_s2.size(); ++gi) {
    const double g = o.gravity_m_s2[gi];
    for (double v0 : o.impact_velocity_m_s) {
      for (int rep = 0; rep < o.repeats; ++rep) {
        ++id;
        const double H = o.fill_height_m[static_cast<std::size_t>(id - 1) % o.fill_height_m.size()];
        // Per-trial bed preparation: friction-like and drag-like coefficients scatter.
        FittedModel m = tm;
        const double sf = 1.0 + o.bed_spread_f0 * n01(rng);
        const double sd = 1.0 + o.bed_spread_drag * n01(rng);
        {
          int col = 0;
          for (const auto& t : truth.terms) {
            const int np = static_cast<int>(t.term->params.size());
            const int per = t.per_gravity ? static_cast<int>(o.gravity_m_s2.size()) : 1;
            for (int j = 0; j < np; ++j)
              for (int q = 0; q < per; ++q, ++col) {
                const bool drag = t.term->name == "base" && j == 1;
                m.coef(col) *= drag ? sd : sf;
              }
          }
        }
        TermContext c;
        c.g_m_s2 = g;
        c.fill_height_m = H;
        c.diameter_m = o.diameter_m;
        c.mass_kg = o.mass_kg;
        c.vc_m_s = v0;
        const double g_sensor = o.noise_scales_with_g ? g : kStandardGravity_m_s2;
        const double bias = o.sensor_bias_g * g_sensor * n01(rng);
        const double t_free = 0.01 + 0.02 * std::uniform_real_distribution<double>(0, 1)(rng);
        // Integrate with RK4 (sub-steps of the sampling period) until the stop.
        const double fs_hz = o.sample_rate_hz;
        const int sub = 20;
        const double dt = 1.0 / (fs_hz * sub);
        double z = 0, v = v0, tc = 0, ou = 0;
        const double ou_a = std::exp(-dt / o.force_fluct_tau_s);
        const double ou_b = o.force_fluct * std::sqrt(1 - ou_a * ou_a);
        auto accel_down = [&](double zz, double vv, double tt, double fl) {
          c.z_m = std::max(zz, 0.0);
          c.v_m_s = vv;
          c.t_since_contact_s = tt;
          const double ramp = o.contact_ramp_m > 0 ? std::min(1.0, c.z_m / o.contact_ramp_m) : 1.0;
          // A bed resists and never pulls: the per-trial spreads of the terms (bed_spread_*)
          // can make their sum negative at contact (immersion_drag against base's drag).
          return g - ramp * (1.0 + fl) * std::max(0.0, m.force(c)) / o.mass_kg;
        };
        std::vector<double> a_samples;  // upward acceleration at each sample after contact
        const int first = static_cast<int>(std::ceil(t_free * fs_hz));
        const double t_first = first / fs_hz - t_free;  // first sample time after contact
        bool stopped = false;
        double zstop = NAN, tstop = NAN;  // the truth: where the integrated motion comes to rest
        double t_next = t_first;
        while (!stopped && tc < 10.0) {
          // advance to the next sample
          while (tc + dt <= t_next + 1e-15) {
            const double k1v = accel_down(z, v, tc, ou), k1z = v;
            const double k2v = accel_down(z + 0.5 * dt * k1z, v + 0.5 * dt * k1v, tc + 0.5 * dt, ou),
                         k2z = v + 0.5 * dt * k1v;
            const double k3v = accel_down(z + 0.5 * dt * k2z, v + 0.5 * dt * k2v, tc + 0.5 * dt, ou),
                         k3z = v + 0.5 * dt * k2v;
            const double k4v = accel_down(z + dt * k3z, v + dt * k3v, tc + dt, ou), k4z = v + dt * k3v;
            const double vn = v + dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
            const double zn = z + dt / 6 * (k1z + 2 * k2z + 2 * k3z + k4z);
            ou = ou_a * ou + ou_b * n01(rng);
            if (vn <= 0 && tc + dt > 1e-4) {
              const double f = v > vn ? v / (v - vn) : 1.0;  // linear in the step: v = 0 at tc + f dt
              tstop = tc + f * dt;
              zstop = z + f * (zn - z);
              z = zn;
              tc += dt;
              v = 0;
              stopped = true;
              break;
            }
            z = zn;
            tc += dt;
            v = vn;
          }
          if (stopped) break;
          const double dt_rem = t_next - tc;
          (void)dt_rem;
          a_samples.push_back(-accel_down(z, v, tc, ou));
          t_next += 1.0 / fs_hz;
        }
        const std::string name = fmt::format("S{:03d}", id);
        const std::string rel = "traces/" + name + ".csv";
        std::ofstream tr(fs::path(dir) / rel);
        tr << "t_s,accel_m_s2\n";
        const int n_after = static_cast<int>(std::lround(o.rest_tail_s * fs_hz));
        const int total = first + static_cast<int>(a_samples.size()) + n_after;
        for (int i = 0; i < total; ++i) {
          double a;
          if (i < first)
            a = -g;
          else if (i < first + static_cast<int>(a_samples.size()))
            a = a_samples[static_cast<std::size_t>(i - first)];
          else
            a = 0.0;
          a += bias + o.sensor_noise_g * g_sensor * n01(rng);
          if (o.sensor_range_m_s2 > 0) a = std::clamp(a, -o.sensor_range_m_s2, o.sensor_range_m_s2);
          tr << fmt::format("{:.6f},{:.5g}\n", i / fs_hz, a);
        }
        const double v_rep = v0 * (1.0 + o.speed_spread * n01(rng));
        csv << fmt::format("{},{},{},{:.4f},{},{},{},{},{},{}\n", name, rel, g, v_rep, H, o.mass_kg, o.diameter_m,
                           o.grain_diameter_m, o.bulk_density_kg_m3, fs_hz);
        truth_csv << fmt::format("{},{:.9g},{:.9g},{:.9g}\n", name, zstop, tstop, t_free);
      }
    }
  }
  return id;
}

}  // namespace gravsweep::results
