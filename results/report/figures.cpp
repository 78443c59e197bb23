// Figures of one drop: the data of Fig. 1 and Fig. 2 (see figures.h), drawn by plots.py.
#include "results/report/figures.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "results/io/bed_file.h"
#include "results/io/hdf5.h"
#include "results/io/snapshot_file.h"
#include "results/io/trace_file.h"
#include "results/measurements/campaign.h"
#include "results/model/collapse.h"
#include "results/processing/metric_fields.h"
#include "results/report/report.h"

namespace gravsweep::results {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

double interp(const std::vector<double>& t, const std::vector<double>& y, double tq) {
  if (t.empty() || y.size() != t.size()) return NAN;
  if (tq <= t.front()) return y.front();
  if (tq >= t.back()) return y.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), tq) - t.begin());
  const double w = (tq - t[k - 1]) / (t[k] - t[k - 1]);
  return y[k - 1] + w * (y[k] - y[k - 1]);
}

/// A lab record: the trial of the campaign folder (trials.csv in the trace's folder or the one above)
/// whose trace_file is this file, read and processed as `measurements import` does.
MeasuredTrial load_lab_record(const fs::path& path) {
  const fs::path file = fs::weakly_canonical(path);
  for (const fs::path& dir : {file.parent_path(), file.parent_path().parent_path()}) {
    if (!fs::exists(dir / "trials.csv")) continue;
    Campaign c;
    try {
      c = load_campaign(dir.string());
    } catch (const std::exception& e) {
      throw ConfigError(fmt::format("{}: cannot read the campaign of this record: {}", path.string(), e.what()));
    }
    for (auto& t : c.trials)
      if (fs::weakly_canonical(dir / t.info.trace_file) == file) return std::move(t);
    for (const auto& is : c.issues)
      if (fs::weakly_canonical(dir / is.file) == file)
        throw ConfigError(fmt::format("{}: cannot process the record: {}", path.string(), is.to_string()));
    throw ConfigError(fmt::format("{}: no row of {} names this trace (column trace_file)", path.string(),
                                  (dir / "trials.csv").string()));
  }
  throw ConfigError(
      fmt::format("{}: a lab trace needs its campaign's trials.csv (gravity, impact speed, ...) in "
                  "the same folder or the one above; none found",
                  path.string()));
}

/// One record of Fig. 2 with the paper's green line: velocity and depth integrated from the
/// filtered acceleration (for a lab record that is its processing; for a DEM trace it is done
/// again without the engine's own velocity and depth, as Sunday et al. 2021 did with Chrono's).
struct Fig2Record {
  MeasuredTrial trial;
  std::vector<double> v_int, z_int;
  std::string label, note;
};

Fig2Record load_record(const std::string& path) {
  if (path.empty() || !fs::exists(path)) throw ConfigError(fmt::format("no record at '{}'", path));
  Fig2Record r;
  const std::string ext = fs::path(path).extension().string();
  if (ext == ".h5") {
    try {
      r.trial = read_dem_trial({fs::path(path).stem().string(), "", path});
    } catch (const std::exception& e) {
      throw ConfigError(fmt::format("{}: not a readable gravsweep trace.h5 ({})", path, e.what()));
    }
    try {
      process_trial(r.trial);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(fmt::format("{}: cannot process the record: {}", path, e.what()));
    }
    const auto parent = fs::path(path).parent_path().filename().string();
    r.label = fmt::format(
        "DEM {}", fs::path(path).filename() == "trace.h5" && !parent.empty() ? parent : fs::path(path).stem().string());
    const ProcessedTrace& p = r.trial.processed;
    // "processed using the same method as the experimental data" (Sect. 2.3, Fig. 2): as a lab
    // record (no own velocity and depth, bias taken from free fall and rest: about 0 for a DEM
    // record), from the engine's contact start and the engine's vc.
    Trace bare = r.trial.raw;
    bare.source = TraceSource::lab;
    bare.velocity_down_m_s.clear();
    bare.depth_m.clear();
    MetricOptions o = r.trial.options;
    o.impact_speed_m_s = p.metrics.vc_m_s;
    try {
      const ProcessedTrace q = process_trace(bare, o);
      const double z0 = interp(p.t_s, p.depth_m, p.metrics.t_start_s);
      r.v_int = q.velocity_down_m_s;
      r.z_int = q.depth_m;
      for (double& z : r.z_int) z += z0;
    } catch (const std::invalid_argument& e) {
      r.note = fmt::format("no re-integrated line: {}", e.what());
    }
  } else if (ext == ".csv") {
    r.trial = load_lab_record(path);
    r.label = fmt::format("lab {}", r.trial.info.trial_id);
    r.v_int = r.trial.processed.velocity_down_m_s;
    r.z_int = r.trial.processed.depth_m;
  } else {
    throw ConfigError(fmt::format("{}: expected a DEM trace (.h5) or a lab trace (.csv)", path));
  }
  return r;
}

