#include "scheduler/queue/job_types.h"

#include <fmt/format.h>

#include <array>

#include "engine/core/error.h"

namespace gravsweep::queue {

namespace {

constexpr std::array<JobKindInfo, 3> kKinds{{
    {JobKind::bed, "bed", "beds", ".h5", false, true},
    {JobKind::drop, "drop", "traces", ".h5", true, false},
    {JobKind::noop, "noop", "noop", ".json", true, false},
}};

constexpr std::array<const char*, 6> kStates{"waiting", "queued", "running", "failed", "done", "dead"};

}  // namespace

const JobKindInfo& kind_info(JobKind k) { return kKinds.at(static_cast<std::size_t>(k)); }

JobKind parse_kind(std::string_view name) {
  std::string valid;
  for (const auto& k : kKinds) {
    if (name == k.name) return k.kind;
    valid += (valid.empty() ? "" : ", ") + std::string(k.name);
  }
  throw ConfigError(fmt::format("unknown job kind '{}' (expected one of {})", name, valid));
}

const std::vector<std::string>& kind_folders() {
  static const std::vector<std::string> folders = [] {
    std::vector<std::string> f;
    for (const auto& k : kKinds) f.emplace_back(k.folder);
    return f;
  }();
  return folders;
}

const std::vector<std::string>& output_folders() {
  static const std::vector<std::string> folders = [] {
    std::vector<std::string> f = kind_folders();
    f.emplace_back("tmp");
    return f;
  }();
  return folders;
}

const char* state_name(JobState s) { return kStates.at(static_cast<std::size_t>(s)); }

JobState parse_state(std::string_view name) {
  std::string valid;
  for (std::size_t i = 0; i < kStates.size(); ++i) {
    if (name == kStates[i]) return static_cast<JobState>(i);
    valid += (valid.empty() ? "" : ", ") + std::string(kStates[i]);
  }
  throw ConfigError(fmt::format("unknown job state '{}' (expected one of {})", name, valid));
}

}  // namespace gravsweep::queue
