// A campaign in SQLite (see campaign.h): trials, their metrics, and their samples stored once per
// content. A raw record (t_s, accel_raw_m_s2) is a row of `traces` named by its SHA-256 with its
// samples in `trace_samples`; the processed arrays (filtered acceleration, velocity, depth) are a
// row of `processed_traces` with `processed_samples`, likewise. A trial names both (trials.trace_id,
// trials.processed_id), so trials that share a trace file share its rows: five trials of one
// 93 MB trace store it once, not five times. The view `trial_samples` gives the per-trial rows of
// the layout before (one table `trial_samples`), which a database written by an older gravsweep
// still holds: it is read as it is, and moved to the shared layout when a campaign is stored into it.
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <set>
#include <stdexcept>

#include "db/database.h"
#include "results/measurements/campaign.h"
#include "results/processing/metric_fields.h"
#include "spec/sha256.h"

namespace gravsweep::results {

namespace {

/// Samples of one trial as stored: raw (t, a) and processed (a filtered, v, z).
struct StoredSamples {
  std::vector<double> t_s, raw, filtered, velocity, depth;
};

/// The processing figures stored beside the metrics in trial_metrics: what a fit needs to use a
/// stored trial without processing it again (the removed bias, the collision's sample window,
/// the fit window, the processed rate). `required`: a row without it was written by an older
/// gravsweep and must be imported again.
struct ProcessingColumn {
  const char* key;
  const char* sql_type;
  bool required;
  void (*bind)(db::Statement&, int, const MeasuredTrial&);
  void (*read)(db::Statement&, int, MeasuredTrial&);
};
std::size_t as_index(std::int64_t v) { return static_cast<std::size_t>(v); }
const ProcessingColumn kProcessingColumns[] = {
    {"bias_m_s2", "REAL", false,
     [](db::Statement& s, int k, const MeasuredTrial& t) { s.bind(k, t.processed.bias_m_s2); },
     [](db::Statement& q, int c, MeasuredTrial& t) { t.processed.bias_m_s2 = q.get_double(c); }},
    {"i_start", "INTEGER", true,
     [](db::Statement& s, int k, const MeasuredTrial& t) { s.bind(k, static_cast<std::int64_t>(t.processed.i_start)); },
     [](db::Statement& q, int c, MeasuredTrial& t) { t.processed.i_start = as_index(q.get_int(c)); }},
    {"i_end", "INTEGER", true,
     [](db::Statement& s, int k, const MeasuredTrial& t) { s.bind(k, static_cast<std::int64_t>(t.processed.i_end)); },
     [](db::Statement& q, int c, MeasuredTrial& t) { t.processed.i_end = as_index(q.get_int(c)); }},
    {"fit_begin", "INTEGER", true,
     [](db::Statement& s, int k, const MeasuredTrial& t) { s.bind(k, static_cast<std::int64_t>(t.fit_begin)); },
     [](db::Statement& q, int c, MeasuredTrial& t) { t.fit_begin = as_index(q.get_int(c)); }},
    {"fit_end", "INTEGER", true,
     [](db::Statement& s, int k, const MeasuredTrial& t) { s.bind(k, static_cast<std::int64_t>(t.fit_end)); },
     [](db::Statement& q, int c, MeasuredTrial& t) { t.fit_end = as_index(q.get_int(c)); }},
    {"processed_rate_hz", "REAL", false,
     [](db::Statement& s, int k, const MeasuredTrial& t) { s.bind(k, t.processed.sample_rate_hz); },
     [](db::Statement& q, int c, MeasuredTrial& t) { t.processed.sample_rate_hz = q.get_double(c); }},
};

StoredSamples samples_of(const MeasuredTrial& t) {
  const auto& p = t.processed;
  const std::size_t n = p.t_s.size();
  return {p.t_s, std::vector<double>(t.raw.accel_up_m_s2.begin(), t.raw.accel_up_m_s2.begin() + n), p.accel_up_m_s2,
          p.velocity_down_m_s, p.depth_m};
}

/// SHA-256 of the columns' doubles (their bytes, in order, after a tag naming the layout).
std::string content_hash(const char* tag, const std::vector<const std::vector<double>*>& cols) {
  spec::Sha256 h;
  h.update(tag, std::char_traits<char>::length(tag));
  for (const auto* c : cols) {
    const std::uint64_t n = c->size();
    h.update(&n, sizeof n);
    h.update(c->data(), c->size() * sizeof(double));
  }
  return h.hex_digest();
}

/// The columns of a table (empty when it does not exist).
std::vector<std::string> columns_of(db::Database& db, const char* table) {
  std::vector<std::string> cols;
  db::Statement q(db, "SELECT name FROM pragma_table_info(?)");
  q.bind(1, table);
  while (q.step()) cols.push_back(q.get_text(0));
  return cols;
}

/// Stores content-addressed sample rows: the id of the row of `table` whose sha256 is `hash`,
/// inserting it and its samples when absent. `table` and `samples` name the tables, `cols` the
/// sample columns after (id, sample).
class ContentStore {
 public:
  ContentStore(db::Database& db, const std::string& table, const std::string& id, const std::string& samples,
               const std::vector<std::string>& cols)
      : find_(db, fmt::format("SELECT {} FROM {} WHERE sha256 = ?", id, table)),
        add_(db, fmt::format("INSERT INTO {} (sha256, samples) VALUES (?, ?)", table)),
        rowid_(db, "SELECT last_insert_rowid()"),
        sample_(db, insert_samples(samples, id, cols)) {}

