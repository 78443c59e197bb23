// The finished drops of a campaign database as trials for the model (results/measurements): one
// reference a drop job with a results row, its trace.h5 under the campaign's files root. Shared
// by the model verbs (scheduler/cli/campaign_input.cpp, which read the traces at once) and
// `serve` (scheduler/serve/rank.cpp, which reads them a few at a time beside its requests).
#pragma once
#include <string>
#include <vector>

#include "db/database.h"
#include "results/measurements/campaign.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::pipeline {

struct DropRefs {
  std::vector<results::DemTraceRef> refs;  ///< every finished drop the filter keeps, trial id = job id
  std::string note;  ///< the drop jobs not finished yet, by state ("2 drop jobs queued, ..."), or empty
};

/// The finished drops of the campaign in `db` whose results rows pass `where` (the grammar of
/// `gravsweep results`), their traces under `paths`. Throws std::invalid_argument for a bad filter.
DropRefs finished_drops(db::Database& db, const queue::CampaignPaths& paths, const std::vector<std::string>& where);

}  // namespace gravsweep::pipeline
