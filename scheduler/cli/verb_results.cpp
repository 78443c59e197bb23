// `gravsweep results`: the results table (one column per swept parameter and per metric).
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/queue/filter.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/table.h"

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

void run_results(const ResultsOptions& o) {
  db::Database db = queue::open_campaign(o.db, queue::OpenMode::read);
  // A table shows the swept parameters and the paper's metrics unless asked for more; CSV and JSON
  // exports carry every column.
  const bool summary = o.format == "table" && o.columns.empty() && !o.all;
  const std::vector<std::string> columns = summary ? queue::summary_result_columns(db) : o.columns;
  queue::ResultsQuery q{o.where, columns, o.sweep, o.sort, o.limit};
  queue::ResultsTable t;
  try {
    t = queue::query_results(db, q);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  std::string text;
  if (o.format == "json") {
    nlohmann::json arr = nlohmann::json::array();
    for (const auto& r : t.rows) {
      nlohmann::json obj = nlohmann::json::object();
      for (std::size_t c = 0; c < t.columns.size(); ++c) obj[t.columns[c]] = r[c];
      arr.push_back(std::move(obj));
    }
    text = arr.dump(2) + "\n";
  } else {
    queue::TextTable tt;
    tt.header = t.columns;
    for (const auto& r : t.rows) {
      std::vector<std::string> cells;
      for (std::size_t c = 0; c < r.size(); ++c) cells.push_back(cell(r[c], o.format == "table", t.columns[c], o.full));
      tt.rows.push_back(std::move(cells));
    }
    text = o.format == "csv" ? queue::render_csv(tt)
                             : queue::render_table(tt) + fmt::format("({} row{})\n", t.rows.size(), t.rows.size() == 1 ? "" : "s");
    if (summary) {
      const std::size_t more = queue::result_columns(db).size() - t.columns.size();
      text += fmt::format("({} more columns: --all, --columns a,b,... or --format csv)\n", more);
    }
  }
  if (o.out.empty()) {
    fmt::print("{}", text);
  } else {
    const std::string tmp = o.out + ".tmp";
    {
      std::ofstream f(tmp, std::ios::binary);
      if (!f) throw std::runtime_error(fmt::format("--out: cannot write '{}'", tmp));
      f << text;
      if (!f) throw std::runtime_error(fmt::format("--out: write error on '{}'", tmp));
    }
    std::filesystem::rename(tmp, o.out);
    fmt::print(stderr, "{} rows written to {}\n", t.rows.size(), o.out);
  }
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
      "of < <= > >= = != ~ (text contains). Several --where are ANDed.\n\n"
      "Examples:\n"
      "  gravsweep results --db campaign.db\n"
      "  gravsweep results --db campaign.db --where 'gravity_m_s2<1' --format csv --out low_g.csv\n"
      "  gravsweep results --db campaign.db --where 'gravity_m_s2>=1 and speed_m_s=2' --format json\n"
      "  gravsweep results --db campaign.db --columns gravity_m_s2,apeak_m_s2 --sort gravity_m_s2");
  sub->add_option("--db", opt->db, "campaign database")->capture_default_str();
  sub->add_option("--where", opt->where, "filter, e.g. 'gravity_m_s2<1' (repeatable)");
  sub->add_option("--columns", opt->columns, "columns to show, comma separated")->delimiter(',');
  sub->add_option("--sweep", opt->sweep, "only this sweep");
  sub->add_option("--sort", opt->sort, "order by this column");
  sub->add_option("--limit", opt->limit, "at most this many rows");
  sub->add_option("--format", opt->format, "table, csv or json")->check(CLI::IsMember({"table", "csv", "json"}))->capture_default_str();
  sub->add_option("--out", opt->out, "write to this file (temporary name, then renamed) instead of stdout");
  sub->add_flag("--full", opt->full, "table: do not shorten checksums");
  sub->add_flag("--all", opt->all, "table: every column, not only the parameters and the paper's metrics");
  sub->callback([opt]() { run_results(*opt); });
}

}  // namespace gravsweep::cli
