// Reader of lab campaign folders (docs/formats/measurements.md): trials.csv and traces/*.csv,
// RFC 4180 CSV (csv.h). Every problem names the file, the line and the column.
#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

#include "results/measurements/campaign.h"
#include "results/io/csv.h"

namespace gravsweep::results {

namespace fs = std::filesystem;

namespace {

struct ParseError {
  ImportIssue issue;
};

/// Parses a finite number.
bool parse_double(const std::string& s, double& v) {
  if (s.empty()) return false;
  const char* b = s.data();
  const char* e = s.data() + s.size();
  if (*b == '+') ++b;
  auto [p, ec] = std::from_chars(b, e, v);
  return ec == std::errc() && p == e && std::isfinite(v);
}

bool next_record(CsvReader& r, std::vector<std::string>& f, int& line, const std::string& rel) {
  try {
    return r.next(f, line);
  } catch (const CsvSyntaxError& e) {
    throw ParseError{{rel, e.line, e.column, e.message}};
  }
}

/// `rel` (a trace_file cell) resolved inside the campaign folder, symlinks followed; refused
/// when it leads outside (an absolute path, '..', or a link pointing out).
fs::path resolve_inside(const fs::path& dir, const std::string& rel, int line, int column) {
  auto refuse = [&](const std::string& why) {
    return ParseError{
        {"trials.csv", line, column,
         fmt::format("column 'trace_file': '{}' {}; a path inside the campaign folder expected", rel, why)}};
  };
  if (rel.empty()) throw refuse("is empty");
  if (fs::path(rel).is_absolute()) throw refuse("is absolute");
  std::error_code ec;
  const fs::path root = fs::canonical(dir, ec);
  if (ec) throw refuse("cannot be resolved (" + ec.message() + ")");
  const fs::path full = fs::weakly_canonical(dir / rel, ec);
  if (ec) throw refuse("cannot be resolved (" + ec.message() + ")");
  const auto mm = std::mismatch(root.begin(), root.end(), full.begin(), full.end());
  if (mm.first != root.end()) throw refuse(fmt::format("resolves to {}, outside {}", full.string(), root.string()));
  return full;
}

/// A trace CSV; `declared_hz` is the row's sample_rate_hz, checked against the timestamps. The
/// line of each sample and the acceleration's column go to `out.sample_lines`, `out.accel_column`.
Trace read_trace_csv(const fs::path& path, const std::string& rel, double declared_hz, int row_line, int rate_col,
                     MeasuredTrial& out) {
  std::ifstream in(path);
  if (!in) throw ParseError{{rel, 0, 0, "cannot open the trace file"}};
  CsvReader reader(in);
  std::vector<std::string> head, f;
  int ln = 0;
  if (!next_record(reader, head, ln, rel))
    throw ParseError{{rel, 1, 0, "empty file: header 't_s,accel_m_s2' expected"}};
  int ct = -1, ca = -1, cz = -1, cv = -1;
  for (int i = 0; i < static_cast<int>(head.size()); ++i) {
    if (head[i] == "t_s") ct = i;
    if (head[i] == "accel_m_s2") ca = i;
    if (head[i] == "position_m") cz = i;
    if (head[i] == "velocity_m_s") cv = i;
  }
  if (ct < 0) throw ParseError{{rel, ln, 0, "missing column 't_s' in the header"}};
  if (ca < 0) throw ParseError{{rel, ln, 0, "missing column 'accel_m_s2' in the header"}};
  Trace tr;
  tr.source = TraceSource::lab;
  std::vector<int> lines;
  while (next_record(reader, f, ln, rel)) {
    auto get = [&](int c, const char* name) {
      if (c >= static_cast<int>(f.size()))
        throw ParseError{{rel, ln, c + 1, fmt::format("column '{}' missing on this line", name)}};
      double v;
      if (!parse_double(f[c], v))
        throw ParseError{{rel, ln, c + 1, fmt::format("column '{}': expected a finite number, got '{}'", name, f[c])}};
      return v;
    };
    const double t = get(ct, "t_s");
    if (!tr.t_s.empty() && !(t > tr.t_s.back()))
      throw ParseError{
          {rel, ln, ct + 1, fmt::format("column 't_s': time must increase, got {} after {}", t, tr.t_s.back())}};
    tr.t_s.push_back(t);
    lines.push_back(ln);
    tr.accel_up_m_s2.push_back(get(ca, "accel_m_s2"));
    if (cz >= 0) tr.depth_m.push_back(get(cz, "position_m"));
    if (cv >= 0) tr.velocity_down_m_s.push_back(get(cv, "velocity_m_s"));
  }
  if (tr.t_s.size() < 8)
    throw ParseError{
        {rel, ln, 0, fmt::format("only {} samples: a record from free fall to rest expected", tr.t_s.size())}};
  // The declared rate against the timestamps (median interval), then no gaps.
  std::vector<double> dt(tr.t_s.size() - 1);
  for (std::size_t i = 0; i + 1 < tr.t_s.size(); ++i) dt[i] = tr.t_s[i + 1] - tr.t_s[i];
  std::vector<double> sorted = dt;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double median_hz = 1.0 / sorted[sorted.size() / 2];
  if (std::abs(median_hz - declared_hz) > 0.01 * declared_hz)
    throw ParseError{{"trials.csv", row_line, rate_col,
                      fmt::format("column 'sample_rate_hz': declared {} Hz, but the timestamps of {} are {:.6g} Hz "
                                  "apart (median interval); the rate of the record expected",
                                  declared_hz, rel, median_hz)}};
  for (std::size_t i = 0; i < dt.size(); ++i)
    if (dt[i] * declared_hz > 1.5)
      throw ParseError{{rel, lines[i + 1], ct + 1,
                        fmt::format("column 't_s': gap in the record: {} s after {} s, about {} samples missing at "
                                    "the declared {} Hz; one sample every {:.6g} s expected",
                                    tr.t_s[i + 1], tr.t_s[i], std::lround(dt[i] * declared_hz) - 1, declared_hz,
                                    1.0 / declared_hz)}};
  out.sample_lines = std::move(lines);
  out.accel_column = ca + 1;
  return tr;
}

/// A processing error of a trial, at the line of the sample it is about (and the acceleration's
/// column when the sample's value is the reason: out of range, not a number).
ImportIssue issue_of(const MeasuredTrial& t, const TraceError& e) {
  ImportIssue is{t.info.trace_file, 0, 0, e.what()};
  if (e.sample() && *e.sample() < t.sample_lines.size()) {
    is.line = t.sample_lines[*e.sample()];
    if (e.bad_value()) is.column = t.accel_column;
  }
  return is;
}

/// The required columns of trials.csv, from the field table.
std::vector<std::string> required_columns() {
  std::vector<std::string> r;
  for (const auto& f : trial_fields())
    if (f.csv_required) r.emplace_back(f.key);
  return r;
}

/// The cells of one trials.csv row by column name, numbers checked against their physical range.
struct RowCells {
  const std::map<std::string, int>& col;
  const std::vector<std::string>& f;
  int ln;
  [[nodiscard]] std::string text(const std::string& name) const {
    const auto it = col.find(name);
    return it != col.end() && it->second < static_cast<int>(f.size()) ? f[it->second] : std::string();
  }
  [[nodiscard]] double num(const std::string& name, bool positive) const {
    const int i = col.at(name);
    const std::string s = text(name);
    double v;
    if (!parse_double(s, v))
      throw ParseError{
          {"trials.csv", ln, i + 1, fmt::format("column '{}': expected a finite number, got '{}'", name, s)}};
    if (positive && !(v > 0))
      throw ParseError{{"trials.csv", ln, i + 1, fmt::format("column '{}': expected a value > 0, got {}", name, v)}};
    if (const std::string expected = out_of_physical_range(name, v); !expected.empty())
      throw ParseError{{"trials.csv", ln, i + 1, fmt::format("column '{}': found {}, expected {}", name, s, expected)}};
    return v;
  }
};

/// The trial's facts from its row: the fields of trial_fields(), the impact speed (or sqrt(2 g h)
/// from drop_height_m), the other columns as attributes, an explicit source.
Trial trial_of_row(const RowCells& row, double cutoff_hz) {
  const auto& col = row.col;
  Trial ti;
  ti.source = TraceSource::lab;
  ti.filter_cutoff_hz = cutoff_hz;
  for (const auto& fd : trial_fields()) {
    const bool present = col.count(fd.key) && !row.text(fd.key).empty();
    if (fd.text) {
      if (col.count(fd.key)) ti.*fd.text = row.text(fd.key);
    } else if (std::string(fd.key) == "impact_speed_m_s") {
      continue;  // below: it may come from drop_height_m
    } else if (fd.csv_required || present) {
      // bulk density is kept, not used by the models: it may be 0; optional fields are checked
      // where they are used
      ti.*fd.number = row.num(fd.key, fd.csv_required && std::string(fd.key) != "bulk_density_kg_m3");
    }
  }
  if (ti.trial_id.empty()) throw ParseError{{"trials.csv", row.ln, col.at("trial_id") + 1, "column 'trial_id': empty"}};
  if (col.count("drop_height_m") && row.text("impact_speed_m_s").empty()) {
    ti.drop_height_m = row.num("drop_height_m", true);
    ti.impact_speed_m_s = std::sqrt(2.0 * ti.gravity_m_s2 * ti.drop_height_m);
  } else {
    ti.impact_speed_m_s = row.num("impact_speed_m_s", true);
  }
  for (const auto& [name, i] : col) {
    const bool known =
        std::any_of(trial_fields().begin(), trial_fields().end(), [&](const TrialField& fd) { return name == fd.key; });
    if (!known && i < static_cast<int>(row.f.size())) ti.attributes[name] = row.f[i];
  }
  // An explicit source column (`gravsweep export` writes "dem" for DEM drops as CSV traces).
  if (!row.text("source").empty()) {
    try {
      ti.source = trace_source_of(row.text("source"));
    } catch (const std::invalid_argument& e) {
      throw ParseError{{"trials.csv", row.ln, col.at("source") + 1, fmt::format("column 'source': {}", e.what())}};
    }
    ti.attributes.erase("source");
  }
  return ti;
}

/// One row of trials.csv into a trial (numbers checked, the trace read, not processed).
MeasuredTrial read_row(const fs::path& dir, const std::map<std::string, int>& col, const std::vector<std::string>& f,
                       int ln, double cutoff_hz) {
  const RowCells row{col, f, ln};
  MeasuredTrial t;
  t.info = trial_of_row(row, cutoff_hz);
  Trial& ti = t.info;
  const std::string& rel = ti.trace_file;
  const fs::path full = resolve_inside(dir, rel, ln, col.at("trace_file") + 1);
  if (fs::path(rel).extension() == ".h5") {
    // A DEM trace written by `gravsweep run` (results/io/trace_file.h), listed in trials.csv.
    try {
      MeasuredTrial d = read_dem_trial({ti.trial_id, ti.job_id, full});
      t.raw = std::move(d.raw);
      ti.source = TraceSource::dem;
      if (!col.count("filter_cutoff_hz")) ti.filter_cutoff_hz = d.info.filter_cutoff_hz;
      if (!col.count("end_threshold_g")) ti.end_threshold_g = d.info.end_threshold_g;
      if (!col.count("end_speed_fraction")) ti.end_speed_fraction = d.info.end_speed_fraction;
    } catch (const std::exception& e) {
      throw ParseError{{rel, 0, 0, e.what()}};
    }
  } else {
    t.raw = read_trace_csv(full, rel, ti.sample_rate_hz, ln, col.at("sample_rate_hz") + 1, t);
    t.raw.source = ti.source;
    if (ti.source == TraceSource::dem && !row.text("contact_start_s").empty()) {
      double s0;
      if (!parse_double(row.text("contact_start_s"), s0))
        throw ParseError{
            {"trials.csv", ln, col.at("contact_start_s") + 1,
             fmt::format("column 'contact_start_s': expected a finite number, got '{}'", row.text("contact_start_s"))}};
      t.raw.contact_start_s = s0;
    }
  }
  return t;
}

}  // namespace

Campaign load_campaign(const std::string& directory, double cutoff_hz, const ProcessingChoice& processing) {
  Campaign c;
  c.directory = directory;
  const fs::path dir(directory);
  const fs::path csv = dir / "trials.csv";
  std::ifstream in(csv);
  if (!in)
    throw std::runtime_error(
        fmt::format("{}: cannot open (a campaign folder holds trials.csv and "
                    "traces/, see docs/formats/measurements.md)",
                    csv.string()));
  CsvReader reader(in);
  std::vector<std::string> head, f;
  int ln = 0;
  try {
    if (!next_record(reader, head, ln, "trials.csv"))
      throw std::runtime_error(fmt::format("{}:1: empty file, header expected", csv.string()));
  } catch (const ParseError& e) {
    throw std::runtime_error(fmt::format("{}/{}", directory, e.issue.to_string()));
  }
  std::map<std::string, int> col;
  for (int i = 0; i < static_cast<int>(head.size()); ++i) col[head[i]] = i;
  for (const auto& [alias, key] : trial_field_aliases()) {  // an older name, read as the field
    if (!col.count(alias)) continue;
    if (col.count(key))
      throw std::runtime_error(
          fmt::format("{}:{}: columns '{}' and '{}' both name the field {} (the first is its "
                      "older name): keep one",
                      csv.string(), ln, alias, key, key));
    col[key] = col.at(alias);
    col.erase(alias);
  }
  for (const auto& r : required_columns())
    if (!col.count(r)) {
      std::string also;
      for (const auto& [alias, key] : trial_field_aliases())
        if (key == r) also += fmt::format(" (or '{}')", alias);
      throw std::runtime_error(fmt::format("{}:{}: missing required column '{}'{}", csv.string(), ln, r, also));
    }
  std::set<std::string> ids;
  for (;;) {
    try {
      if (!next_record(reader, f, ln, "trials.csv")) break;
    } catch (const ParseError& e) {
      c.issues.push_back(e.issue);
      break;  // the rest of the file cannot be split into records
    }
    try {
      MeasuredTrial t = read_row(dir, col, f, ln, cutoff_hz);
      if (!ids.insert(t.info.trial_id).second)
        throw ParseError{{"trials.csv", ln, col.at("trial_id") + 1,
                          fmt::format("column 'trial_id': '{}' appears twice", t.info.trial_id)}};
      apply_choice(t.info, processing);
      try {
        process_trial(t);
      } catch (const TraceError& e) {
        throw ParseError{issue_of(t, e)};
      } catch (const std::invalid_argument& e) {
        throw ParseError{{t.info.trace_file, 0, 0, e.what()}};
      }
      c.trials.push_back(std::move(t));
    } catch (const ParseError& e) {
      ImportIssue is = e.issue;
      if (is.file != "trials.csv") is.message += fmt::format(" (trial on trials.csv line {})", ln);
      c.issues.push_back(is);
    }
  }
  if (c.trials.empty() && c.issues.empty())
    c.issues.push_back({"trials.csv", ln, 0, "no trial rows: one row per trial after the header expected"});
  return c;
}

}  // namespace gravsweep::results
