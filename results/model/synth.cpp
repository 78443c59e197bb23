// Synthetic measurement campaigns (see synth.h).
#include "results/model/model_spec.h"
#include "results/model/fit.h"
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

namespace {

/// The sensor's unit: the trial's g, or the standard g for a fixed-range sensor.
constexpr double kStandardGravity_m_s2 = 9.81;
/// RK4 sub-steps per sampling period of the synthetic record.
constexpr int kSubstepsPerSample = 20;
/// The integration gives up after this much time since contact (no synthetic drop lasts as long).
constexpr double kMaxCollision_s = 10.0;

/// The truth model of one trial: its bed preparation scatters the friction-like coefficients by
/// the factor `friction` and base's drag (its second parameter) by `drag`.
FittedModel bed_scattered(const FittedModel& truth_model, const ModelSpec& truth, std::size_t levels, double friction,
                          double drag) {
  FittedModel m = truth_model;
  int col = 0;
  for (const auto& t : truth.terms) {
    const int np = static_cast<int>(t.term->params.size());
    const int per = t.per_gravity ? static_cast<int>(levels) : 1;
    for (int j = 0; j < np; ++j)
      for (int q = 0; q < per; ++q, ++col) m.coef(col) *= t.term->name == "base" && j == 1 ? drag : friction;
  }
  return m;
}

/// How much longer the drop's own times are at gravity g than at 9.81 m/s2 with D = 10 cm
/// (SynthOptions::froude_times; 1 without).
double time_factor(const SynthOptions& o, double g_m_s2) {
  if (!o.froude_times) return 1.0;
  return std::sqrt((kPaperGravity_m_s2 / kPaperProjectileDiameter_m) / (g_m_s2 / o.diameter_m));
}

/// The helpers below draw from the campaign's one generator and one normal distribution (which
/// keeps the second value of each pair it makes), so a seed gives the same campaign as ever.

/// The motion after contact: the upward acceleration at each sample and where and when the
/// integrated motion comes to rest (the truth the synthetic record is checked against).
struct SynthDrop {
  std::vector<double> a_up_m_s2;
  double zstop_m = NAN, tstop_s = NAN;
};

/// Integrates m z'' = m g - (1 + fluctuation) R(z, v) from contact (RK4, kSubstepsPerSample
/// sub-steps per sample) with R ramped in over o.contact_ramp_m and an Ornstein-Uhlenbeck force
/// fluctuation (o.force_fluct, o.force_fluct_tau_s), sampling from t_first_s after contact on.
SynthDrop integrate_drop(const FittedModel& m, TermContext c, const SynthOptions& o, double t_first_s,
                         std::mt19937_64& rng, std::normal_distribution<double>& n01) {
  const double g = c.g_m_s2, fs_hz = o.sample_rate_hz, dt = 1.0 / (fs_hz * kSubstepsPerSample);
  const double tf = time_factor(o, g);
  const double ou_a = std::exp(-dt / (o.force_fluct_tau_s * tf)), ou_b = o.force_fluct * std::sqrt(1 - ou_a * ou_a);
  auto accel_down = [&](double zz, double vv, double tt, double fl) {
    c.z_m = std::max(zz, 0.0);
    c.v_m_s = vv;
    c.t_since_contact_s = tt;
    const double ramp = o.contact_ramp_m > 0 ? std::min(1.0, c.z_m / o.contact_ramp_m) : 1.0;
    // A bed resists and never pulls: the per-trial spreads of the terms (bed_spread_*) can make
    // their sum negative at contact (immersion_drag against base's drag).
    return g - ramp * (1.0 + fl) * std::max(0.0, m.force(c)) / o.mass_kg;
  };
  SynthDrop d;
  double z = 0, v = c.vc_m_s, tc = 0, ou = 0, t_next = t_first_s;
  while (tc < kMaxCollision_s * tf) {
    while (tc + dt <= t_next + 1e-15) {  // advance to the next sample
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
        d.tstop_s = tc + f * dt;
        d.zstop_m = z + f * (zn - z);
        return d;
      }
      z = zn;
      tc += dt;
      v = vn;
    }
    d.a_up_m_s2.push_back(-accel_down(z, v, tc, ou));
    t_next += 1.0 / fs_hz;
  }
  return d;
}

