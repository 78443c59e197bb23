// Reading, processing and storing measurement campaigns (see campaign.h).
#include "results/measurements/campaign.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "results/io/trace_file.h"
#include "scheduler/db/sqlite.h"

namespace gravsweep::results {

namespace fs = std::filesystem;

std::string ImportIssue::to_string() const {
  if (line > 0 && column > 0) return fmt::format("{}:{}:{}: {}", file, line, column, message);
  if (line > 0) return fmt::format("{}:{}: {}", file, line, message);
  return fmt::format("{}: {}", file, message);
}

std::vector<double> Campaign::gravity_levels() const {
  std::vector<double> g;
  for (const auto& t : trials) {
    bool seen = false;
    for (double x : g) seen = seen || std::abs(x - t.info.gravity_m_s2) <= 1e-9 * std::abs(x);
    if (!seen) g.push_back(t.info.gravity_m_s2);
  }
  std::sort(g.rbegin(), g.rend());
  return g;
}

namespace {

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur.push_back(c);
    }
  }
  out.push_back(cur);
  for (auto& s : out) {
    const auto b = s.find_first_not_of(" \t");
    const auto e = s.find_last_not_of(" \t");
    s = b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  }
  return out;
}

/// Parses a finite number; nullopt-like failure reported through `ok`.
bool parse_double(const std::string& s, double& v) {
  if (s.empty()) return false;
  const char* b = s.data();
  const char* e = s.data() + s.size();
  auto [p, ec] = std::from_chars(b, e, v);
  return ec == std::errc() && p == e && std::isfinite(v);
}

struct ParseError {
  ImportIssue issue;
};

const char* kRequired[] = {"trial_id",         "trace_file",         "gravity_m_s2",
                           "impact_velocity_m_s", "fill_height_m",   "projectile_mass_kg",
                           "projectile_diameter_m", "grain_diameter_m", "bulk_density_kg_m3",
                           "sample_rate_hz"};

Trace read_trace_csv(const fs::path& path, const std::string& rel) {
  std::ifstream in(path);
  if (!in) throw ParseError{{rel, 0, 0, "cannot open the trace file"}};
  std::string line;
  if (!std::getline(in, line)) throw ParseError{{rel, 1, 0, "empty file: header 't_s,accel_m_s2' expected"}};
  const auto head = split_csv(line);
  int ct = -1, ca = -1, cz = -1, cv = -1;
  for (int i = 0; i < static_cast<int>(head.size()); ++i) {
    if (head[i] == "t_s") ct = i;
    if (head[i] == "accel_m_s2") ca = i;
    if (head[i] == "position_m") cz = i;
    if (head[i] == "velocity_m_s") cv = i;
  }
  if (ct < 0) throw ParseError{{rel, 1, 0, "missing column 't_s' in the header"}};
  if (ca < 0) throw ParseError{{rel, 1, 0, "missing column 'accel_m_s2' in the header"}};
  Trace tr;
  int ln = 1;
  while (std::getline(in, line)) {
    ++ln;
    if (line.empty() || line == "\r") continue;
    const auto f = split_csv(line);
    auto get = [&](int c, const char* name) {
      if (c >= static_cast<int>(f.size()))
        throw ParseError{{rel, ln, c + 1, fmt::format("column '{}' missing on this line", name)}};
      double v;
      if (!parse_double(f[c], v))
        throw ParseError{{rel, ln, c + 1,
                          fmt::format("column '{}': expected a finite number, got '{}'", name, f[c])}};
      return v;
    };
    const double t = get(ct, "t_s");
    if (!tr.t_s.empty() && !(t > tr.t_s.back()))
      throw ParseError{{rel, ln, ct + 1,
                        fmt::format("column 't_s': time must increase, got {} after {}", t,
                                    tr.t_s.back())}};
    tr.t_s.push_back(t);
    tr.accel_up_m_s2.push_back(get(ca, "accel_m_s2"));
    if (cz >= 0) tr.depth_m.push_back(get(cz, "position_m"));
    if (cv >= 0) tr.velocity_down_m_s.push_back(get(cv, "velocity_m_s"));
  }
  if (tr.t_s.size() < 8)
    throw ParseError{{rel, ln, 0, fmt::format("only {} samples: a record from free fall to rest expected",
                                              tr.t_s.size())}};
  return tr;
}

}  // namespace

