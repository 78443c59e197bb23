// `gravsweep results`: the results table (one column per swept parameter and per metric).
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <algorithm>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "results/measurements/trial.h"
#include "results/processing/metric_fields.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/campaign_options.h"
#include "results/io/table.h"
#include "scheduler/cli/format_option.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/queue/filter.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::cli {

namespace {

struct ResultsOptions {
  std::string db = "campaign.db";
  std::vector<std::string> where;
  std::vector<std::string> columns;
  std::string sweep;
  std::string sort;
  std::string format = "table";
  std::string out;
  std::vector<std::string> group_by;
  long limit = -1;
  bool full = false;
  bool all = false;
};

std::string cell(const nlohmann::json& v, bool for_table, const std::string& col, bool full) {
  if (v.is_null()) return for_table ? "-" : "";
  if (v.is_number_float()) {
    const double d = v.get<double>();
    return for_table ? fmt::format("{:.6g}", d) : fmt::format("{}", d);
  }
  if (v.is_number()) return v.dump();
  std::string s = v.get<std::string>();
  if (for_table && !full && col == "trace_sha256" && s.size() > 12) s = s.substr(0, 12);
  return s;
}

/// stdout, or --out (temporary name, then renamed).
void write_text(const ResultsOptions& o, const std::string& text, std::size_t n, const char* what) {
  if (o.out.empty()) {
    fmt::print("{}", text);
    return;
  }
  const std::string tmp = o.out + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) throw std::runtime_error(fmt::format("--out: cannot write '{}'", tmp));
    f << text;
    if (!f) throw std::runtime_error(fmt::format("--out: write error on '{}'", tmp));
  }
  std::filesystem::rename(tmp, o.out);
  fmt::print(stderr, "{} {} written to {}\n", n, what, o.out);
}

/// `--group-by a,b`: per group of equal keys (gravity columns grouped by results::same_gravity_level,
/// the rule of every verb) the mean, sample standard deviation and count of each metric.
struct Group {
  std::vector<nlohmann::json> key;
  std::size_t rows = 0;
  std::vector<std::vector<double>> values;  ///< per metric, the non-null numbers
};

bool same_key(const nlohmann::json& a, const nlohmann::json& b, const std::string& col) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    return col.rfind("gravity", 0) == 0 ? results::same_gravity_level(x, y) : x == y;
  }
  return a == b;
}

std::vector<std::string> metric_columns(db::Database& db) {
  std::vector<std::string> m;
  db::Statement st(db,
                   "SELECT name FROM results_columns WHERE role='metric' AND sql_type IN ('REAL','INTEGER') "
                   "ORDER BY position");
  while (st.step()) m.push_back(st.get_text(0));
  return m;
}

/// Mean and sample standard deviation (NaN when undefined).
std::pair<double, double> mean_and_std(const std::vector<double>& v) {
  double mean = 0, ss = 0;
  for (double x : v) mean += x;
  mean = v.empty() ? NAN : mean / static_cast<double>(v.size());
  for (double x : v) ss += (x - mean) * (x - mean);
  const double sd = v.size() > 1 ? std::sqrt(ss / static_cast<double>(v.size() - 1)) : NAN;
  return {mean, sd};
}

