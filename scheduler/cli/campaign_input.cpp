#include "scheduler/cli/campaign_input.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>

#include "db/database.h"
#include "results/processing/metric_fields.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/filter.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::cli {

namespace fs = std::filesystem;

namespace {

bool has_table(db::Database& db, const char* name) {
  db::Statement q(db, "SELECT 1 FROM sqlite_master WHERE type='table' AND name=?");
  q.bind(1, name);
  return q.step();
}

/// Every finished drop of a campaign database (filtered on its results table) as a DEM trial.
CampaignInput load_queue_campaign(const std::string& path, db::Database& db, const std::vector<std::string>& where,
                                  const std::string& files) {
  CampaignInput in;
  in.kind = "campaign database (submit/work)";
  queue::ResultsQuery q;
  q.where = where;
  q.columns = {"job_id", "kind", "trace_path"};
  queue::ResultsTable t;
  try {
    t = queue::query_results(db, q);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("{}: {}", path, e.what()));
  }
  const queue::CampaignPaths paths(path, files);
  std::vector<results::DemTraceRef> refs;
  for (const auto& r : t.rows) {
    if (r[1] != "drop" || !r[2].is_string()) continue;
    const std::string job = r[0].get<std::string>();
    refs.push_back({job, job, paths.abs(r[2].get<std::string>())});
  }
  {
    db::Statement st(
        db, "SELECT state, count(*) FROM jobs WHERE kind='drop' AND state != 'done' GROUP BY state ORDER BY state");
    while (st.step())
      in.note += fmt::format("{}{} drop jobs {}", in.note.empty() ? "" : ", ", st.get_int(1), st.get_text(0));
    if (!in.note.empty()) in.note += " (not finished: not trials yet; `gravsweep work` runs them)";
  }
  in.campaign = results::load_dem_campaign(path, refs);
  return in;
}

/// A trial as the row --where sees outside a campaign database: its fields and its metrics.
nlohmann::json row_of(const results::MeasuredTrial& t) {
  nlohmann::json j = t.info;
  j.erase("attributes");
  for (const auto& [k, v] : t.info.attributes) j[k] = v;
  for (const auto& [alias, key] : results::trial_field_aliases()) j[alias] = j[key];  // older --where names
  const nlohmann::json m = t.processed.metrics;
  for (const auto& f : results::metric_fields())
    if (!f.text) j[f.key] = m[f.key];  // the processing note stays out: a trial may have a "note" column
  return j;
}

/// Refuses a trial whose numbers lie outside physical ranges (an imported file written before
/// `measurements import` checked them, or edited since): a fit on it would be garbage or NaN.
void refuse_unphysical(const std::string& path, const CampaignInput& in) {
  for (const auto& t : in.campaign.trials)
    for (const auto& f : results::trial_fields()) {
      if (!f.number) continue;
      const double v = t.info.*f.number;
      if (const std::string expected = results::out_of_physical_range(f.key, v); !expected.empty())
        throw UsageError(
            fmt::format("{}: trial '{}': {} = {}, expected {} (a wrong unit or a corrupt number; fix the "
                        "record and import it again)",
                        path, t.info.trial_id, f.key, v, expected));
    }
}

void filter_in_memory(const std::string& path, CampaignInput& in, const std::vector<std::string>& where) {
  if (where.empty()) return;
  auto& trials = in.campaign.trials;
  const std::size_t before = trials.size();
  std::vector<results::MeasuredTrial> kept;
  try {
    for (const auto& w : where) queue::parse_where(w);  // a malformed filter fails even on no trials
    for (auto& t : trials)
      if (queue::row_matches(row_of(t), where)) kept.push_back(std::move(t));
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("{}: {}", path, e.what()));
  }
  trials = std::move(kept);
  in.filtered_out = before - trials.size();
}

}  // namespace

