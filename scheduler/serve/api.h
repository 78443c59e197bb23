// The JSON API of `gravsweep serve` (docs/serve.md): each endpoint a function from the request's
// query parameters to a reply, on a campaign opened for reading. It knows no HTTP library (the
// server in server.h routes to it) and writes nothing: every query reads one snapshot through the
// queue's own functions (status, query_results, troubled_jobs) and the trace file's reader.
// Every reply is bounded: tables come in pages, a trace is thinned to at most a set number of
// samples, so a campaign of 100,000 jobs answers as fast as a small one.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "db/database.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::serve {

/// The query string of a request (a name may come several times: `where`).
using Params = std::multimap<std::string, std::string>;

struct Reply {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::string download_name;  ///< non-empty: sent as an attachment of this name
};

/// The bounds of the pages (docs/serve.md, "Limits").
inline constexpr std::int64_t kDefaultPageRows = 50;
inline constexpr std::int64_t kMaxPageRows = 5000;   ///< a JSON page of results or failed jobs
inline constexpr std::int64_t kMaxCsvRows = 200000;  ///< one CSV download
inline constexpr std::int64_t kDefaultTracePoints = 2000;
inline constexpr std::int64_t kMaxTracePoints = 20000;
inline constexpr std::int64_t kMaxAttempts = 50;  ///< a job's attempts in /api/attempts/ID

/// Job ids are hex digests: anything else is no job (and never reaches the where grammar).
bool is_job_id(const std::string& id);

/// Debian's HDF5 library is built without its thread-safety option: every trace read of the
/// process (a drop's trace, the traces behind the model verdict) holds this lock.
std::mutex& hdf5_mutex();

/// A reply of status `status` with {"error": what}.
Reply error_reply(int status, const std::string& what);

/// /api/status: `status --format json`'s object, plus the campaign's name, its clock (`now`:
/// heartbeat ages on the page) and the time the query took.
Reply status_reply(db::Database& db, const std::string& campaign);

/// /api/results: where (repeatable, the `results --where` grammar), sort (a column, `-column`
/// from the largest), offset, limit, columns (comma separated; `all`; default the summary
/// columns of `results`), sweep, format (json or csv).
Reply results_reply(db::Database& db, const Params& params);

/// /api/failed: the failed and dead jobs with their reasons, latest first; offset, limit.
Reply failed_reply(db::Database& db, const Params& params);

/// /api/attempts/ID: the job's attempts, latest first (at most kMaxAttempts): outcome, worker,
/// host, threads, build, start, end, run time and the error each attempt ended with. A job runs
/// inside its worker's process and writes no log of its own: this history is its log.
Reply attempts_reply(db::Database& db, const std::string& job_id);

/// /api/collapse: the drops the filter `where` keeps (the first kMaxPageRows) in Froude scaling:
/// gravity and projectile diameter from each drop's scenario, Fr = vc / sqrt(g D), zstop / D,
/// tstop sqrt(g / D), apeak / g (collapse.cpp).
Reply collapse_reply(db::Database& db, const Params& params);

/// /api/drop/ID: the job's results row and, for a drop, its trace (time, acceleration, depth,
/// speed) thinned to at most `points` samples, read from the trace file under the files root
/// (`paths`; null: a server campaign served without --files, the row alone).
Reply drop_reply(db::Database& db, const queue::CampaignPaths* paths, const std::string& job_id, const Params& params);

}  // namespace gravsweep::serve
