// Reader of DEM traces (trace.h5 of `gravsweep run` and of a campaign's drop jobs) as trials, and
// `measurements from-runs` (see campaign.h).
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <set>
#include <stdexcept>
#include <utility>

#include "results/io/hdf5.h"
#include "results/io/trace_file.h"
#include "results/measurements/campaign.h"
#include "results/io/table.h"

namespace gravsweep::results {

namespace fs = std::filesystem;

void prepare_dem_trial(TraceData& d, const DemTraceRef& ref) {
  Trial& ti = d.info;
  ti.trial_id = ref.trial_id;
  ti.job_id = ref.job_id;
  ti.trace_file = ref.path.string();
  // Processing settings: the scenario's /output (defaults filled when it was validated).
  const auto s = nlohmann::json::parse(d.scenario_json.empty() ? "{}" : d.scenario_json, nullptr, false);
  if (s.is_object() && s.contains("output") && s["output"].is_object()) {
    const auto& o = s["output"];
    ti.filter_cutoff_hz = o.value("filter_cutoff_hz", ti.filter_cutoff_hz);
    ti.end_threshold_g = o.value("end_threshold_g", ti.end_threshold_g);
    ti.end_speed_fraction = o.value("end_speed_fraction", ti.end_speed_fraction);
  }
  // Impact speed: the trace's own velocity at first contact (the job's metrics), else the release.
  ti.impact_speed_m_s = d.release_speed_m_s;
  const auto m = nlohmann::json::parse(d.metrics_json.empty() ? "{}" : d.metrics_json, nullptr, false);
  if (m.is_object() && m.contains("vc_m_s") && m["vc_m_s"].is_number()) ti.impact_speed_m_s = m["vc_m_s"].get<double>();
}

MeasuredTrial read_dem_trial(const DemTraceRef& ref) {
  TraceData d = read_trace(ref.path);
  prepare_dem_trial(d, ref);
  return MeasuredTrial(std::move(d));  // the trial part, its columns moved
}

Campaign load_dem_campaign(const std::string& label, const std::vector<DemTraceRef>& refs,
                           const ProcessingChoice& processing) {
  Campaign c;
  c.directory = label;
  for (const auto& r : refs) {
    const std::string who = r.job_id.empty() ? "" : fmt::format(" (drop job {})", r.job_id);
    try {
      MeasuredTrial t = read_dem_trial(r);
      apply_choice(t.info, processing);
      process_trial(t);
      if (t.processed.metrics.rebound)
        throw std::invalid_argument("not measurable: rebound (" + t.processed.metrics.note + ")");
      c.trials.push_back(std::move(t));
    } catch (const std::invalid_argument& e) {
      c.issues.push_back({r.path.string(), 0, 0, std::string(e.what()) + who, ImportIssue::Kind::unmeasurable});
    } catch (const std::exception& e) {
      c.issues.push_back({r.path.string(), 0, 0, std::string(e.what()) + who, ImportIssue::Kind::bad_input});
    }
  }
  return c;
}

int write_campaign_from_runs(const std::vector<std::string>& roots, const std::string& out_dir,
                             std::vector<ImportIssue>& issues) {
  // trace.h5 of `gravsweep run`; <campaign>.files/traces/<job>.a<n>.h5 of a campaign's drops.
  auto is_trace = [](const fs::path& p) {
    return p.filename() == "trace.h5" || (p.extension() == ".h5" && p.parent_path().filename() == "traces" &&
                                          p.parent_path().parent_path().extension() == ".files");
  };
  std::vector<fs::path> traces;
  for (const auto& r : roots) {
    if (fs::is_regular_file(r)) {
      traces.emplace_back(r);
      continue;
    }
    if (!fs::is_directory(r)) {
      issues.push_back({r, 0, 0, "neither a trace.h5 file nor a folder"});
      continue;
    }
    for (const auto& e : fs::recursive_directory_iterator(r))
      if (e.is_regular_file() && is_trace(e.path())) traces.push_back(e.path());
  }
  std::sort(traces.begin(), traces.end());
  std::vector<std::pair<std::string, MeasuredTrial>> trials;
  std::set<std::string> ids;
  for (const auto& p : traces) {
    std::string id = p.filename() == "trace.h5" ? p.parent_path().filename().string() : p.stem().stem().string();
    if (id.empty() || !ids.insert(id).second) id = fmt::format("{}_{}", id, trials.size() + 1);
    ids.insert(id);
    try {
      MeasuredTrial t = read_dem_trial({id, "", p});
      trials.emplace_back(p.string(), std::move(t));
    } catch (const std::exception& e) {
      issues.push_back({p.string(), 0, 0, e.what()});
    }
  }
  if (trials.empty()) return 0;
  const fs::path out(out_dir);
  fs::create_directories(out / "traces");
  std::vector<std::string> keys;
  for (const auto& f : trial_fields()) keys.emplace_back(f.key);
  Table table(keys);
  for (auto& [src, t] : trials) {
    // The trace goes inside the campaign folder (trials.csv paths never lead outside it).
    const std::string rel = "traces/" + t.info.trial_id + ".h5";
    std::error_code ec;
    fs::remove(out / rel, ec);
    fs::create_hard_link(src, out / rel, ec);
    if (ec) fs::copy_file(src, out / rel, fs::copy_options::overwrite_existing);
    t.info.trace_file = rel;
    std::vector<std::string> row;
    for (const auto& f : trial_fields()) row.push_back(f.number ? fmt::format("{}", t.info.*f.number) : t.info.*f.text);
    table.add(std::move(row));
  }
  const fs::path tmp = out / "trials.csv.tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!(f << table.csv())) throw std::runtime_error(fmt::format("{}: cannot write trials.csv", out_dir));
  }
  fs::rename(tmp, out / "trials.csv");
  return static_cast<int>(trials.size());
}

}  // namespace gravsweep::results
