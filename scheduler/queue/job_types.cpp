#include "scheduler/queue/job_types.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <deque>
#include <mutex>

#include "engine/core/error.h"
#include "engine/core/registry.h"

namespace gravsweep::queue {

namespace {

/// The no-op kind's row: its runner (scheduler/sweep/noop_kind.cpp) echoes the point's `value`
/// and reports the time it slept.
JobKindInfo noop_row() {
  return {"noop", "noop", ".json", true, false, {{"noop_value", "1", "REAL"}, {"sleep_s", "s", "REAL"}}};
}

/// The table of kinds: rows are only appended (JobKind is an index), so references stay valid.
struct KindTable {
  std::mutex mutex;
  std::deque<JobKindInfo> rows{noop_row()};
};

KindTable& kind_table() {
  static KindTable table;
  return table;
}

bool same_row(const JobKindInfo& a, const JobKindInfo& b) {
  return a.name == b.name && a.folder == b.folder && a.extension == b.extension && a.results_row == b.results_row &&
         a.takes_idle_threads == b.takes_idle_threads && a.outputs == b.outputs;
}

/// A key that is a column name as it stands (no quoting, no clash with SQL's case folding).
bool plain_column_name(const std::string& key) {
  if (key.empty() || key[0] < 'a' || key[0] > 'z') return false;
  for (char c : key)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  return true;
}

/// Refuses outputs that could not be a results column each.
void check_outputs_declared(const JobKindInfo& info) {
  if (!info.outputs.empty() && !info.results_row)
    throw ConfigError(
        fmt::format("job kind '{}': declares outputs but its finished jobs are no results rows", info.name));
  std::vector<std::string> seen;
  for (const auto& o : info.outputs) {
    if (!plain_column_name(o.key))
      throw ConfigError(
          fmt::format("job kind '{}': output key '{}' is not a plain column name (expected lower case "
                      "letters, digits and '_', starting with a letter)",
                      info.name, o.key));
    if (o.type != "REAL" && o.type != "INTEGER" && o.type != "TEXT")
      throw ConfigError(fmt::format("job kind '{}': output '{}' has type '{}', expected REAL, INTEGER or TEXT",
                                    info.name, o.key, o.type));
    if (std::find(seen.begin(), seen.end(), o.key) != seen.end())
      throw ConfigError(fmt::format("job kind '{}': output '{}' is declared twice", info.name, o.key));
    seen.push_back(o.key);
  }
}

constexpr std::array<const char*, 6> kStates{"waiting", "queued", "running", "failed", "done", "dead"};

}  // namespace

JobKind register_kind(JobKindInfo info) {
  check_outputs_declared(info);
  KindTable& t = kind_table();
  const std::lock_guard lock(t.mutex);
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const JobKindInfo& row = t.rows[i];
    if (row.name == info.name) {
      if (same_row(row, info)) return JobKind(i);
      throw ConfigError(fmt::format("job kind '{}' is registered twice, with different table rows", info.name));
    }
    if (row.folder == info.folder)
      throw ConfigError(
          fmt::format("job kinds '{}' and '{}' cannot share the output folder '{}'", row.name, info.name, info.folder));
  }
  if (info.name.empty() || info.folder.empty() || info.folder == "tmp")
    throw ConfigError(fmt::format("job kind '{}': a kind needs a name and an output folder other than tmp", info.name));
  t.rows.push_back(std::move(info));
  return JobKind(t.rows.size() - 1);
}

std::vector<JobKind> registered_kinds() {
  KindTable& t = kind_table();
  const std::lock_guard lock(t.mutex);
  std::vector<JobKind> kinds;
  for (std::size_t i = 0; i < t.rows.size(); ++i) kinds.push_back(JobKind(i));
  return kinds;
}

const JobKindInfo& kind_info(JobKind k) {
  KindTable& t = kind_table();
  const std::lock_guard lock(t.mutex);
  return t.rows.at(k.index());
}

JobKind parse_kind(std::string_view name) {
  KindTable& t = kind_table();
  const std::lock_guard lock(t.mutex);
  const JobKindInfo& row = find_row(t.rows, name, "job kind");
  std::size_t index = 0;  // the rows are a deque (stable addresses, not contiguous): walk to the row
  while (&t.rows[index] != &row) ++index;
  return JobKind(index);
}

std::vector<std::string> kind_folders() {
  std::vector<std::string> folders;
  for (JobKind k : registered_kinds()) folders.push_back(kind_info(k).folder);
  return folders;
}

std::vector<std::string> output_folders() {
  std::vector<std::string> folders = kind_folders();
  folders.emplace_back("tmp");
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