/// fig2_<i>.csv: time since the collision start and the columns plots.py draws (empty = absent).
json write_fig2_record(const fs::path& dir, std::size_t i, const Fig2Record& r) {
  const auto& raw = r.trial.raw;
  const auto& p = r.trial.processed;
  const std::string name = fmt::format("fig2_{}.csv", i);
  std::ofstream f(dir / name);
  f << "t_s,accel_raw_m_s2,velocity_raw_m_s,depth_raw_m,accel_m_s2,velocity_int_m_s,depth_int_m\n";
  auto cell = [](const std::vector<double>& v, std::size_t k) { return k < v.size() ? fmt::format("{}", v[k]) : ""; };
  for (std::size_t k = 0; k < p.t_s.size(); ++k)
    f << fmt::format("{},{},{},{},{},{},{}\n", p.t_s[k] - p.metrics.t_start_s, cell(raw.accel_up_m_s2, k),
                     cell(raw.velocity_down_m_s, k), cell(raw.depth_m, k), p.accel_up_m_s2[k], cell(r.v_int, k),
                     cell(r.z_int, k));
  if (!f) throw std::runtime_error(fmt::format("{}: cannot write", (dir / name).string()));
  return json{{"csv", name},
              {"label", r.label},
              {"source", to_string(r.trial.info.source)},
              {"gravity_m_s2", r.trial.info.gravity_m_s2},
              {"bias_m_s2", p.bias_m_s2},
              {"note", r.note},
              {"metrics", json(p.metrics)}};
}

void check_png(const std::string& out) {
  if (out.empty() || fs::path(out).extension() != ".png")
    throw ConfigError(fmt::format("--out: expected a file name ending in .png, found '{}'", out));
}

void plot(const ScratchDir& tmp, const char* which, const json& spec, const std::string& out) {
  fs::create_directories(fs::absolute(out).parent_path());
  {
    std::ofstream f(tmp.path / (std::string(which) + ".json"));
    f << spec.dump();
  }
  std::string log;
  if (run_plots(tmp.path.string(), which, log) != 0) throw std::runtime_error("plotting failed: " + log);
}

}  // namespace

Metrics draw_fig2(const Fig2Request& rq) {
  check_png(rq.out);
  const Fig2Record main = load_record(rq.record);
  ScratchDir tmp("fig2");
  json records = json::array({write_fig2_record(tmp.path, 0, main)});
  if (!rq.compare.empty()) {
    const Fig2Record other = load_record(rq.compare);
    records.push_back(write_fig2_record(tmp.path, 1, other));
  }
  const Metrics& m = main.trial.processed.metrics;
  const json spec{
      {"out", fs::absolute(rq.out).string()},
      {"records", records},
      {"title", fmt::format("{}: g = {:g} m/s2, vc = {:.3f} m/s", main.label, main.trial.info.gravity_m_s2, m.vc_m_s)}};
  plot(tmp, "trace", spec, rq.out);
  return m;
}

/// The bed of Fig. 1 (its grains into `grains`: their positions and radii are drawn), read or
/// refused with the file named.
BedFacts fig1_bed(const std::string& path, Particles& grains) {
  if (!fs::exists(path)) throw ConfigError(fmt::format("no bed file at '{}'", path));
  try {
    return read_bed(path, grains);
  } catch (const std::exception& e) {
    throw ConfigError(fmt::format("{}: not a readable gravsweep bed.h5 ({})", path, e.what()));
  }
}

