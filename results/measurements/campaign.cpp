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

std::vector<std::vector<std::size_t>> Campaign::trials_by_level() const {
  const std::vector<double> levels = gravity_levels();
  std::vector<std::vector<std::size_t>> out(levels.size());
  for (std::size_t i = 0; i < trials.size(); ++i)
    for (std::size_t gi = 0; gi < levels.size(); ++gi)
      if (same_gravity_level(levels[gi], trials[i].info.gravity_m_s2)) {
        out[gi].push_back(i);
        break;
      }
  return out;
}

void process_trial(MeasuredTrial& t) {
  t.raw.source = t.info.source;
  MetricOptions o = metric_options(t.info);
  try {
    t.processed = process_trace(t.raw, o);
  } catch (const TraceError& e) {
    // A lab record sized in seconds (a few ms of free fall, 0.1 s of rest) can be too short for
    // the drop-scaled filter at low gravity, whose edges ring over tens of ms: its contact step
    // rings into the free fall the sensor bias is read from. It is processed in the paper's fixed
    // scales instead, and says so (its apeak then holds the wider bandwidth).
    const bool narrowed = o.cutoff_hz < t.info.filter_cutoff_hz;
    if (t.info.source != TraceSource::lab || !narrowed) throw;
    o.cutoff_hz = t.info.filter_cutoff_hz;
    o.end_hold_s = kPaperEndHold_s;
    t.processed = process_trace(t.raw, o);
    t.processed.metrics.note += fmt::format(
        "{}processed in the paper's fixed scales ({:g} Hz, {:g} s hold): the "
        "record is too short for its drop-scaled filter ({})",
        t.processed.metrics.note.empty() ? "" : "; ", o.cutoff_hz, o.end_hold_s, e.what());
  }
  t.options = o;
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

void apply_choice(Trial& t, const ProcessingChoice& p) {
  if (!p.time_scale.empty()) t.time_scale = p.time_scale;
  if (!p.end_rule.empty()) t.end_rule = p.end_rule;
}

void reprocess_campaign(Campaign& c, const ProcessingChoice& p) {
  std::vector<MeasuredTrial> kept;
  for (auto& t : c.trials) {
    apply_choice(t.info, p);
    try {
      process_trial(t);
      kept.push_back(std::move(t));
    } catch (const std::invalid_argument& e) {
      c.issues.push_back({t.info.trace_file, 0, 0,
                          fmt::format("{} (time scale {}, end rule {})", e.what(), t.info.time_scale, t.info.end_rule),
                          ImportIssue::Kind::unmeasurable});
    }
  }
  c.trials = std::move(kept);
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
