// Moving a campaign between backends (SQLite <-> PostgreSQL, or to another file): every job with
// its state, lease, attempts, dependencies, sweeps and results (with its dynamic columns), in one
// transaction on the destination, and the campaign's files when the two files roots differ.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

#include "db/database.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::queue {

struct CopyReport {
  std::int64_t jobs = 0, attempts = 0, results = 0, result_columns = 0;
  std::size_t files = 0;  ///< files copied to the destination's files root
};

/// Copies campaign `src` (opened for reading) into `dst`, which must hold no campaign yet (its
/// schema is created). Refuses (ConfigError) while jobs of `src` are running (stop its workers
/// first): a copied lease would run twice. Files under beds/, traces/ and noop/ are copied from
/// `src_paths.root` to `dst_paths.root` when those differ (files already there are kept).
CopyReport copy_campaign(db::Database& src, const CampaignPaths& src_paths, db::Database& dst,
                         const CampaignPaths& dst_paths);

}  // namespace gravsweep::queue