  std::int64_t put(const std::string& hash, const std::vector<const std::vector<double>*>& cols) {
    find_.reset();
    find_.bind(1, hash);
    if (find_.step()) return find_.get_int(0);
    const std::size_t n = cols.front()->size();
    add_.reset();
    add_.bind(1, hash).bind(2, static_cast<std::int64_t>(n)).run();
    rowid_.reset();
    rowid_.step();
    const std::int64_t id = rowid_.get_int(0);
    for (std::size_t s = 0; s < n; ++s) {
      sample_.reset();
      sample_.bind(1, id).bind(2, static_cast<std::int64_t>(s));
      for (std::size_t c = 0; c < cols.size(); ++c) sample_.bind(static_cast<int>(c) + 3, (*cols[c])[s]);
      sample_.run();
    }
    return id;
  }

 private:
  static std::string insert_samples(const std::string& samples, const std::string& id,
                                    const std::vector<std::string>& cols) {
    std::string names = id + ", sample", marks = "?, ?";
    for (const auto& c : cols) names += ", " + c, marks += ", ?";
    return fmt::format("INSERT INTO {} ({}) VALUES ({})", samples, names, marks);
  }
  db::Statement find_, add_, rowid_, sample_;
};

constexpr const char* kRawTag = "gravsweep-trace/1 t_s accel_raw_m_s2\n";
constexpr const char* kProcessedTag = "gravsweep-processed/1 accel_filtered_m_s2 velocity_m_s depth_m\n";

/// The ids of a trial's raw and processed samples, stored when new.
std::pair<std::int64_t, std::int64_t> put_samples(ContentStore& raw, ContentStore& processed, const StoredSamples& s) {
  const std::vector<const std::vector<double>*> r{&s.t_s, &s.raw}, p{&s.filtered, &s.velocity, &s.depth};
  return {raw.put(content_hash(kRawTag, r), r), processed.put(content_hash(kProcessedTag, p), p)};
}

ContentStore raw_store(db::Database& db) {
  return ContentStore(db, "traces", "trace_id", "trace_samples", {"t_s", "accel_raw_m_s2"});
}
ContentStore processed_store(db::Database& db) {
  return ContentStore(db, "processed_traces", "processed_id", "processed_samples",
                      {"accel_filtered_m_s2", "velocity_m_s", "depth_m"});
}

/// A database of the layout before (a table trial_samples with every trial's own rows): each
/// trial's samples moved to the shared tables, the old table dropped (one transaction).
void migrate_trial_samples(db::Database& db) {
  db::Transaction tx(db);
  std::vector<std::string> ids;
  {
    db::Statement q(db, "SELECT trial_id FROM trials");
    while (q.step()) ids.push_back(q.get_text(0));
  }
  {  // the statements end before the table is dropped (SQLite refuses to drop a table being read)
    ContentStore raw = raw_store(db), processed = processed_store(db);
    db::Statement rows(db,
                       "SELECT t_s, accel_raw_m_s2, accel_filtered_m_s2, velocity_m_s, depth_m FROM trial_samples "
                       "WHERE trial_id = ? ORDER BY sample");
    db::Statement set(db, "UPDATE trials SET trace_id = ?, processed_id = ? WHERE trial_id = ?");
    for (const auto& id : ids) {
      StoredSamples s;
      rows.reset();
      rows.bind(1, id);
      std::vector<double>* const into[] = {&s.t_s, &s.raw, &s.filtered, &s.velocity, &s.depth};
      while (rows.step())
        for (int col = 0; col < 5; ++col) into[col]->push_back(rows.get_double(col));
      const auto [r, p] = put_samples(raw, processed, s);
      set.reset();
      set.bind(1, r).bind(2, p).bind(3, id).run();
    }
  }
  db.exec("DROP TABLE trial_samples");
  tx.commit();
}

/// The tables (created when missing, new columns added to a table of an older gravsweep, its
/// per-trial samples moved to the shared tables).
void ensure_trial_tables(db::Database& db) {
  db.exec(R"(
CREATE TABLE IF NOT EXISTS trials (
  trial_id TEXT PRIMARY KEY, campaign_dir TEXT, attributes_json TEXT,
  imported_at TEXT DEFAULT (datetime('now')));
CREATE TABLE IF NOT EXISTS traces (trace_id INTEGER PRIMARY KEY, sha256 TEXT NOT NULL UNIQUE, samples INTEGER);
CREATE TABLE IF NOT EXISTS trace_samples (
  trace_id INTEGER NOT NULL, sample INTEGER NOT NULL, t_s REAL, accel_raw_m_s2 REAL,
  PRIMARY KEY (trace_id, sample)) WITHOUT ROWID;
CREATE TABLE IF NOT EXISTS processed_traces (
  processed_id INTEGER PRIMARY KEY, sha256 TEXT NOT NULL UNIQUE, samples INTEGER);
CREATE TABLE IF NOT EXISTS processed_samples (
  processed_id INTEGER NOT NULL, sample INTEGER NOT NULL, accel_filtered_m_s2 REAL, velocity_m_s REAL, depth_m REAL,
  PRIMARY KEY (processed_id, sample)) WITHOUT ROWID;
CREATE TABLE IF NOT EXISTS trial_metrics (
  trial_id TEXT PRIMARY KEY REFERENCES trials(trial_id) ON DELETE CASCADE);
)");
  auto adder = [&db](const char* table) {
    const auto cols = columns_of(db, table);
    return [&db, table, have = std::set<std::string>(cols.begin(), cols.end())](const std::string& name,
                                                                                const char* type) mutable {
      if (have.insert(name).second) db.exec(fmt::format("ALTER TABLE {} ADD COLUMN \"{}\" {}", table, name, type));
    };
  };
  auto add = adder("trials");
  add("source", "TEXT");
  add("trace_id", "INTEGER");
  add("processed_id", "INTEGER");
  for (const auto& f : trial_fields()) add(f.key, f.number ? "REAL" : "TEXT");
  auto add_metric = adder("trial_metrics");
  for (const auto& f : metric_fields()) add_metric(f.key, f.sql_type());
  for (const auto& c : kProcessingColumns) add_metric(c.key, c.sql_type);
  if (db::has_table(db, "trial_samples")) migrate_trial_samples(db);
  db.exec(R"(
CREATE VIEW IF NOT EXISTS trial_samples AS
  SELECT t.trial_id, s.sample, s.t_s, s.accel_raw_m_s2, p.accel_filtered_m_s2, p.velocity_m_s, p.depth_m
  FROM trials t JOIN trace_samples s ON s.trace_id = t.trace_id
  JOIN processed_samples p ON p.processed_id = t.processed_id AND p.sample = s.sample;
)");
}

/// Samples no trial names any more (a trial replaced by a re-import) are removed.
void remove_unused_samples(db::Database& db) {
  db.exec(R"(
DELETE FROM trace_samples WHERE trace_id IN
  (SELECT trace_id FROM traces WHERE trace_id NOT IN (SELECT trace_id FROM trials WHERE trace_id IS NOT NULL));
DELETE FROM traces WHERE trace_id NOT IN (SELECT trace_id FROM trials WHERE trace_id IS NOT NULL);
DELETE FROM processed_samples WHERE processed_id IN
  (SELECT processed_id FROM processed_traces
   WHERE processed_id NOT IN (SELECT processed_id FROM trials WHERE processed_id IS NOT NULL));
DELETE FROM processed_traces WHERE processed_id NOT IN (SELECT processed_id FROM trials WHERE processed_id IS NOT NULL);
)");
}

/// "vc_m_s, ..., processed_rate_hz": the metric and processing columns of trial_metrics, in the
/// order insert_metrics binds and read_metrics reads them (`prefix` before each name).
/// `present`: the columns the table has (a database of an older gravsweep may lack some; they read
/// as NULL), or nullptr for all of them.
std::string metric_columns(const char* prefix, const std::set<std::string>* present = nullptr) {
  std::string out;
  auto add = [&](const char* key) {
    const bool has = !present || present->count(key);
    out += fmt::format("{}{}", out.empty() ? "" : ", ", has ? fmt::format("{}\"{}\"", prefix, key) : "NULL");
  };
  for (const auto& f : metric_fields()) add(f.key);
  for (const auto& c : kProcessingColumns) add(c.key);
  return out;
}

std::size_t metric_column_count() { return metric_fields().size() + std::size(kProcessingColumns); }

void insert_metrics(db::Statement& met, const MeasuredTrial& t) {
  const auto& m = t.processed.metrics;
  met.reset();
  met.bind(1, t.info.trial_id);
  int k = 2;
  for (const auto& f : metric_fields()) {
    if (f.number)
      met.bind(k++, m.*f.number);
    else if (f.flag)
      met.bind(k++, m.*f.flag ? 1 : 0);
    else
      met.bind(k++, m.*f.text);
  }
  for (const auto& c : kProcessingColumns) c.bind(met, k++, t);
  met.run();
}

}  // namespace

int store_campaign(db::Database& db, const Campaign& c) {
  ensure_trial_tables(db);
  db::Transaction tx(db);
  db::Statement del(db, "DELETE FROM trials WHERE trial_id = ?");
  std::string names = "campaign_dir, attributes_json, source, trace_id, processed_id", marks = "?, ?, ?, ?, ?";
  for (const auto& f : trial_fields()) {
    names += fmt::format(", \"{}\"", f.key);
    marks += ", ?";
  }
  db::Statement ins(db, fmt::format("INSERT INTO trials ({}) VALUES ({})", names, marks));
  std::string met_marks = "?";
  for (std::size_t k = 0; k < metric_column_count(); ++k) met_marks += ", ?";
  db::Statement met(db,
                    fmt::format("INSERT INTO trial_metrics (trial_id, {}) VALUES ({})", metric_columns(""), met_marks));
  ContentStore raw = raw_store(db), processed = processed_store(db);
  int stored = 0;
  for (const auto& t : c.trials) {
    const auto& i = t.info;
    del.reset();
    del.bind(1, i.trial_id).run();
    const auto [trace_id, processed_id] = put_samples(raw, processed, samples_of(t));
    ins.reset();
    ins.bind(1, c.directory).bind(2, nlohmann::json(i.attributes).dump()).bind(3, to_string(i.source));
    ins.bind(4, trace_id).bind(5, processed_id);
    int k = 6;
    for (const auto& f : trial_fields()) {
      if (f.number)
        ins.bind(k++, i.*f.number);
      else
        ins.bind(k++, i.*f.text);
    }
    ins.run();
    insert_metrics(met, t);
    ++stored;
  }
  remove_unused_samples(db);
  tx.commit();
  return stored;
}

namespace {

/// The trial's fields from a row of `SELECT t.* ...` (columns by name; absent ones keep defaults).
Trial trial_of_row(db::Statement& q, const std::vector<std::string>& cols) {
  nlohmann::json j = nlohmann::json::object();
  for (int c = 0; c < static_cast<int>(cols.size()); ++c) {
    if (q.is_null(c)) continue;
    const std::string name = trial_field_key(cols[static_cast<std::size_t>(c)]);  // an older column: its field
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

/// The options a stored trial was processed with: its facts' (metric_options) with the cut-off and
/// the hold its metrics record as applied (process_trial's fallback to the fixed scales included).
/// A row without them was imported before they were recorded, when every trial was processed in
/// the paper's fixed scales: the trial's own cut-off and the paper's hold.
MetricOptions stored_options(const MeasuredTrial& t, bool recorded) {
  MetricOptions o = metric_options(t.info);
  const Metrics& m = t.processed.metrics;
  o.cutoff_hz = recorded ? m.cutoff_hz : t.info.filter_cutoff_hz;
  o.end_hold_s = recorded ? m.end_hold_s : kPaperEndHold_s;
  return o;
}

/// The metrics columns of a row, from column b on, in metric_columns() order (null: the default),
/// and the options they record (stored_options).
void read_metrics(db::Database& db, db::Statement& q, int b, MeasuredTrial& t) {
  auto& m = t.processed.metrics;
  int c = b;
  bool recorded = true;  // the cut-off and the hold applied
  for (const auto& f : metric_fields()) {
    if (!q.is_null(c)) {
      if (f.number)
        m.*f.number = q.get_double(c);
      else if (f.flag)
        m.*f.flag = q.get_int(c) != 0;
      else
        m.*f.text = q.get_text(c);
    } else if (f.number == &Metrics::cutoff_hz || f.number == &Metrics::end_hold_s) {
      recorded = false;
    }
    ++c;
  }
  t.options = stored_options(t, recorded);
  for (const auto& col : kProcessingColumns) {
    if (q.is_null(c) && col.required)
      throw std::runtime_error(
          fmt::format("{}: trial '{}' was imported by an older gravsweep without {}; import "
                      "the campaign again",
                      db.path(), t.info.trial_id, col.key));
    if (!q.is_null(c)) col.read(q, c, t);
    ++c;
  }
}

}  // namespace

Campaign load_campaign_db(db::Database& db) {
  Campaign c;
  c.directory = db.path();
  const std::vector<std::string> cols = columns_of(db, "trials");
  std::string sel;
  for (const auto& n : cols) sel += fmt::format("{}t.\"{}\"", sel.empty() ? "" : ", ", n);
  const auto metric_cols = columns_of(db, "trial_metrics");
  const std::set<std::string> stored(metric_cols.begin(), metric_cols.end());
  db::Statement q(db, fmt::format("SELECT {}, {} FROM trials t JOIN trial_metrics m USING (trial_id) ORDER BY t.rowid",
                                  sel, metric_columns("m.", &stored)));
  // The view over the shared tables, or the table of a database written before them: one query.
  db::Statement smp(db,
                    "SELECT t_s, accel_raw_m_s2, accel_filtered_m_s2, velocity_m_s, depth_m FROM trial_samples "
                    "WHERE trial_id = ? ORDER BY sample");
  const int b = static_cast<int>(cols.size());
  const int dir_col = static_cast<int>(std::find(cols.begin(), cols.end(), "campaign_dir") - cols.begin());
  while (q.step()) {
    MeasuredTrial t;
    t.info = trial_of_row(q, cols);
    read_metrics(db, q, b, t);
    const auto& i = t.info;
    auto& p = t.processed;
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

}  // namespace gravsweep::results