CampaignInput load_campaign_input(const std::string& path, const std::vector<std::string>& where, double cutoff_hz,
                                  const std::string& files) {
  CampaignInput in;
  try {
    if (db::is_postgres_url(path)) {
      db::Database db = queue::open_campaign(path, queue::OpenMode::read, files);  // refuses a non-campaign
      in = load_queue_campaign(path, db, where, files);
      refuse_unphysical(path, in);
      return in;
    }
    if (fs::is_directory(path)) {
      in.kind = "lab campaign folder";
      in.campaign = results::load_campaign(path, cutoff_hz);
    } else if (fs::is_regular_file(path)) {
      if (fs::file_size(path) == 0)
        throw UsageError(
            fmt::format("{}: an empty file: a campaign database, an imported SQLite file or a lab "
                        "campaign folder expected",
                        path));
      db::Database db(path, 30000, true);
      if (has_table(db, "jobs") && has_table(db, "results")) {
        in = load_queue_campaign(path, db, where, files);
        refuse_unphysical(path, in);
        return in;
      }
      if (!has_table(db, "trials"))
        throw UsageError(
            fmt::format("{}: neither a campaign database (tables jobs, results) nor an imported "
                        "SQLite file (table trials)",
                        path));
      in.kind = "imported SQLite file";
      in.campaign = results::load_campaign_db(db);
    } else {
      throw UsageError(
          fmt::format("{}: no such file or folder: a campaign database, an imported SQLite file or "
                      "a lab campaign folder expected",
                      path));
    }
  } catch (const UsageError&) {
    throw;
  } catch (const db::DbError& e) {
    throw UsageError(fmt::format("{}: not a readable campaign ({})", path, e.what()));
  } catch (const std::runtime_error& e) {
    throw UsageError(e.what());
  }
  refuse_unphysical(path, in);
  filter_in_memory(path, in, where);
  return in;
}

CampaignInput load_campaign_inputs(const std::vector<std::string>& paths, const std::vector<std::string>& where,
                                   double cutoff_hz, const std::string& files) {
  if (paths.size() == 1) {
    auto in = load_campaign_input(paths.front(), where, cutoff_hz, files);
    describe_input(paths.front(), in);
    return in;
  }
  CampaignInput all;
  std::set<std::string> kinds, ids;
  for (const auto& p : paths) {
    auto in = load_campaign_input(p, where, cutoff_hz, files);
    describe_input(p, in);
    for (auto& t : in.campaign.trials) {
      if (!ids.insert(t.info.trial_id).second)
        throw UsageError(
            fmt::format("{}: trial '{}' is also in an earlier input: each trial may be read once", p, t.info.trial_id));
      all.campaign.trials.push_back(std::move(t));
    }
    for (auto& is : in.campaign.issues) all.campaign.issues.push_back(std::move(is));
    kinds.insert(in.kind);
    all.filtered_out += in.filtered_out;
    if (!in.note.empty()) all.note += (all.note.empty() ? "" : "; ") + p + ": " + in.note;
    all.campaign.directory += (all.campaign.directory.empty() ? "" : " + ") + p;
  }
  for (const auto& k : kinds) all.kind += (all.kind.empty() ? "" : " + ") + k;
  all.kind = fmt::format("{} inputs ({})", paths.size(), all.kind);
  return all;
}

void describe_input(const std::string& path, const CampaignInput& in) {
  const auto& c = in.campaign;
  std::fprintf(stderr, "reading %s: %s, %zu trials", path.c_str(), in.kind.c_str(), c.trials.size());
  if (in.filtered_out) std::fprintf(stderr, " (%zu left out by --where)", in.filtered_out);
  if (!c.issues.empty()) std::fprintf(stderr, ", %zu not usable", c.issues.size());
  std::fprintf(stderr, "\n");
  if (!in.note.empty()) std::fprintf(stderr, "note: %s\n", in.note.c_str());
  for (const auto& is : c.issues) {
    const bool dem = is.kind == results::ImportIssue::Kind::unmeasurable;
    const std::string where = dem || fs::path(is.file).is_absolute() ? is.to_string() : path + "/" + is.to_string();
    std::fprintf(stderr, "%s: %s\n", dem ? "not measurable" : "skipped", where.c_str());
  }
}

}  // namespace gravsweep::cli
