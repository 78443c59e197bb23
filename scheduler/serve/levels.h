// /api/levels for `gravsweep serve`: the jobs of each sweep, kind and gravity level by state, with
// the throughput of the last 10 minutes and an ETA at that rate. The gravity level of a job is
// its `gravity_m_s2` (a swept parameter in params_json, otherwise its scenario's). A job's sweep,
// kind and level never change: each is read once (new jobs by their increasing seq), and a poll
// reads only the states and finish times (one narrow scan of the jobs table), at most once a second.
#pragma once
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "scheduler/serve/api.h"

namespace gravsweep::serve {

/// The window of the throughput and the ETA of /api/levels, s.
inline constexpr double kLevelRateWindowS = 600;

class LevelCounts {
 public:
  Reply reply(db::Database& db);

 private:
  void read_new_jobs(db::Database& db);
  Reply compute(db::Database& db);

  std::mutex m_;
  std::int64_t last_seq_ = 0;
  std::vector<std::string> groups_;                     ///< "sweep\x1fkind\x1flevel", in first-seen order
  std::unordered_map<std::string, std::size_t> group_;  ///< its index in groups_
  std::unordered_map<std::int64_t, std::size_t> of_;    ///< job seq -> group
  Reply reply_;
  std::chrono::steady_clock::time_point at_;
  bool fresh_ = false;
};

}  // namespace gravsweep::serve