Campaign load_campaign(const std::string& directory, double cutoff_hz) {
  Campaign c;
  c.directory = directory;
  const fs::path dir(directory);
  const fs::path csv = dir / "trials.csv";
  std::ifstream in(csv);
  if (!in)
    throw std::runtime_error(fmt::format("{}: cannot open (a campaign folder holds trials.csv and "
                                         "traces/, see shared/formats/measurements.md)",
                                         csv.string()));
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(fmt::format("{}:1: empty file, header expected", csv.string()));
  const auto head = split_csv(line);
  std::map<std::string, int> col;
  for (int i = 0; i < static_cast<int>(head.size()); ++i) col[head[i]] = i;
  for (const char* r : kRequired)
    if (!col.count(r))
      throw std::runtime_error(fmt::format("{}:1: missing required column '{}'", csv.string(), r));
  std::set<std::string> ids;
  int ln = 1;
  while (std::getline(in, line)) {
    ++ln;
    if (line.empty() || line == "\r") continue;
    try {
      const auto f = split_csv(line);
      auto text = [&](const char* name) -> std::string {
        const int i = col.at(name);
        return i < static_cast<int>(f.size()) ? f[i] : std::string();
      };
      auto num = [&](const char* name, bool positive) {
        const int i = col.at(name);
        const std::string s = text(name);
        double v;
        if (!parse_double(s, v))
          throw ParseError{{"trials.csv", ln, i + 1,
                            fmt::format("column '{}': expected a finite number, got '{}'", name, s)}};
        if (positive && !(v > 0))
          throw ParseError{{"trials.csv", ln, i + 1,
                            fmt::format("column '{}': expected a value > 0, got {}", name, v)}};
        return v;
      };
      Trial t;
      TrialInfo& ti = t.info;
      ti.trial_id = text("trial_id");
      if (ti.trial_id.empty())
        throw ParseError{{"trials.csv", ln, col["trial_id"] + 1, "column 'trial_id': empty"}};
      if (!ids.insert(ti.trial_id).second)
        throw ParseError{{"trials.csv", ln, col["trial_id"] + 1,
                          fmt::format("column 'trial_id': '{}' appears twice", ti.trial_id)}};
      ti.trace_file = text("trace_file");
      ti.gravity_m_s2 = num("gravity_m_s2", true);
      if (col.count("drop_height_m") && text("impact_velocity_m_s").empty()) {
        ti.drop_height_m = num("drop_height_m", true);
        ti.impact_velocity_m_s = std::sqrt(2.0 * ti.gravity_m_s2 * ti.drop_height_m);
      } else {
        ti.impact_velocity_m_s = num("impact_velocity_m_s", true);
      }
      ti.fill_height_m = num("fill_height_m", true);
      ti.projectile_mass_kg = num("projectile_mass_kg", true);
      ti.projectile_diameter_m = num("projectile_diameter_m", true);
      ti.grain_diameter_m = num("grain_diameter_m", true);
      ti.bulk_density_kg_m3 = num("bulk_density_kg_m3", false);  // kept, not used by the models
      ti.sample_rate_hz = num("sample_rate_hz", true);
      for (const auto& [name, i] : col) {
        bool req = name == "drop_height_m";
        for (const char* r : kRequired) req = req || name == r;
        if (!req && i < static_cast<int>(f.size())) ti.attributes[name] = f[i];
      }
      const std::string rel = ti.trace_file;
      if (fs::path(rel).extension() == ".h5") {
        // A DEM trace written by `gravsweep run` (results/io/trace_file.h): it carries z and v.
        try {
          t.raw = read_trace(dir / rel).to_trace();
        } catch (const std::exception& e) {
          throw ParseError{{rel, 0, 0, e.what()}};
        }
      } else {
        t.raw = read_trace_csv(dir / rel, rel);
      }
      MetricOptions o;
      o.gravity_m_s2 = ti.gravity_m_s2;
      o.cutoff_hz = cutoff_hz;
      o.impact_velocity_m_s = ti.impact_velocity_m_s;
      o.fill_height_m = ti.fill_height_m;
      o.grain_diameter_m = ti.grain_diameter_m;
      o.projectile_diameter_m = ti.projectile_diameter_m;
      try {
        t.processed = process_trace(t.raw, o);
      } catch (const std::invalid_argument& e) {
        throw ParseError{{rel, 0, 0, e.what()}};
      }
      // Fit window: inside the collision, two filter edge widths clear of contact and stop.
      const auto& p = t.processed;
      const std::size_t w = 2 * (1 + static_cast<std::size_t>(std::ceil(p.sample_rate_hz / cutoff_hz)));
      t.fit_begin = p.i_start + 1 + w;
      t.fit_end = p.i_end > w ? p.i_end - w : 0;
      if (t.fit_end < t.fit_begin + 3) {
        // Short collision: keep what lies inside it.
        t.fit_begin = p.i_start + 1;
        t.fit_end = std::max(t.fit_begin, p.i_end);
      }
      c.trials.push_back(std::move(t));
    } catch (const ParseError& e) {
      ImportIssue is = e.issue;
      if (is.file != "trials.csv") is.message += fmt::format(" (trial on trials.csv line {})", ln);
      c.issues.push_back(is);
    }
  }
  return c;
}

