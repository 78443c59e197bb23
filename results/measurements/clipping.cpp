// A saturated accelerometer (see campaign.h): the flat top found at import and what it leaves usable.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "results/measurements/campaign.h"

namespace gravsweep::results {

namespace {

std::string clip_text(const Trial& i) {
  return fmt::format("accelerometer clipped at {:.6g} m/s2 ({:g} samples)", i.clipped_at_m_s2, i.clipped_samples);
}

}  // namespace

std::optional<ClippedRun> clipped_run(const std::vector<double>& accel_up_m_s2) {
  if (accel_up_m_s2.empty()) return std::nullopt;
  const double top = *std::max_element(accel_up_m_s2.begin(), accel_up_m_s2.end());
  if (!(top > 0)) return std::nullopt;  // no impact peak above rest: nothing to saturate
  const double tol = kClipRelTolerance * top;
  ClippedRun best;
  for (std::size_t i = 0; i < accel_up_m_s2.size();) {
    if (std::abs(accel_up_m_s2[i] - top) > tol) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < accel_up_m_s2.size() && std::abs(accel_up_m_s2[j] - top) <= tol) ++j;
    if (j - i > best.end - best.begin) best = {top, i, j};
    i = j;
  }
  if (best.end - best.begin < kClipMinSamples) return std::nullopt;
  return best;
}

void mark_clipping(MeasuredTrial& t, std::size_t edge_samples) {
  Trial& i = t.info;
  i.clipped_at_m_s2 = i.clipped_samples = i.clip_depth_error_m = 0;
  if (i.source != TraceSource::lab) return;  // a DEM trace has no sensor
  const auto run = clipped_run(t.raw.accel_up_m_s2);
  if (!run) return;
  const auto& p = t.processed;
  i.clipped_at_m_s2 = run->level_m_s2;
  i.clipped_samples = static_cast<double>(run->end - run->begin);
  // The integrated speed misses the impulse above the clip until the clip ends; bring_to_rest
  // takes what it reads at rest off from the contact on, so the depth is off at most by that
  // offset over the time from the contact to the clip's end. A record with its own depth is not
  // integrated.
  if (t.raw.depth_m.empty() && run->end > 0 && run->end - 1 < p.t_s.size())
    i.clip_depth_error_m = std::abs(p.rest_speed_offset_m_s) * std::max(0.0, p.t_s[run->end - 1] - p.metrics.t_start_s);
  // Trace-level fits: only the samples after the flat top (and its filter edge); none when
  // fewer than three are left.
  const std::size_t after = run->end + edge_samples;
  if (after >= t.fit_end || t.fit_end - after < 3)
    t.fit_begin = t.fit_end;
  else
    t.fit_begin = std::max(t.fit_begin, after);
}

std::string clip_exclusion(const MeasuredTrial& t, ClippedMetric metric) {
  const Trial& i = t.info;
  if (!(i.clipped_at_m_s2 > 0)) return {};
  const std::string clip = clip_text(i);
  switch (metric) {
    case ClippedMetric::apeak:
      return clip + ": apeak is a lower bound";
    case ClippedMetric::zstop: {
      const double zstop = t.processed.metrics.zstop_m;
      if (i.clip_depth_error_m <= kClipDepthTolerance * std::abs(zstop)) return {};
      return fmt::format("{}: the depth integrated across it may be off by {:.3g} mm, more than {:g} % of zstop", clip,
                         1e3 * i.clip_depth_error_m, 100 * kClipDepthTolerance);
    }
    case ClippedMetric::tstop:
      return {};
  }
  return {};
}

std::string clip_summary(const MeasuredTrial& t) {
  if (!(t.info.clipped_at_m_s2 > 0)) return {};
  const std::string z = clip_exclusion(t, ClippedMetric::zstop);
  return fmt::format(
      "{}: apeak {:.6g} m/s2 is a lower bound, left out of apeak fits and errors; tstop kept; {}", clip_text(t.info),
      t.processed.metrics.apeak_m_s2,
      z.empty() ? fmt::format("zstop kept (the clip moves it by at most {:.3g} mm)", 1e3 * t.info.clip_depth_error_m)
                : fmt::format("zstop left out too (the depth integrated across the clip may be off by "
                              "{:.3g} mm, more than {:g} % of it)",
                              1e3 * t.info.clip_depth_error_m, 100 * kClipDepthTolerance));
}

}  // namespace gravsweep::results