/// The projectile's record of Fig. 1 (empty path: none), read or refused with the file named.
TraceData fig1_trace(const std::string& path) {
  TraceData td;
  if (path.empty()) return td;
  if (!fs::exists(path)) throw ConfigError(fmt::format("--trace: no trace file at '{}'", path));
  try {
    td = read_trace(path);
  } catch (const std::exception& e) {
    throw ConfigError(fmt::format("{}: not a readable gravsweep trace.h5 ({})", path, e.what()));
  }
  if (td.size() == 0) throw ConfigError(fmt::format("{}: the trace holds no sample", path));
  return td;
}

/// Fig. 1 (b): the projectile where the record ends, over the grains of the drop's last snapshot
/// (written by `write_grains` as rest.csv) or, without snapshots, the grains as prepared.
template <class WriteGrains, class Projectile>
json fig1_rest_panel(const Fig1Request& rq, std::size_t bed_grains, const TraceData& td, WriteGrains write_grains,
                     Projectile projectile, std::string& what) {
  const std::size_t k = td.size() - 1;
  json panel{
      {"title", fmt::format("(b) {} at t = {:.0f} ms, {:.2f} cm deep", td.stopped ? "at rest" : "at the time cap",
                            1000 * td.raw.t_s[k], 100 * td.raw.depth_m[k])},
      {"grains", "bed.csv"},
      {"projectile", projectile(k)}};
  const std::string snaps = rq.snapshots.empty() ? snapshot_path_for(rq.trace).string() : rq.snapshots;
  if (fs::exists(snaps)) {
    try {
      const Snapshot s = read_snapshot(snaps, -1);
      if (s.grains.size() != bed_grains)
        throw ConfigError(fmt::format("{}: {} grains, the bed has {}", snaps, s.grains.size(), bed_grains));
      const std::vector<double>& at_rest = s.grains.position_m;  // (N, 3) row-major
      write_grains("rest.csv",
                   [&](std::size_t i) { return Vec3(at_rest[3 * i], at_rest[3 * i + 1], at_rest[3 * i + 2]); });
      panel["grains"] = "rest.csv";
      what += fmt::format(", grains at rest from {}", snaps);
    } catch (const h5::H5Error& e) {
      throw ConfigError(fmt::format("{}: not a readable snapshots file ({})", snaps, e.what()));
    }
  } else {
    panel["note"] = "grains as prepared (no snapshots.h5 of this drop)";
    what += ", no snapshots: grains as prepared in (b)";
  }
  return panel;
}

