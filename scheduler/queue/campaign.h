// Opening a campaign safely, and the campaign's files: stored paths, orphans and quarantine.
//
// A campaign is `<stem>.db` plus `<stem>.files/`. Paths stored in the database (jobs.output_path,
// attempts.output_path, results.trace_path) are relative to `<stem>.files/` (schema version 2), so
// a renamed copy (`c2.db` + `c2.files/`) finds its own files. Version-1 rows (`<stem>.files/...`,
// relative to the database's folder, or absolute) are read the same way and rewritten by the first
// verb that writes.
#pragma once
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "db/database.h"
#include "scheduler/queue/job_types.h"

namespace gravsweep::queue {

struct CampaignPaths;

/// What a verb does with the campaign it opens.
enum class OpenMode {
  read,    ///< status, results: nothing is written
  write,   ///< work, resume: an existing campaign, migrated to the current schema if needed
  create,  ///< submit: a missing or new database gets the schema
};

/// Opens the campaign database at `db_path` (a file, or a `postgresql://` URL: then `files_root`
/// must be given), refusing (ConfigError, exit 2, naming the file) a
/// file that is not a campaign: missing (except for `create`), empty, not SQLite, or without the
/// queue tables. `create` also refuses a missing or empty database beside a files folder that
/// holds files (the database was lost or truncated: a new schema would orphan every output).
db::Database open_campaign(const std::filesystem::path& db_path, OpenMode mode,
                           const std::filesystem::path& files_root = {});

/// Throws ConfigError unless `db` holds the queue tables with a known schema version.
void check_campaign(db::Database& db);

/// The canonical form of a stored path: relative to the files root. Version-1 forms
/// (`<any stem>.files/beds/x.h5`, relative or absolute) lose everything up to `.files/`.
std::string files_rel(const std::string& stored);

/// Rewrites version-1 paths to `files_rel` form and sets schema version 2 (in one transaction).
void migrate_paths(db::Database& db);

/// Adds the columns a campaign written by an earlier gravsweep lacks (jobs.blocked_by, filled from
/// the earlier message form once; the results columns the kinds of its jobs declare), in one
/// transaction. Schema version 2 either way.
void add_missing_columns(db::Database& db);

// ---- the files root's marker ---------------------------------------------------------------------

/// The file in a files root naming the campaign it belongs to: {"campaign_id", "database"}.
inline constexpr const char* kFilesMarker = "gravsweep-campaign.json";

/// The campaign's identity (`queue_meta` key `campaign_id`, random), created on first use. A copy
/// of the database (`.backup`, `campaign copy`) keeps it, so its copied folder still belongs.
std::string campaign_id(db::Database& db);

/// Sets the campaign's identity (`campaign copy`: the destination is the same campaign).
void set_campaign_id(db::Database& db, const std::string& id);

/// Proves that `paths.root` belongs to the campaign of `db` before anything in it is moved or
/// deleted; ConfigError (exit 2, naming both) otherwise. Its marker must name this campaign. A
/// root without a marker (a campaign of an earlier gravsweep) is accepted when it is the default
/// root beside an SQLite database (`<stem>.files/`), or when it holds nothing foreign: no entry at
/// its top but gravsweep's folders, no file in `beds/`, `traces/`, `noop/`, `tmp/` that the
/// database does not refer to, no file in `quarantine/` or `snapshots/`. With `write`, an accepted
/// root gets its marker (nothing is written otherwise: a dry run).
void bind_files_root(db::Database& db, const CampaignPaths& paths, bool write = true);

/// Regular files under `dir`, recursively (0 when it does not exist).
std::size_t count_files(const std::filesystem::path& dir);

// ---- orphans ------------------------------------------------------------------------------------

/// What the database refers to, read in one read transaction.
struct Referenced {
  std::set<std::string> done;              ///< files_rel of done jobs' outputs
  std::set<std::string> live;              ///< files_rel of running attempts' planned outputs
  std::vector<std::string> live_prefixes;  ///< "<job>.a<k>." of running attempts (tmp files)
  double taken_at_s = 0;                   ///< wall clock just before the snapshot began
  [[nodiscard]] bool refers_to(const std::string& rel) const;
};
Referenced referenced_files(db::Database& db);

/// Throws ConfigError when most files that done jobs refer to are missing: the database and the
/// folder beside it do not belong together, and removing "orphans" would destroy the wrong data.
void check_files_belong(db::Database& db, const CampaignPaths& paths);

/// Throws ConfigError when `<root>/quarantine` exists and is not a real folder (a symbolic link,
/// a file): nothing is ever moved into or removed through a link.
void check_quarantine_folder(const CampaignPaths& paths);

struct OrphanReport {
  std::vector<std::string> moved;     ///< files_rel of files moved to quarantine (or found: dry run)
  std::vector<std::string> restored;  ///< moved, then found referenced, and put back
  std::size_t purged = 0;             ///< quarantined files (of earlier resumes) removed
};

/// Moves files no done job and no live attempt refers to, and older than the snapshot by
/// `min_age_s`, to `<root>/quarantine/<stamp>/`; files quarantined by an earlier call are removed
/// first (unless the database refers to them again: then they go back), only from gravsweep's own
/// `<stamp>/` batches and never through a symbolic link. Nothing moves in a dry run.
OrphanReport quarantine_orphans(db::Database& db, const CampaignPaths& paths, bool dry_run, double min_age_s = 5.0);

}  // namespace gravsweep::queue
