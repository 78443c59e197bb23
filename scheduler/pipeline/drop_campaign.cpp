#include "scheduler/pipeline/drop_campaign.h"

#include <fmt/format.h>

#include "scheduler/queue/filter.h"

namespace gravsweep::pipeline {

DropRefs finished_drops(db::Database& db, const queue::CampaignPaths& paths, const std::vector<std::string>& where) {
  queue::ResultsQuery q;
  q.where = where;
  q.columns = {"job_id", "kind", "trace_path"};
  const queue::ResultsTable t = queue::query_results(db, q);
  DropRefs out;
  for (const auto& r : t.rows) {
    if (r[1] != "drop" || !r[2].is_string()) continue;
    const std::string job = r[0].get<std::string>();
    out.refs.push_back({job, job, paths.abs(r[2].get<std::string>())});
  }
  db::Statement st(
      db, "SELECT state, count(*) FROM jobs WHERE kind='drop' AND state != 'done' GROUP BY state ORDER BY state");
  while (st.step())
    out.note += fmt::format("{}{} drop jobs {}", out.note.empty() ? "" : ", ", st.get_int(1), st.get_text(0));
  if (!out.note.empty()) out.note += " (not finished: not trials yet; `gravsweep work` runs them)";
  return out;
}

}  // namespace gravsweep::pipeline