/// The groups as JSON (per metric an object of mean, std and count) or as one flat row each.
std::string render_groups(const ResultsOptions& o, const std::vector<Group>& groups,
                          const std::vector<std::string>& metrics) {
  const std::size_t nk = o.group_by.size();
  const auto finite = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  if (o.format == "json") {
    std::vector<std::string> cols = o.group_by;
    cols.insert(cols.end(), {"rows", "metrics"});
    results::Table jt(cols);
    for (const auto& g : groups) {
      nlohmann::json ms = nlohmann::json::object();
      for (std::size_t m = 0; m < metrics.size(); ++m) {
        const auto [mean, sd] = mean_and_std(g.values[m]);
        ms[metrics[m]] = {{"mean", finite(mean)}, {"std", finite(sd)}, {"count", g.values[m].size()}};
      }
      std::vector<nlohmann::json> row(g.key.begin(), g.key.end());
      row.insert(row.end(), {nlohmann::json(g.rows), std::move(ms)});
      jt.add_values(std::move(row));
    }
    return jt.json();
  }
  std::vector<std::string> header = o.group_by;
  header.emplace_back("rows");
  for (const auto& m : metrics)
    for (const char* s : {"_mean", "_std", "_count"}) header.push_back(m + s);
  results::Table tt(header, results::kRuledText);
  const bool table = o.format == "table";
  for (const auto& g : groups) {
    std::vector<std::string> cells;
    for (std::size_t k = 0; k < nk; ++k) cells.push_back(cell(g.key[k], table, o.group_by[k], o.full));
    cells.push_back(std::to_string(g.rows));
    for (std::size_t m = 0; m < metrics.size(); ++m) {
      const auto [mean, sd] = mean_and_std(g.values[m]);
      cells.push_back(std::isfinite(mean) ? cell(mean, table, "", o.full) : (table ? "-" : ""));
      cells.push_back(std::isfinite(sd) ? cell(sd, table, "", o.full) : (table ? "-" : ""));
      cells.push_back(std::to_string(g.values[m].size()));
    }
    tt.add(std::move(cells));
  }
  return table ? tt.text() + fmt::format("({} group{})\n", groups.size(), groups.size() == 1 ? "" : "s") : tt.csv();
}