/// Writes the record: free fall (-g) for `first` samples, the motion, then o.rest_tail_s at rest,
/// each sample with the sensor's bias and noise (in units of g_sensor) and clipped to its range.
void write_trace(const std::filesystem::path& path, int first, const std::vector<double>& a_up, double g,
                 double bias_m_s2, double g_sensor, const SynthOptions& o, std::mt19937_64& rng,
                 std::normal_distribution<double>& n01) {
  std::ofstream tr(path);
  tr << "t_s,accel_m_s2\n";
  const int motion = static_cast<int>(a_up.size());
  const int total =
      first + motion + static_cast<int>(std::lround(o.rest_tail_s * time_factor(o, g) * o.sample_rate_hz));
  const double chatter_m_s2 = o.contact_chatter_g * g * std::sqrt(time_factor(o, g));
  for (int i = 0; i < total; ++i) {
    double a = i < first ? -g : i < first + motion ? a_up[static_cast<std::size_t>(i - first)] : 0.0;
    a += bias_m_s2 + o.sensor_noise_g * g_sensor * n01(rng);
    if (chatter_m_s2 > 0 && i >= first) a += chatter_m_s2 * n01(rng);
    if (o.sensor_range_m_s2 > 0) a = std::clamp(a, -o.sensor_range_m_s2, o.sensor_range_m_s2);
    tr << fmt::format("{:.6f},{:.5g}\n", i / o.sample_rate_hz, a);
  }
  if (!tr) throw std::runtime_error(fmt::format("{}: cannot write", path.string()));
}

}  // namespace

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
  int id = 0;
  for (double g : o.gravity_m_s2) {
    std::vector<double> speeds = o.impact_speed_m_s;
    if (!o.froude.empty()) {
      speeds.clear();
      for (double fr : o.froude) speeds.push_back(fr * std::sqrt(g * o.diameter_m));
    }
    for (double v0 : speeds) {
      for (int rep = 0; rep < o.repeats; ++rep) {
        ++id;
        const double H = o.fill_height_m[static_cast<std::size_t>(id - 1) % o.fill_height_m.size()];
        // The draws, in this order for every trial: bed scatter, sensor bias, free-fall time,
        // the motion's force fluctuation, the sensor's noise, the reported impact speed.
        const double friction = 1.0 + o.bed_spread_f0 * n01(rng), drag = 1.0 + o.bed_spread_drag * n01(rng);
        const FittedModel m = bed_scattered(tm, truth, o.gravity_m_s2.size(), friction, drag);
        TermContext c;
        c.g_m_s2 = g;
        c.fill_height_m = H;
        c.diameter_m = o.diameter_m;
        c.mass_kg = o.mass_kg;
        c.vc_m_s = v0;
        const double g_sensor = o.noise_scales_with_g ? g : kStandardGravity_m_s2;
        const double bias = o.sensor_bias_g * g_sensor * n01(rng);
        const double t_free = (0.01 + 0.02 * std::uniform_real_distribution<double>(0, 1)(rng)) * time_factor(o, g);
        const int first = static_cast<int>(std::ceil(t_free * o.sample_rate_hz));  // first sample after contact
        const SynthDrop drop = integrate_drop(m, c, o, first / o.sample_rate_hz - t_free, rng, n01);
        const std::string name = fmt::format("{}{:03d}", o.trial_prefix, id), rel = fmt::format("traces/{}.csv", name);
        write_trace(fs::path(dir) / rel, first, drop.a_up_m_s2, g, bias, g_sensor, o, rng, n01);
        const double v_rep = v0 * (1.0 + o.speed_spread * n01(rng));
        // (Speeds by Froude number reach mm/s at low gravity: all their digits.)
        const std::string v_text = o.froude.empty() ? fmt::format("{:.4f}", v_rep) : fmt::format("{:.6g}", v_rep);
        csv << fmt::format("{},{},{},{},{},{},{},{},{},{}\n", name, rel, g, v_text, H, o.mass_kg, o.diameter_m,
                           o.grain_diameter_m, o.bulk_density_kg_m3, o.sample_rate_hz);
        truth_csv << fmt::format("{},{:.9g},{:.9g},{:.9g}\n", name, drop.zstop_m, drop.tstop_s, t_free);
      }
    }
  }
  return id;
}

}  // namespace gravsweep::results