int store_campaign(db::Database& db, const Campaign& c) {
  db.exec(R"(
CREATE TABLE IF NOT EXISTS trials (
  trial_id TEXT PRIMARY KEY, campaign_dir TEXT, trace_file TEXT, gravity_m_s2 REAL,
  impact_velocity_m_s REAL, fill_height_m REAL, projectile_mass_kg REAL,
  projectile_diameter_m REAL, grain_diameter_m REAL, bulk_density_kg_m3 REAL,
  sample_rate_hz REAL, attributes_json TEXT, imported_at TEXT DEFAULT (datetime('now')));
CREATE TABLE IF NOT EXISTS trial_samples (
  trial_id TEXT NOT NULL REFERENCES trials(trial_id) ON DELETE CASCADE, sample INTEGER NOT NULL,
  t_s REAL, accel_raw_m_s2 REAL, accel_filtered_m_s2 REAL, velocity_m_s REAL, depth_m REAL,
  PRIMARY KEY (trial_id, sample));
CREATE TABLE IF NOT EXISTS trial_metrics (
  trial_id TEXT PRIMARY KEY REFERENCES trials(trial_id) ON DELETE CASCADE,
  vc_m_s REAL, apeak_m_s2 REAL, zstop_m REAL, tstop_s REAL, t_start_s REAL, t_end_s REAL,
  rebound INTEGER, bias_m_s2 REAL, note TEXT, i_start INTEGER, i_end INTEGER, fit_begin INTEGER,
  fit_end INTEGER, processed_rate_hz REAL);
)");
  db::Transaction tx(db);
  db::Statement del(db, "DELETE FROM trials WHERE trial_id = ?");
  db::Statement ins(db,
                    "INSERT INTO trials (trial_id, campaign_dir, trace_file, gravity_m_s2, "
                    "impact_velocity_m_s, fill_height_m, projectile_mass_kg, projectile_diameter_m, "
                    "grain_diameter_m, bulk_density_kg_m3, sample_rate_hz, attributes_json) "
                    "VALUES (?,?,?,?,?,?,?,?,?,?,?,?)");
  db::Statement smp(db,
                    "INSERT INTO trial_samples (trial_id, sample, t_s, accel_raw_m_s2, "
                    "accel_filtered_m_s2, velocity_m_s, depth_m) VALUES (?,?,?,?,?,?,?)");
  db::Statement met(db,
                    "INSERT INTO trial_metrics (trial_id, vc_m_s, apeak_m_s2, zstop_m, tstop_s, "
                    "t_start_s, t_end_s, rebound, bias_m_s2, note, i_start, i_end, fit_begin, fit_end, "
                    "processed_rate_hz) VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)");
  int stored = 0;
  for (const auto& t : c.trials) {
    const auto& i = t.info;
    del.reset();
    del.bind(1, i.trial_id).run();
    std::string attrs = "{";
    for (const auto& [k, v] : i.attributes)
      attrs += fmt::format("{}\"{}\":\"{}\"", attrs.size() > 1 ? "," : "", k, v);
    attrs += "}";
    ins.reset();
    ins.bind(1, i.trial_id).bind(2, c.directory).bind(3, i.trace_file).bind(4, i.gravity_m_s2)
        .bind(5, i.impact_velocity_m_s).bind(6, i.fill_height_m).bind(7, i.projectile_mass_kg)
        .bind(8, i.projectile_diameter_m).bind(9, i.grain_diameter_m).bind(10, i.bulk_density_kg_m3)
        .bind(11, i.sample_rate_hz).bind(12, attrs);
    ins.run();
    const auto& p = t.processed;
    for (std::size_t k = 0; k < p.t_s.size(); ++k) {
      smp.reset();
      smp.bind(1, i.trial_id).bind(2, static_cast<std::int64_t>(k)).bind(3, p.t_s[k])
          .bind(4, t.raw.accel_up_m_s2[k]).bind(5, p.accel_up_m_s2[k])
          .bind(6, p.velocity_down_m_s[k]).bind(7, p.depth_m[k]);
      smp.run();
    }
    const auto& m = p.metrics;
    met.reset();
    met.bind(1, i.trial_id).bind(2, m.vc_m_s).bind(3, m.apeak_m_s2).bind(4, m.zstop_m)
        .bind(5, m.tstop_s).bind(6, m.t_start_s).bind(7, m.t_end_s).bind(8, m.rebound ? 1 : 0)
        .bind(9, p.bias_m_s2).bind(10, m.note).bind(11, static_cast<std::int64_t>(p.i_start))
        .bind(12, static_cast<std::int64_t>(p.i_end)).bind(13, static_cast<std::int64_t>(t.fit_begin))
        .bind(14, static_cast<std::int64_t>(t.fit_end)).bind(15, p.sample_rate_hz);
    met.run();
    ++stored;
  }
  tx.commit();
  return stored;
}

