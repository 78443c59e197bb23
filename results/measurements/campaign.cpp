// Processing and storing measurement campaigns (see campaign.h).
#include "results/measurements/campaign.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "db/database.h"

namespace gravsweep::results {

namespace fs = std::filesystem;

std::string ImportIssue::to_string() const {
  if (line > 0 && column > 0) return fmt::format("{}:{}:{}: {}", file, line, column, message);
  if (line > 0) return fmt::format("{}:{}: {}", file, line, message);
  return fmt::format("{}: {}", file, message);
}

std::vector<double> Campaign::gravity_levels() const {
  std::vector<double> g;
  for (const auto& t : trials) g.push_back(t.info.gravity_m_s2);
  return gravity_levels_of(g);
}

void process_trial(MeasuredTrial& t) {
  t.raw.source = t.info.source;
  const MetricOptions o = metric_options(t.info);
  t.processed = process_trace(t.raw, o);
  // Fit window: inside the collision, two filter edge widths clear of contact and stop.
  const auto& p = t.processed;
  const std::size_t w = 2 * (1 + static_cast<std::size_t>(std::ceil(p.sample_rate_hz / o.cutoff_hz)));
  t.fit_begin = p.i_start + 1 + w;
  t.fit_end = p.i_end > w ? p.i_end - w : 0;
  if (t.fit_end < t.fit_begin + 3) {
    // Short collision: keep what lies inside it.
    t.fit_begin = p.i_start + 1;
    t.fit_end = std::max(t.fit_begin, p.i_end);
  }
}

namespace {

/// The trials table: fixed columns, then one per field of trial_fields() (added to a table made
/// by an older gravsweep).
void ensure_trial_tables(db::Database& db) {
  db.exec(R"(
CREATE TABLE IF NOT EXISTS trials (
  trial_id TEXT PRIMARY KEY, campaign_dir TEXT, attributes_json TEXT,
  imported_at TEXT DEFAULT (datetime('now')));
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
  std::set<std::string> have;
  {
    db::Statement q(db, "SELECT name FROM pragma_table_info('trials')");
    while (q.step()) have.insert(q.get_text(0));
  }
  auto add = [&](const std::string& name, const char* type) {
    if (have.insert(name).second) db.exec(fmt::format("ALTER TABLE trials ADD COLUMN \"{}\" {}", name, type));
  };
  add("source", "TEXT");
  for (const auto& f : trial_fields()) add(f.key, f.number ? "REAL" : "TEXT");
}

}  // namespace

int store_campaign(db::Database& db, const Campaign& c) {
  ensure_trial_tables(db);
  db::Transaction tx(db);
  db::Statement del(db, "DELETE FROM trials WHERE trial_id = ?");
  std::string names = "campaign_dir, attributes_json, source", marks = "?, ?, ?";
  for (const auto& f : trial_fields()) {
    names += fmt::format(", \"{}\"", f.key);
    marks += ", ?";
  }
  db::Statement ins(db, fmt::format("INSERT INTO trials ({}) VALUES ({})", names, marks));
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
    ins.reset();
    ins.bind(1, c.directory).bind(2, nlohmann::json(i.attributes).dump()).bind(3, to_string(i.source));
    int k = 4;
    for (const auto& f : trial_fields()) {
      if (f.number)
        ins.bind(k++, i.*f.number);
      else
        ins.bind(k++, i.*f.text);
    }
    ins.run();
    const auto& p = t.processed;
    for (std::size_t s = 0; s < p.t_s.size(); ++s) {
      smp.reset();
      smp.bind(1, i.trial_id)
          .bind(2, static_cast<std::int64_t>(s))
          .bind(3, p.t_s[s])
          .bind(4, t.raw.accel_up_m_s2[s])
          .bind(5, p.accel_up_m_s2[s])
          .bind(6, p.velocity_down_m_s[s])
          .bind(7, p.depth_m[s]);
      smp.run();
    }
    const auto& m = p.metrics;
    met.reset();
    met.bind(1, i.trial_id)
        .bind(2, m.vc_m_s)
        .bind(3, m.apeak_m_s2)
        .bind(4, m.zstop_m)
        .bind(5, m.tstop_s)
        .bind(6, m.t_start_s)
        .bind(7, m.t_end_s)
        .bind(8, m.rebound ? 1 : 0)
        .bind(9, p.bias_m_s2)
        .bind(10, m.note)
        .bind(11, static_cast<std::int64_t>(p.i_start))
        .bind(12, static_cast<std::int64_t>(p.i_end))
        .bind(13, static_cast<std::int64_t>(t.fit_begin))
        .bind(14, static_cast<std::int64_t>(t.fit_end))
        .bind(15, p.sample_rate_hz);
    met.run();
    ++stored;
  }
  tx.commit();
  return stored;
}

namespace {

/// The trial's fields from a row of `SELECT t.* ...` (columns by name; absent ones keep defaults).
Trial trial_of_row(db::Statement& q, const std::vector<std::string>& cols) {
  nlohmann::json j = nlohmann::json::object();
  for (int c = 0; c < static_cast<int>(cols.size()); ++c) {
    if (q.is_null(c)) continue;
    const auto& name = cols[static_cast<std::size_t>(c)];
    const auto it =
        std::find_if(trial_fields().begin(), trial_fields().end(), [&](const TrialField& f) { return name == f.key; });
    if (it != trial_fields().end()) {
      if (it->number)
        j[name] = q.get_double(c);
      else
        j[name] = q.get_text(c);
    } else if (name == "source") {
      j["source"] = q.get_text(c);
    } else if (name == "attributes_json") {
      j["attributes"] = nlohmann::json::parse(q.get_text(c), nullptr, false);
      if (!j["attributes"].is_object()) j.erase("attributes");
    }
  }
  return j.get<Trial>();
}

}  // namespace

Campaign load_campaign_db(db::Database& db) {
  Campaign c;
  c.directory = db.path();
  std::vector<std::string> cols;
  {
    db::Statement q(db, "SELECT name FROM pragma_table_info('trials')");
    while (q.step()) cols.push_back(q.get_text(0));
  }
  std::string sel;
  for (const auto& n : cols) sel += fmt::format("{}t.\"{}\"", sel.empty() ? "" : ", ", n);
  db::Statement q(db, fmt::format("SELECT {}, m.vc_m_s, m.apeak_m_s2, m.zstop_m, m.tstop_s, m.t_start_s, m.t_end_s, "
                                  "m.rebound, m.bias_m_s2, m.note, m.i_start, m.i_end, m.fit_begin, m.fit_end, "
                                  "m.processed_rate_hz FROM trials t JOIN trial_metrics m USING (trial_id) "
                                  "ORDER BY t.rowid",
                                  sel));
  db::Statement smp(db,
                    "SELECT t_s, accel_raw_m_s2, accel_filtered_m_s2, velocity_m_s, depth_m FROM trial_samples "
                    "WHERE trial_id = ? ORDER BY sample");
  const int b = static_cast<int>(cols.size());
  const int dir_col = static_cast<int>(std::find(cols.begin(), cols.end(), "campaign_dir") - cols.begin());
  while (q.step()) {
    MeasuredTrial t;
    t.info = trial_of_row(q, cols);
    const auto& i = t.info;
    auto& p = t.processed;
    auto& m = p.metrics;
    m.vc_m_s = q.get_double(b);
    m.apeak_m_s2 = q.get_double(b + 1);
    m.zstop_m = q.get_double(b + 2);
    m.tstop_s = q.get_double(b + 3);
    m.t_start_s = q.get_double(b + 4);
    m.t_end_s = q.get_double(b + 5);
    m.rebound = q.get_int(b + 6) != 0;
    p.bias_m_s2 = q.get_double(b + 7);
    m.note = q.is_null(b + 8) ? "" : q.get_text(b + 8);
    if (q.is_null(b + 9) || q.is_null(b + 11))
      throw std::runtime_error(
          fmt::format("{}: trial '{}' was imported by an older gravsweep without fit "
                      "windows; import the campaign again",
                      db.path(), i.trial_id));
    p.i_start = static_cast<std::size_t>(q.get_int(b + 9));
    p.i_end = static_cast<std::size_t>(q.get_int(b + 10));
    t.fit_begin = static_cast<std::size_t>(q.get_int(b + 11));
    t.fit_end = static_cast<std::size_t>(q.get_int(b + 12));
    p.sample_rate_hz = q.get_double(b + 13);
    if (c.directory == db.path() && dir_col < b && !q.is_null(dir_col)) c.directory = q.get_text(dir_col);
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
    t.raw.source = i.source;
    if (t.fit_end > p.t_s.size() || t.fit_begin > t.fit_end)
      throw std::runtime_error(fmt::format("{}: trial '{}': fit window [{}, {}) outside its {} samples", db.path(),
                                           i.trial_id, t.fit_begin, t.fit_end, p.t_s.size()));
    c.trials.push_back(std::move(t));
  }
  return c;
}

Campaign load_campaign_any(const std::string& path, double cutoff_hz) {
  if (fs::is_regular_file(path)) {
    db::Database db(path, 30000, true);
    Campaign c = load_campaign_db(db);
    if (c.trials.empty()) throw std::runtime_error(fmt::format("{}: no imported trials", path));
    return c;
  }
  return load_campaign(path, cutoff_hz);
}

}  // namespace gravsweep::results
