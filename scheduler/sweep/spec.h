// Sweep specs (schemas/sweep.schema.json): a base scenario plus axes that set scenario fields
// addressed by JSON pointer, as value lists, ranges or zipped groups, with repeats (seeds or
// offsets). expand() turns a spec into content-addressed jobs by its kind's planner
// (sweep_kind.h): for an impact sweep one `drop` job per point and one `bed` job per distinct bed
// key, which the drops that share the bed depend on.
//
// Validation never stops at the first problem: the schema (spec/schemas.h) and then the checks
// across fields (spec.cpp) each report every problem, and SpecError (spec::SpecError, made by
// SpecError::sweep_spec) lists them all with the file, the JSON pointer, the value found and what
// was expected. The kind's own checks (its base check, then every point's) come at expand(), and
// list all of theirs in the same way.
#pragma once
#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "scheduler/queue/job_types.h"
#include "scheduler/queue/queue.h"
#include "spec/json_schema.h"

namespace gravsweep::sweep {

/// One problem: JSON pointer into the spec ("" = the document), the value found, what was expected.
using SpecProblem = spec::SpecProblem;

/// The one spec error (spec/json_schema.h), thrown here as SpecError::sweep_spec(file, problems):
/// a ConfigError whose message lists every problem.
using SpecError = spec::SpecError;

/// One swept scenario field.
struct Axis {
  std::string name;                    ///< results column name (units in the name, e.g. gravity_m_s2)
  std::string pointer;                 ///< JSON pointer into the scenario
  std::vector<nlohmann::json> values;  ///< canonical values
};

/// Axes that vary together (zip) form one dimension of the product; a plain axis is a group of one.
struct AxisGroup {
  std::vector<Axis> axes;
  [[nodiscard]] std::size_t size() const { return axes.empty() ? 0 : axes.front().values.size(); }
};

/// A sweep spec as read: the sweep the queue stores (queue::SweepRecord: name, job kind, the spec's
/// canonical text, retry budget and a results column per axis, all set by load_spec), plus what
/// expansion needs. The spec's JSON tree lives only while load_spec reads it (the schema check and
/// the error pointers are made on it); what is kept of it is this record and the stored text.
struct SweepSpec : queue::SweepRecord {
  nlohmann::json base;            ///< canonical base scenario
  std::vector<AxisGroup> groups;  ///< product over groups, first group slowest; repeats last
  int priority = 0;
  std::string file;  ///< where it was read from (for error messages)
  [[nodiscard]] std::size_t points() const;
};

/// Reads a spec file into its record: parsed (JSON errors are SpecError with line and column),
/// schema-checked, defaults filled, the rules across fields checked; a base given as a file name is
/// read relative to the spec. Throws SpecError listing every problem.
SweepSpec load_spec(const std::filesystem::path& path);
/// The same for spec text not read from a file (a test's, a benchmark's): `file` names it in
/// errors, `base_dir` resolves a base given as a file name.
SweepSpec load_spec_text(const std::string& text, const std::string& file, const std::filesystem::path& base_dir);

/// A point's scenario as checked by the pipeline that runs it: the scenario its jobs store
/// (validated, defaults filled, marked so that the worker need not validate it again) and its bed
/// key (drops with equal keys share a bed job).
struct CheckedPoint {
  std::string scenario_json;  ///< the text the jobs store (PlannedJob::scenario_json)
  nlohmann::json bed_key;
  nlohmann::json id_point;  ///< what the drop's id is computed from (null: the point as written)
};
/// Checks a point's scenario; throws SpecError naming its problems.
using PointCheckFn = std::function<CheckedPoint(const nlohmann::json& scenario)>;

/// Told how many of the points are expanded and validated so far (every kExpandProgressEvery
/// points, and at the end).
using ExpandProgress = std::function<void(std::size_t done, std::size_t total)>;
inline constexpr std::size_t kExpandProgressEvery = 1000;

struct SweepKind;  // sweep_kind.h
/// Expands the spec by its kind's planner (sweep_kind.h): each point is checked once, here, and
/// its jobs store the checked scenario. Shared jobs (an impact sweep's beds) come first, in order
/// of first use, then the points' jobs in product order. Problems of the base or of points
/// (invalid scenarios) throw one SpecError naming each field and point.
std::vector<queue::PlannedJob> expand(const SweepSpec& spec, const SweepKind& kind,
                                      const ExpandProgress& progress = {});
/// The same by the registered kind the spec names (its "job").
std::vector<queue::PlannedJob> expand(const SweepSpec& spec, const ExpandProgress& progress = {});

/// What expanding and validating a sweep takes, estimated from its points and the size of its
/// scenario before any of it is done: memory held by its planned jobs (each point's scenario as a
/// JSON tree), and time on one core (measured figures in BENCHMARKS.md, "Sweep expansion").
struct ExpansionCost {
  double points = 0;
  double memory_bytes = 0;
  double seconds = 0;
};
ExpansionCost expansion_cost(const SweepSpec& spec);
/// Physical memory of this machine in bytes (0 when unknown).
double machine_memory_bytes();
/// A sweep whose expansion would need more than this share of the machine's memory, or longer
/// than kMaxExpansionSeconds, is refused by load_spec with both estimates and the limits.
inline constexpr double kMaxExpansionMemoryFraction = 0.5;
inline constexpr double kMaxExpansionSeconds = 1800;

/// The column name an axis without "name" gets: its pointer's tokens, lower case, joined by '_'
/// ("/drop/speed_m_s" -> "drop_speed_m_s"); checked by the schema's rule for column names.
std::string column_from_pointer(const std::string& pointer);

}  // namespace gravsweep::sweep
