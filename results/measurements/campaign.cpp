// Processing measurement campaigns (see campaign.h; their SQLite tables: campaign_db.cpp).
#include "results/measurements/campaign.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "db/database.h"

namespace gravsweep::results {

namespace fs = std::filesystem;

std::string ImportIssue::to_string() const {
  if (line > 0 && column > 0) return fmt::format("{}:{}:{}: {}", file, line, column, message);
  if (line > 0) return fmt::format("{}:{}: {}", file, line, message);
  return fmt::format("{}: {}", file, message);
}

std::vector<double> Campaign::gravity_levels() const {
  std::vector<double> g;
  for (const auto& t : trials) g.push_back(t.info.gravity_m_s2);
  return gravity_levels_of(g);
}

void process_trial(MeasuredTrial& t) {
  t.raw.source = t.info.source;
  const MetricOptions o = metric_options(t.info);
  t.processed = process_trace(t.raw, o);
  // Fit window: inside the collision, two filter edge widths clear of contact and stop.
  const auto& p = t.processed;
  const std::size_t w = 2 * (1 + static_cast<std::size_t>(std::ceil(p.sample_rate_hz / o.cutoff_hz)));
  t.fit_begin = p.i_start + 1 + w;
  t.fit_end = p.i_end > w ? p.i_end - w : 0;
  if (t.fit_end < t.fit_begin + 3) {
    // Short collision: keep what lies inside it.
    t.fit_begin = p.i_start + 1;
    t.fit_end = std::max(t.fit_begin, p.i_end);
  }
  mark_clipping(t, w);
}

Campaign load_campaign_any(const std::string& path, double cutoff_hz) {
  if (fs::is_regular_file(path)) {
    db::Database db(path, 30000, true);
    Campaign c = load_campaign_db(db);
    if (c.trials.empty()) throw std::runtime_error(fmt::format("{}: no imported trials", path));
    return c;
  }
  return load_campaign(path, cutoff_hz);
}

}  // namespace gravsweep::results
