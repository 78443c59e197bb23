#include "scheduler/cli/campaign_input.h"

#include <fmt/format.h>

#include <filesystem>
#include <optional>
#include <utility>

#include "db/database.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/filter.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::cli {

namespace fs = std::filesystem;

namespace {

/// The campaign database of the job queue at `path` (tables jobs and results), opened read-only;
/// nothing when `path` is anything else (results/ reads those).
std::optional<db::Database> open_queue_database(const std::string& path) {
  if (!fs::is_regular_file(path) || fs::file_size(path) == 0) return std::nullopt;
  db::Database db(path, 30000, true);
  if (!db::has_table(db, "jobs") || !db::has_table(db, "results")) return std::nullopt;
  return db;
}

/// Every finished drop of a campaign database (filtered on its results table) as a DEM trial.
CampaignInput load_queue_campaign(const std::string& path, db::Database& db, const std::vector<std::string>& where,
                                  const std::string& files, const results::ProcessingChoice& processing) {
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
  in.campaign = results::load_dem_campaign(path, refs, processing);
  results::refuse_unphysical(path, in);
  return in;
}

}  // namespace

CampaignInput load_campaign_input(const std::string& path, const std::vector<std::string>& where, double cutoff_hz,
                                  const std::string& files, const results::ProcessingChoice& processing) {
  try {
    if (db::is_postgres_url(path)) {
      db::Database db = queue::open_campaign(path, queue::OpenMode::read, files);  // refuses a non-campaign
      return load_queue_campaign(path, db, where, files, processing);
    }
    if (auto db = open_queue_database(path)) return load_queue_campaign(path, *db, where, files, processing);
    return results::load_trial_input(path, where, cutoff_hz, processing);
  } catch (const UsageError&) {
    throw;
  } catch (const db::DbError& e) {
    throw UsageError(fmt::format("{}: not a readable campaign ({})", path, e.what()));
  } catch (const std::runtime_error& e) {
    throw UsageError(e.what());
  }
}

CampaignInput load_campaign_inputs(const std::vector<std::string>& paths, const std::vector<std::string>& where,
                                   double cutoff_hz, const std::string& files,
                                   const results::ProcessingChoice& processing) {
  std::vector<std::pair<std::string, CampaignInput>> inputs;
  for (const auto& p : paths) {
    inputs.emplace_back(p, load_campaign_input(p, where, cutoff_hz, files, processing));
    describe_input(p, inputs.back().second);
  }
  try {
    return results::concatenate_inputs(std::move(inputs));
  } catch (const std::runtime_error& e) {
    throw UsageError(e.what());
  }
}

}  // namespace gravsweep::cli
