// Held-out comparisons and report data (see report.h).
#include "results/model/model_spec.h"
#include "results/model/fit.h"
#include "results/model/predict.h"
#include "results/model/cross_validation.h"
#include "results/model/table3.h"
#include "results/model/discover.h"
#include "results/report/report.h"

#include <fmt/format.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>
#include <unistd.h>
#include <stdexcept>

#include "results/report/plots_py.h"
#include "results/io/table.h"

namespace gravsweep::results {

std::vector<ComparedModel> compare_models(const Campaign& c, const std::vector<ModelSpec>& specs, int folds) {
  std::vector<ComparedModel> out;
  ComparedModel paper;
  paper.name = "paper_eq2-4";
  paper.held_out = cross_validate_paper(c, folds, 1);
  paper.errors = summarize(c, paper.held_out);
  out.push_back(std::move(paper));
  for (const auto& s : specs) {
    ComparedModel m;
    m.name = s.name();
    m.held_out = cross_validate(s, c, folds, 1, true);
    m.errors = summarize(c, m.held_out);
    out.push_back(std::move(m));
  }
  return out;
}

namespace {

/// Each value as fmt writes it (`{}`: shortest exact form, nan for NaN).
template <class... V>
std::vector<std::string> cells(const V&... v) {
  return {fmt::format("{}", v)...};
}

/// A CSV file of the report (the one table writer: RFC 4180).
void write_csv(const std::filesystem::path& p, const Table& t) {
  std::ofstream f(p, std::ios::binary);
  if (!(f << t.csv())) throw std::runtime_error(fmt::format("{}: cannot write", p.string()));
}

std::ofstream open_out(const std::filesystem::path& p) {
  std::ofstream f(p);
  if (!f) throw std::runtime_error(fmt::format("{}: cannot write", p.string()));
  return f;
}

/// model_curves.csv: each model's metrics against vc per gravity level (models fitted on all trials).
void write_model_curves(const std::filesystem::path& D, const Campaign& c, const std::vector<Table3Row>& t3,
                        const std::vector<FittedModel>& fits) {
  Table f({"model", "gravity_m_s2", "vc_m_s", "apeak_m_s2", "zstop_m", "tstop_s"});
  for (const auto& r : t3) {
    double vmax = 0, mass = 0, H = 0, Dm = 0;
    int n = 0;
    for (const auto& t : c.trials)
      if (same_gravity_level(t.info.gravity_m_s2, r.g_m_s2)) {
        vmax = std::max(vmax, t.processed.metrics.vc_m_s);
        mass += t.info.projectile_mass_kg, H += t.info.fill_height_m, Dm += t.info.projectile_diameter_m;
        ++n;
      }
    if (!n) continue;
    mass /= n, H /= n, Dm /= n;
    for (int k = 1; k <= 40; ++k) {
      const double vc = 1.1 * vmax * k / 40.0;
      const Prediction pp = predict_paper(r, mass, vc);
      f.add(cells("paper_eq2-4", r.g_m_s2, vc, pp.apeak_m_s2, pp.zstop_m, pp.tstop_s));
      for (const auto& fm : fits) {
        TermContext tc;
        tc.g_m_s2 = r.g_m_s2, tc.mass_kg = mass, tc.fill_height_m = H, tc.diameter_m = Dm;
        tc.vc_m_s = tc.v_m_s = vc;
        const Prediction p = predict(fm, tc);
        f.add(cells(fm.spec.name(), r.g_m_s2, vc, p.apeak_m_s2, p.stopped ? p.zstop_m : NAN,
                    p.stopped ? p.tstop_s : NAN));
      }
    }
  }
  write_csv(D / "model_curves.csv", f);
}

/// residuals.csv: a_meas - a_model of each model along the fit windows (at most about 20000 samples).
void write_residuals(const std::filesystem::path& D, const Campaign& c, const std::vector<FittedModel>& fits) {
  std::vector<std::string> cols{"trial_id",  "gravity_m_s2",        "vc_m_s", "fill_height_m", "depth_m",
                                "speed_m_s", "time_since_contact_s"};
  for (const auto& fm : fits) cols.push_back("r_" + fm.spec.name() + "_m_s2");
  Table f(cols);
  std::size_t total = 0;
  for (const auto& t : c.trials) total += t.fit_end - t.fit_begin;
  const std::size_t stride = std::max<std::size_t>(1, total / 20000);
  for (const auto& t : c.trials)
    for (std::size_t k = t.fit_begin; k < t.fit_end; k += stride) {
      TermContext tc;
      tc.z_m = t.processed.depth_m[k];
      tc.v_m_s = t.processed.velocity_down_m_s[k];
      tc.g_m_s2 = t.info.gravity_m_s2;
      tc.t_since_contact_s = t.processed.t_s[k] - t.processed.metrics.t_start_s;
      tc.fill_height_m = t.info.fill_height_m;
      tc.diameter_m = t.info.projectile_diameter_m;
      tc.mass_kg = t.info.projectile_mass_kg;
      tc.vc_m_s = t.processed.metrics.vc_m_s;
      auto row = cells(t.info.trial_id, tc.g_m_s2, tc.vc_m_s, tc.fill_height_m, tc.z_m, tc.v_m_s, tc.t_since_contact_s);
      for (const auto& fm : fits)  // 6 significant digits, as the stream wrote them
        row.push_back(fmt::format("{:.6g}", t.processed.accel_up_m_s2[k] - (fm.force(tc) / tc.mass_kg - tc.g_m_s2)));
      f.add(std::move(row));
    }
  write_csv(D / "residuals.csv", f);
}

}  // namespace

void write_report_data(const std::string& dir, const Campaign& c, const std::vector<ComparedModel>& compared,
                       const std::vector<ModelSpec>& specs, const Discovery* d) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  const fs::path D(dir);
  {
    Table f({"trial_id", "gravity_m_s2", "vc_m_s", "fill_height_m", "drop_height_m", "apeak_m_s2", "zstop_m", "tstop_s",
             "rebound", "clipped_at_m_s2"});
    const std::vector<double> levels = c.gravity_levels();
    for (const auto& t : c.trials) {
      const auto& m = t.processed.metrics;
      // The level's value (same_gravity_level), so the plots group as the fits do.
      double level = t.info.gravity_m_s2;
      for (double g : levels)
        if (same_gravity_level(g, level)) level = g;
      const double drop =
          t.info.drop_height_m > 0 ? t.info.drop_height_m : m.vc_m_s * m.vc_m_s / (2 * t.info.gravity_m_s2);
      // clipped_at_m_s2: 0, or the level of a saturated accelerometer (apeak a lower bound).
      f.add(cells(t.info.trial_id, level, m.vc_m_s, t.info.fill_height_m, drop, m.apeak_m_s2, m.zstop_m, m.tstop_s,
                  m.rebound ? 1 : 0, t.info.clipped_at_m_s2));
    }
    write_csv(D / "trials.csv", f);
  }
  {
    Table f({"trial_id", "model", "apeak_m_s2", "zstop_m", "tstop_s", "trace_mse_m2_s4"});
    for (const auto& cm : compared)
      for (std::size_t i = 0; i < c.trials.size(); ++i) {
        const auto& p = cm.held_out.pred[i];
        f.add(cells(c.trials[i].info.trial_id, cm.name, p.apeak_m_s2, p.stopped ? p.zstop_m : NAN,
                    p.stopped ? p.tstop_s : NAN, cm.held_out.trace_mse[i]));
      }
    write_csv(D / "predictions.csv", f);
  }
  {
    Table f({"model", "trace_rms_m_s2", "trace_rel_pct", "zstop_rms_mm", "zstop_rel_pct", "tstop_rms_ms",
             "tstop_rel_pct", "apeak_rms_m_s2", "apeak_rel_pct", "trials"});
    for (const auto& cm : compared) {
      const auto& e = cm.errors;
      f.add(cells(cm.name, e.trace_rms_m_s2, e.trace_rel_pct, e.zstop_rms_mm, e.zstop_rel_pct, e.tstop_rms_ms,
                  e.tstop_rel_pct, e.apeak_rms_m_s2, e.apeak_rel_pct, e.trials));
    }
    write_csv(D / "errors.csv", f);
  }
  const auto t3 = table3(c);
  {
    Table f({"gravity_m_s2", "trials", "f0_N", "f0_se_N", "inv_d1_1_m", "inv_d1_se_1_m", "vt_m_s", "vt_se_m_s", "alpha",
             "alpha_se"});
    for (const auto& r : t3)
      f.add(cells(r.g_m_s2, r.trials, r.f0_N, r.f0_se_N, r.inv_d1_1_m, r.inv_d1_se_1_m, r.vt_m_s, r.vt_se_m_s, r.alpha,
                  r.alpha_se));
    write_csv(D / "table3.csv", f);
  }
  std::vector<FittedModel> fits;
  for (const auto& s : specs) fits.push_back(fit_model(s, c));
  write_model_curves(D, c, t3, fits);
  write_residuals(D, c, fits);
  if (d) {
    Table f({"round", "term", "mean_rel_improvement", "trials_better", "trials", "p_value", "significant"});
    for (std::size_t r = 0; r < d->rounds.size(); ++r)
      for (const auto& cd : d->rounds[r])
        f.add(cells(r + 1, cd.term, cd.mean_rel_improvement, cd.trials_better, cd.trials, cd.p_value,
                    cd.significant ? 1 : 0));
    write_csv(D / "ranking.csv", f);
    auto v = open_out(D / "verdict.txt");
    v << d->verdict << "\n";
  }
}

ScratchDir::ScratchDir(const std::string& tag) {
  // A fresh folder of this process's own (mode 0700): never one that was there before, another
  // user's or another thread's.
  std::string pattern = (std::filesystem::temp_directory_path() / fmt::format("gravsweep-{}-XXXXXX", tag)).string();
  if (!::mkdtemp(pattern.data()))
    throw std::runtime_error(fmt::format("cannot create a temporary folder {}: {}", pattern, std::strerror(errno)));
  path = pattern;
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  std::filesystem::remove_all(path, ec);
}

int run_plots(const std::string& dir, const std::string& which, std::string& log) {
  namespace fs = std::filesystem;
  const fs::path script = fs::path(dir) / "plots.py";
  {
    auto f = open_out(script);
    f << kPlotsPy;
  }
  // Debian's python3 carries matplotlib; a python3 earlier in PATH may not.
  const std::string py = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string cmd = fmt::format("'{}' '{}' '{}' '{}' 2>&1", py, script.string(), dir, which);
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) throw std::runtime_error("cannot start python3 for the plots");
  std::array<char, 512> buf{};
  while (fgets(buf.data(), buf.size(), p)) log += buf.data();
  const int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : 1;
}

}  // namespace gravsweep::results
