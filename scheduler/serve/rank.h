// The campaign's `model rank` verdict for `gravsweep serve` (/api/rank): computed by a background
// thread, never by a request, and cached per campaign state (the number of finished drops and the
// latest finish time). The thread looks at the campaign every few seconds; when drops have
// finished since the last verdict it reads their traces (a few at a time, sharing the HDF5 lock
// with /api/drop) and runs results::discover as `gravsweep model rank campaign.db` does. A request
// only copies the latest answer: "computing" while the first one is under way, the previous
// verdict with the state being computed while a newer one is, "not enough drops" below the
// minimum of `model rank`.
#pragma once
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "results/measurements/campaign.h"
#include "scheduler/queue/queue.h"
#include "scheduler/serve/api.h"

namespace gravsweep::serve {

/// The trials `model rank` needs at least (its grouped cross-validation's folds).
inline constexpr std::int64_t kRankMinDrops = 6;

/// What a verdict is computed for: the finished drops and the latest finish time.
struct CampaignState {
  std::int64_t drops = 0;
  double last_finished_at = 0;
  bool operator==(const CampaignState& o) const { return drops == o.drops && last_finished_at == o.last_finished_at; }
};

class RankWatch {
 public:
  /// On the campaign `db` (read with its own connection), its traces under `paths` (none: a server
  /// campaign served without --files, whose traces cannot be read). Looks every `interval_s`.
  RankWatch(std::string db, std::string files, std::optional<queue::CampaignPaths> paths, double interval_s = 2.0);
  ~RankWatch();
  RankWatch(const RankWatch&) = delete;
  RankWatch& operator=(const RankWatch&) = delete;

  /// /api/rank: the latest answer (docs/serve.md).
  Reply reply() const;

 private:
  void run();
  /// Reads the campaign's state and its finished drops in one snapshot and publishes the answer
  /// for them; the state answered (nothing: stopped meanwhile). Throws db::DbError.
  std::optional<CampaignState> compute(db::Database& db);
  /// The drops' traces read and processed, a few under each hold of the HDF5 lock (nothing: stopped).
  std::optional<results::Campaign> load(const std::vector<results::DemTraceRef>& refs) const;
  bool stopping() const;
  bool wait(double seconds);  ///< false once stopping
  void publish(nlohmann::json j);

  std::string db_, files_;
  std::optional<queue::CampaignPaths> paths_;
  double interval_s_;
  mutable std::mutex m_;
  std::condition_variable cv_;
  bool stopping_ = false;
  nlohmann::json answer_;
  std::thread thread_;
};

}  // namespace gravsweep::serve
