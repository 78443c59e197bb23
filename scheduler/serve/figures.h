// PNG figures of one drop for the page of `gravsweep serve`: Fig. 2 of Sunday et al. 2021
// (acceleration, velocity and depth against time, raw and processed as the campaign processes
// them) and Fig. 1 (the bed cut through its axis, the projectile at release and at rest), drawn
// by results/report (as `gravsweep plot trace` and `plot bed` draw them) on the first request and
// kept for the server's lifetime: a finished drop's trace and bed do not change.
#pragma once
#include <memory>
#include <mutex>
#include <string>

#include "db/database.h"
#include "scheduler/queue/queue.h"
#include "scheduler/serve/api.h"

namespace gravsweep::results {
struct ScratchDir;
}

namespace gravsweep::serve {

class DropFigures {
 public:
  DropFigures();
  ~DropFigures();
  DropFigures(const DropFigures&) = delete;
  DropFigures& operator=(const DropFigures&) = delete;
  /// /api/drop/ID/fig1.png and /api/drop/ID/fig2.png (`which`: "fig1" or "fig2"). A job that is
  /// not a finished drop, a campaign served without its files root, a trace or bed that cannot be
  /// read: a JSON error naming the reason.
  Reply reply(db::Database& db, const queue::CampaignPaths* paths, const std::string& job_id, const std::string& which);

 private:
  std::unique_ptr<results::ScratchDir> cache_;  ///< <id>_<which>.png, removed with the server
  std::mutex drawing_;                          ///< one figure at a time (plots.py's scratch folder is per process)
};

}  // namespace gravsweep::serve