std::string draw_fig1(const Fig1Request& rq) {
  check_png(rq.out);
  if (rq.at != "" && rq.at != "release" && rq.at != "rest")
    throw ConfigError(fmt::format("--at '{}': expected release or rest", rq.at));
  if (!rq.at.empty() && rq.trace.empty()) throw ConfigError("--at needs --trace (the projectile's record)");
  if (!fs::exists(rq.bed)) throw ConfigError(fmt::format("no bed file at '{}'", rq.bed));
  Particles grains;
  const BedFacts bed = fig1_bed(rq.bed, grains);
  const TraceData td = fig1_trace(rq.trace);
  ScratchDir tmp("fig1");
  // Each grain at the position `position_of` gives it, with its radius and its distance from the
  // axis as prepared (r0_m).
  auto write_grains = [&](const std::string& name, const auto& position_of) {
    std::ofstream f(tmp.path / name);
    f << "x_m,y_m,z_m,radius_m,r0_m\n";
    for (std::size_t i = 0; i < grains.size(); ++i) {
      const Vec3 p = position_of(i);
      f << fmt::format("{},{},{},{},{}\n", p[0], p[1], p[2], grains.radius_m[i],
                       std::hypot(grains.position_m[i][0], grains.position_m[i][1]));
    }
  };
  write_grains("bed.csv", [&](std::size_t i) { return grains.position_m[i]; });
  json panels = json::array();
  const double R = 0.5 * td.info.projectile_diameter_m;
  auto projectile = [&](std::size_t k) {
    return json{{"x_m", td.position_m[3 * k]},
                {"y_m", td.position_m[3 * k + 1]},
                {"z_m", td.position_m[3 * k + 2]},
                {"radius_m", R},
                {"t_s", td.raw.t_s[k]},
                {"depth_m", td.raw.depth_m[k]}};
  };
  std::string what = fmt::format("{} grains", grains.size());
  if (rq.trace.empty()) panels.push_back(json{{"title", "prepared bed"}, {"grains", "bed.csv"}});
  if (!rq.trace.empty() && rq.at != "rest")
    panels.push_back(json{{"title", fmt::format("(a) release, {:.1f} cm above the surface",
                                                100 * (td.release_height_m - td.info.fill_height_m))},
                          {"grains", "bed.csv"},
                          {"projectile", projectile(0)}});
  if (!rq.trace.empty() && rq.at != "release")
    panels.push_back(fig1_rest_panel(rq, grains.size(), td, write_grains, projectile, what));
  const json spec{{"out", fs::absolute(rq.out).string()},
                  {"panels", panels},
                  {"container_diameter_m", bed.container_diameter_m},
                  {"wall_height_m", bed.wall_height_m},
                  {"surface_height_m", bed.surface_height_m},
                  {"title", fmt::format("{}: {} grains, fill {:.1f} cm, g = {:g} m/s2", rq.bed, grains.size(),
                                        100 * bed.fill_height_m, bed.gravity_m_s2)}};
  plot(tmp, "bed", spec, rq.out);
  return what;
}

void draw_collapse(const Campaign& campaign, const std::string& out, const std::string& title) {
  check_png(out);
  ScratchDir tmp("collapse");
  {
    std::ofstream f(tmp.path / "collapse.csv");
    f << "gravity_m_s2,froude,zstop_over_D,tstop_sqrt_g_over_D,apeak_over_g\n";
    for (const auto& s : scaled_trials(campaign))
      f << fmt::format("{},{},{},{},{}\n", s.gravity_m_s2, s.froude, s.zstop_over_D, s.tstop_sqrt_g_over_D,
                       s.apeak_over_g);
    if (!f) throw std::runtime_error(fmt::format("{}: cannot write", (tmp.path / "collapse.csv").string()));
  }
  json rows = json::array();
  for (const auto& r : collapse(campaign))
    rows.push_back({{"metric", r.metric},
                    {"common_scatter_pct", r.common_scatter_pct},
                    {"within_scatter_pct", r.within_scatter_pct},
                    {"collapse_ratio", r.collapse_ratio}});
  plot(tmp, "collapse", json{{"out", fs::absolute(out).string()}, {"title", title}, {"rows", rows}}, out);
}

void draw_law_against_gravity(const std::vector<LawCurvePoint>& points, const LawRange& fitted_gravity,
                              const std::string& out, const std::string& title) {
  check_png(out);
  ScratchDir tmp("law_g");
  {
    std::ofstream f(tmp.path / "law_g.csv");
    f << "curve,gravity_m_s2,zstop_m,zstop_lo_m,zstop_hi_m,tstop_s,tstop_lo_s,tstop_hi_s,apeak_m_s2,apeak_lo_m_s2,"
         "apeak_hi_m_s2,range\n";
    for (const auto& q : points) {
      const auto& p = q.p;
      f << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}\n", q.curve, q.gravity_m_s2, p.zstop_m, p.zstop_lo_m,
                       p.zstop_hi_m, p.tstop_s, p.tstop_lo_s, p.tstop_hi_s, p.apeak_m_s2, p.apeak_lo_m_s2,
                       p.apeak_hi_m_s2, to_string(p.range));
    }
    if (!f) throw std::runtime_error(fmt::format("{}: cannot write", (tmp.path / "law_g.csv").string()));
  }
  plot(tmp, "law_g",
       json{{"out", fs::absolute(out).string()},
            {"title", title},
            {"fitted_g_min", fitted_gravity.lo},
            {"fitted_g_max", fitted_gravity.hi}},
       out);
}

}  // namespace gravsweep::results