int write_campaign_from_runs(const std::vector<std::string>& roots, const std::string& out_dir,
                             std::vector<ImportIssue>& issues) {
  std::vector<fs::path> traces;
  for (const auto& r : roots) {
    if (fs::is_regular_file(r)) {
      traces.emplace_back(r);
      continue;
    }
    if (!fs::is_directory(r)) {
      issues.push_back({r, 0, 0, "neither a trace.h5 file nor a folder"});
      continue;
    }
    for (const auto& e : fs::recursive_directory_iterator(r))
      if (e.is_regular_file() && e.path().filename() == "trace.h5") traces.push_back(e.path());
  }
  std::sort(traces.begin(), traces.end());
  fs::create_directories(out_dir);
  std::ofstream csv(fs::path(out_dir) / "trials.csv");
  if (!csv) throw std::runtime_error(fmt::format("{}: cannot write trials.csv", out_dir));
  csv << "trial_id,trace_file,gravity_m_s2,impact_velocity_m_s,fill_height_m,projectile_mass_kg,"
         "projectile_diameter_m,grain_diameter_m,bulk_density_kg_m3,sample_rate_hz,code_version\n";
  int n = 0;
  std::set<std::string> ids;
  for (const auto& p : traces) {
    try {
      const TraceData td = read_trace(p);
      MetricOptions o;
      o.gravity_m_s2 = td.gravity_m_s2;
      const Metrics m = compute_metrics(td.to_trace(), o);  // vc from the trace's own velocity
      std::string id = p.parent_path().filename().string();
      if (id.empty() || !ids.insert(id).second) id = fmt::format("{}_{}", id, n + 1);
      csv << fmt::format("{},{},{},{},{},{},{},{},0,{},{}\n", id, fs::absolute(p).string(), td.gravity_m_s2,
                         m.vc_m_s, td.fill_height_m, td.projectile_mass_kg, td.projectile_diameter_m,
                         td.grain_diameter_m, td.sample_rate_hz, td.code_version);
      ++n;
    } catch (const std::exception& e) {
      issues.push_back({p.string(), 0, 0, e.what()});
    }
  }
  return n;
}

