#include "results/measurements/campaign_input.h"

#include <fmt/format.h>

#include <cstdio>
#include <cmath>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "db/database.h"
#include "db/where.h"
#include "results/processing/metric_fields.h"

namespace gravsweep::results {

namespace fs = std::filesystem;

namespace {

constexpr const char* kExpectedInput = "a campaign database, an imported SQLite file or a lab campaign folder expected";

/// An imported SQLite file (table trials); anything else is refused with what was expected.
Campaign read_imported_file(const std::string& path) {
  if (fs::file_size(path) == 0) throw std::runtime_error(fmt::format("{}: an empty file: {}", path, kExpectedInput));
  try {
    db::Database db(path, 30000, true);
    if (!db::has_table(db, "trials"))
      throw std::runtime_error(fmt::format(
          "{}: neither a campaign database (tables jobs, results) nor an imported SQLite file (table trials)", path));
    return load_campaign_db(db);
  } catch (const db::DbError& e) {
    throw std::runtime_error(fmt::format("{}: not a readable campaign ({})", path, e.what()));
  }
}

}  // namespace

nlohmann::json where_row(const MeasuredTrial& t) {
  nlohmann::json j = t.info;
  j.erase("attributes");
  for (const auto& [k, v] : t.info.attributes) j[k] = v;
  for (const auto& [alias, key] : trial_field_aliases()) j[alias] = j[key];  // older --where names
  const nlohmann::json m = t.processed.metrics;
  for (const auto& f : metric_fields())
    if (!f.text) j[f.key] = m[f.key];
  // The impact Froude number vc / sqrt(g D), for a gravity sweep's subsets ('impact_froude<=1').
  const double gD = t.info.gravity_m_s2 * t.info.projectile_diameter_m;
  if (gD > 0) j["impact_froude"] = t.processed.metrics.vc_m_s / std::sqrt(gD);
  return j;
}

void refuse_unphysical(const std::string& path, const CampaignInput& in) {
  for (const auto& t : in.campaign.trials)
    for (const auto& f : trial_fields()) {
      if (!f.number) continue;
      const double v = t.info.*f.number;
      if (const std::string expected = out_of_physical_range(f.key, v); !expected.empty())
        throw std::runtime_error(
            fmt::format("{}: trial '{}': {} = {}, expected {} (a wrong unit or a corrupt number; fix the "
                        "record and import it again)",
                        path, t.info.trial_id, f.key, v, expected));
    }
}

void filter_trials(const std::string& path, CampaignInput& in, const std::vector<std::string>& where) {
  if (where.empty()) return;
  auto& trials = in.campaign.trials;
  const std::size_t before = trials.size();
  std::vector<MeasuredTrial> kept;
  try {
    for (const auto& w : where) db::parse_where(w);  // a malformed filter fails even on no trials
    for (auto& t : trials)
      if (db::row_matches(where_row(t), where)) kept.push_back(std::move(t));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(fmt::format("{}: {}", path, e.what()));
  }
  trials = std::move(kept);
  in.filtered_out = before - trials.size();
}

CampaignInput load_trial_input(const std::string& path, const std::vector<std::string>& where, double cutoff_hz,
                               const ProcessingChoice& processing) {
  CampaignInput in;
  if (fs::is_directory(path)) {
    in.kind = kLabFolderKind;
    in.campaign = load_campaign(path, cutoff_hz, processing);
  } else if (fs::is_regular_file(path)) {
    in.kind = kImportedFileKind;
    in.campaign = read_imported_file(path);
    if (processing.any()) reprocess_campaign(in.campaign, processing);
  } else {
    throw std::runtime_error(fmt::format("{}: no such file or folder: {}", path, kExpectedInput));
  }
  refuse_unphysical(path, in);
  filter_trials(path, in, where);
  return in;
}

CampaignInput concatenate_inputs(std::vector<std::pair<std::string, CampaignInput>> inputs) {
  if (inputs.size() == 1) return std::move(inputs.front().second);
  CampaignInput all;
  std::set<std::string> kinds, ids;
  for (auto& [p, in] : inputs) {
    for (auto& t : in.campaign.trials) {
      if (!ids.insert(t.info.trial_id).second)
        throw std::runtime_error(
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
  all.kind = fmt::format("{} inputs ({})", inputs.size(), all.kind);
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
    const bool dem = is.kind == ImportIssue::Kind::unmeasurable;
    const std::string where = dem || fs::path(is.file).is_absolute() ? is.to_string() : path + "/" + is.to_string();
    std::fprintf(stderr, "%s: %s\n", dem ? "not measurable" : "skipped", where.c_str());
  }
}

}  // namespace gravsweep::results
