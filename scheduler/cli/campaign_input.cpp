#include "scheduler/cli/campaign_input.h"

#include <fmt/format.h>

#include <filesystem>
#include <optional>
#include <utility>

#include "db/database.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/pipeline/drop_campaign.h"
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
  pipeline::DropRefs drops;
  try {
    drops = pipeline::finished_drops(db, queue::CampaignPaths(path, files), where);
  } catch (const std::invalid_argument& e) {
    throw UsageError(fmt::format("{}: {}", path, e.what()));
  }
  in.note = std::move(drops.note);
  in.campaign = results::load_dem_campaign(path, drops.refs, processing);
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