std::string group_text(const ResultsOptions& o, db::Database& db, std::size_t& n_groups) {
  std::vector<std::string> metrics = o.columns;
  if (metrics.empty()) {
    metrics = metric_columns(db);
    if (o.format == "table" && !o.all) {
      std::vector<std::string> paper;
      for (const auto& f : results::metric_fields())
        if (f.headline && f.number && std::find(metrics.begin(), metrics.end(), f.key) != metrics.end())
          paper.emplace_back(f.key);
      metrics = paper;
    }
  }
  std::vector<std::string> cols = o.group_by;
  cols.insert(cols.end(), metrics.begin(), metrics.end());
  queue::ResultsTable t;
  try {
    t = queue::query_results(db, queue::ResultsQuery{o.where, cols, o.sweep, "", -1});
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  const std::size_t nk = o.group_by.size();
  std::vector<Group> groups;
  for (const auto& r : t.rows) {
    Group* g = nullptr;
    for (auto& x : groups) {
      bool eq = true;
      for (std::size_t k = 0; k < nk && eq; ++k) eq = same_key(x.key[k], r[k], o.group_by[k]);
      if (eq) g = &x;
    }
    if (!g) {
      groups.push_back({std::vector<nlohmann::json>(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(nk)), 0,
                        std::vector<std::vector<double>>(metrics.size())});
      g = &groups.back();
    }
    ++g->rows;
    for (std::size_t m = 0; m < metrics.size(); ++m)
      if (r[nk + m].is_number()) g->values[m].push_back(r[nk + m].get<double>());
  }
  std::stable_sort(groups.begin(), groups.end(), [&](const Group& a, const Group& b) {
    for (std::size_t k = 0; k < nk; ++k) {
      if (same_key(a.key[k], b.key[k], o.group_by[k])) continue;
      if (a.key[k].is_number() && b.key[k].is_number()) return a.key[k].get<double>() < b.key[k].get<double>();
      return a.key[k].dump() < b.key[k].dump();
    }
    return false;
  });
  n_groups = groups.size();
  return render_groups(o, groups, metrics);
}

void run_results(const ResultsOptions& o) {
  db::Database db = queue::open_campaign(o.db, queue::OpenMode::read);
  if (!o.group_by.empty()) {
    std::size_t n = 0;
    const std::string text = group_text(o, db, n);
    write_text(o, text, n, "groups");
    return;
  }
  // A table shows the swept parameters and the paper's metrics unless asked for more; CSV and JSON
  // exports carry every column.
  const bool summary = o.format == "table" && o.columns.empty() && !o.all;
  const std::vector<std::string> columns =
      summary ? queue::summary_result_columns(db, results::headline_metric_keys()) : o.columns;
  queue::ResultsQuery q{o.where, columns, o.sweep, o.sort, o.limit};
  queue::ResultsTable t;
  try {
    t = queue::query_results(db, q);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  results::Table tt(t.columns, results::kRuledText);
  for (const auto& r : t.rows) {
    if (o.format != "table") {  // CSV and JSON: the values as stored (null: an empty CSV cell)
      tt.add_values(r);
      continue;
    }
    std::vector<std::string> cells;
    for (std::size_t c = 0; c < r.size(); ++c) cells.push_back(cell(r[c], true, t.columns[c], o.full));
    tt.add(std::move(cells));
  }
  std::string text = tt.render(o.format);
  if (o.format == "table") {
    text += fmt::format("({} row{})\n", t.rows.size(), t.rows.size() == 1 ? "" : "s");
    if (summary) {
      const std::size_t more = queue::result_columns(db).size() - t.columns.size();
      text += fmt::format("({} more columns: --all, --columns a,b,... or --format csv)\n", more);
    }
  }
  write_text(o, text, t.rows.size(), "rows");
}

}  // namespace

void setup_results(CLI::App& app) {
  auto opt = std::make_shared<ResultsOptions>();
  auto* sub = app.add_subcommand(
      "results",
      "Print the results table: one row per finished drop, with one column per swept parameter and\n"
      "per metric (units in the names), the trace path and its SHA-256. As a table it shows the\n"
      "job, the swept parameters and the paper's metrics (vc, apeak, zstop, tstop, rebound) unless\n"
      "--all or --columns asks for more; CSV and JSON carry every column. Filters are parsed and bound\n"
      "as SQL parameters (never pasted into SQL): column op value, joined by 'and' or ','; op is one\n"
      "of < <= > >= = != ~ (text contains). A column of numbers compares with a finite number only\n"
      "(anything else, nan and inf are refused, exit 2); a text column with the text as typed; ~ looks\n"
      "for the text in the column's text form. The same on SQLite and PostgreSQL. Several --where are ANDed.\n\n"
      "Examples:\n"
      "  gravsweep results --db campaign.db\n"
      "  gravsweep results --db campaign.db --where 'gravity_m_s2<1' --format csv --out low_g.csv\n"
      "  gravsweep results --db campaign.db --where 'gravity_m_s2>=1 and speed_m_s=2' --format json\n"
      "  gravsweep results --db campaign.db --columns gravity_m_s2,apeak_m_s2 --sort gravity_m_s2\n"
      "  gravsweep results --db campaign.db --group-by gravity_m_s2,impact_speed_m_s\n\n"
      "--group-by: one row per group of equal values (gravity levels equal to a relative 1e-6), with\n"
      "the number of rows and each metric's mean, sample standard deviation and count of values (the\n"
      "paper's error bars over repeats); the table shows vc, apeak, zstop and tstop unless --all or\n"
      "--columns names the metrics; CSV and JSON carry every numeric metric.");
  add_campaign_options(sub, opt->db, nullptr);
  sub->add_option("--where", opt->where, "filter, e.g. 'gravity_m_s2<1' (repeatable)");
  sub->add_option("--columns", opt->columns, "columns to show, comma separated")->delimiter(',');
  sub->add_option("--sweep", opt->sweep, "only this sweep");
  sub->add_option("--sort", opt->sort, "order by this column");
  sub->add_option("--group-by", opt->group_by, "group by these columns, comma separated: mean, std, count per metric")
      ->delimiter(',');
  sub->add_option("--limit", opt->limit, "at most this many rows");
  add_format_option(sub, opt->format);
  sub->add_option("--out", opt->out, "write to this file (temporary name, then renamed) instead of stdout");
  sub->add_flag("--full", opt->full, "table: do not shorten checksums");
  sub->add_flag("--all", opt->all, "table: every column, not only the parameters and the paper's metrics");
  sub->callback([opt]() { run_results(*opt); });
}

}  // namespace gravsweep::cli