Campaign load_campaign_db(db::Database& db) {
  Campaign c;
  c.directory = db.path();
  db::Statement q(db,
                  "SELECT t.trial_id, t.trace_file, t.gravity_m_s2, t.impact_velocity_m_s, t.fill_height_m, "
                  "t.projectile_mass_kg, t.projectile_diameter_m, t.grain_diameter_m, t.bulk_density_kg_m3, "
                  "t.sample_rate_hz, m.vc_m_s, m.apeak_m_s2, m.zstop_m, m.tstop_s, m.t_start_s, m.t_end_s, "
                  "m.rebound, m.bias_m_s2, m.note, m.i_start, m.i_end, m.fit_begin, m.fit_end, "
                  "m.processed_rate_hz, t.campaign_dir FROM trials t JOIN trial_metrics m USING (trial_id) "
                  "ORDER BY t.rowid");
  db::Statement smp(db,
                    "SELECT t_s, accel_raw_m_s2, accel_filtered_m_s2, velocity_m_s, depth_m FROM trial_samples "
                    "WHERE trial_id = ? ORDER BY sample");
  while (q.step()) {
    Trial t;
    auto& i = t.info;
    i.trial_id = q.get_text(0);
    i.trace_file = q.get_text(1);
    i.gravity_m_s2 = q.get_double(2);
    i.impact_velocity_m_s = q.get_double(3);
    i.fill_height_m = q.get_double(4);
    i.projectile_mass_kg = q.get_double(5);
    i.projectile_diameter_m = q.get_double(6);
    i.grain_diameter_m = q.get_double(7);
    i.bulk_density_kg_m3 = q.get_double(8);
    i.sample_rate_hz = q.get_double(9);
    auto& p = t.processed;
    auto& m = p.metrics;
    m.vc_m_s = q.get_double(10);
    m.apeak_m_s2 = q.get_double(11);
    m.zstop_m = q.get_double(12);
    m.tstop_s = q.get_double(13);
    m.t_start_s = q.get_double(14);
    m.t_end_s = q.get_double(15);
    m.rebound = q.get_int(16) != 0;
    p.bias_m_s2 = q.get_double(17);
    m.note = q.is_null(18) ? "" : q.get_text(18);
    if (q.is_null(19) || q.is_null(21))
      throw std::runtime_error(fmt::format("{}: trial '{}' was imported by an older gravsweep without fit "
                                           "windows; import the campaign again",
                                           db.path(), i.trial_id));
    p.i_start = static_cast<std::size_t>(q.get_int(19));
    p.i_end = static_cast<std::size_t>(q.get_int(20));
    t.fit_begin = static_cast<std::size_t>(q.get_int(21));
    t.fit_end = static_cast<std::size_t>(q.get_int(22));
    p.sample_rate_hz = q.get_double(23);
    if (c.directory == db.path()) c.directory = q.get_text(24);
    smp.reset();
    smp.bind(1, i.trial_id);
    while (smp.step()) {
      t.raw.t_s.push_back(smp.get_double(0));
      t.raw.accel_up_m_s2.push_back(smp.get_double(1));
      p.t_s.push_back(smp.get_double(0));
      p.accel_up_m_s2.push_back(smp.get_double(2));
      p.velocity_down_m_s.push_back(smp.get_double(3));
      p.depth_m.push_back(smp.get_double(4));
    }
    if (t.fit_end > p.t_s.size() || t.fit_begin > t.fit_end)
      throw std::runtime_error(fmt::format("{}: trial '{}': fit window [{}, {}) outside its {} samples",
                                           db.path(), i.trial_id, t.fit_begin, t.fit_end, p.t_s.size()));
    c.trials.push_back(std::move(t));
  }
  return c;
}

Campaign load_campaign_any(const std::string& path, double cutoff_hz) {
  namespace fs = std::filesystem;
  if (fs::is_regular_file(path)) {
    db::Database db(path, 30000, true);
    Campaign c = load_campaign_db(db);
    if (c.trials.empty()) throw std::runtime_error(fmt::format("{}: no imported trials", path));
    return c;
  }
  return load_campaign(path, cutoff_hz);
}

}  // namespace gravsweep::results
