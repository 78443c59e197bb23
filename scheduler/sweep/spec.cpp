#include "scheduler/sweep/spec.h"
#include "scheduler/sweep/sweep_kind.h"

#include "spec/problems.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include <unistd.h>

#include "scheduler/queue/canonical.h"
#include "spec/json_pointer.h"
#include "spec/json_schema.h"
#include "spec/schemas.h"

namespace gravsweep::sweep {

using nlohmann::json;

// A sweep spec is checked in two passes, and every problem of both is reported at once:
//  1. schemas/sweep.schema.json (spec/schemas.h): types, names, ranges, unknown and missing
//     fields, exactly one of values/range/count, unique values;
//  2. below, what a schema cannot say: the base scenario file, pointers present in the base, values
//     of the base field's type, range and repeat expansion, zip lengths, a field swept twice; the
//     kind's own checks (the sweep's "job", sweep_kind.h) come at expansion. An axis the schema
//     already found bad is not checked again.

namespace {

std::string join(const std::string& ptr, const std::string& token) { return spec::pointer_child(ptr, token); }
std::string join(const std::string& ptr, std::size_t i) { return ptr + "/" + std::to_string(i); }

using spec::Problems;

/// The kind a swept value must share with the base field: its JSON type, numbers all alike (10 and
/// 9.81 are both numbers).
std::string value_kind(const json& v) { return v.is_number() ? "number" : spec::type_name(v); }

/// The field an axis sets, looked up in the base; nullptr (reported) when it is not there.
const json* base_field(const json& a, const std::string& ptr, const json* base, Problems& ck) {
  const std::string pointer = a["pointer"].get<std::string>();
  try {
    const json::json_pointer jp(pointer);
    if (!base) return nullptr;  // the base could not be read (reported at /base)
    if (base->contains(jp)) return &base->at(jp);
    ck.add(join(ptr, "pointer"), a["pointer"],
           "a pointer to a field present in the base scenario (to sweep a default, write the field into the base)");
  } catch (const json::exception&) {
    ck.add(join(ptr, "pointer"), a["pointer"], "a valid JSON pointer (RFC 6901)");
  }
  return nullptr;
}

/// The values of a range {start, stop, step | num}; nothing when it is refused (reported).
std::optional<std::vector<json>> range_values(const json& r, const std::string& rp, bool integer_base, Problems& ck) {
  std::vector<json> values;
  const double start = r["start"].get<double>(), stop = r["stop"].get<double>();
  if (r.contains("num")) {
    const long num = r["num"].get<long>();
    for (long i = 0; i < num; ++i)
      values.emplace_back(num == 1 ? start
                                   : queue::round_decimal(start + (stop - start) * static_cast<double>(i) /
                                                                      static_cast<double>(num - 1)));
    return values;
  }
  const double step = r["step"].get<double>();
  if (stop < start) {
    ck.add(join(rp, "stop"), r["stop"], fmt::format("a number >= start ({})", start));
    return std::nullopt;
  }
  // Inclusive of stop up to rounding: n = floor((stop - start) / step + 1e-9) + 1.
  const double n = std::floor((stop - start) / step + 1e-9) + 1;
  if (n > 1e6) {
    ck.add(join(rp, "step"), r["step"], "a step giving at most 1000000 values");
    return std::nullopt;
  }
  const bool ints = spec::is_exact_integer(r["start"]) && spec::is_exact_integer(r["stop"]) &&
                    spec::is_exact_integer(r["step"]) && integer_base;
  for (long i = 0; i < static_cast<long>(n); ++i) {
    const double v = queue::round_decimal(start + static_cast<double>(i) * step);
    values.push_back(ints ? json(static_cast<std::int64_t>(std::llround(v))) : json(v));
  }
  return values;
}

/// The values of repeats {count, start, step} (defaults inserted by the schema); an integer base
/// value (a seed) needs integer start and step (reported there).
std::optional<std::vector<json>> repeat_values(const json& a, const std::string& ptr, const json* base_value,
                                               const std::string& pointer, Problems& ck) {
  const json &start = a["start"], &step = a["step"];
  if (base_value && base_value->is_number_integer()) {
    bool ok = true;
    for (const char* k : {"start", "step"})
      if (!spec::is_exact_integer(a[k])) {
        ck.add(join(ptr, k), a[k],
               fmt::format("an integer like the base value at {} ({})", pointer, base_value->dump()));
        ok = false;
      }
    if (!ok) return std::nullopt;
  }
  std::vector<json> values;
  const bool ints = spec::is_exact_integer(start) && spec::is_exact_integer(step);
  for (long i = 0; i < a["count"].get<long>(); ++i) {
    if (ints)
      values.emplace_back(static_cast<std::int64_t>(std::llround(start.get<double>())) +
                          i * static_cast<std::int64_t>(std::llround(step.get<double>())));
    else
      values.emplace_back(queue::round_decimal(start.get<double>() + static_cast<double>(i) * step.get<double>()));
  }
  return values;
}

/// Reads one axis the schema found sound ({name?, pointer, values | range} or, for repeats,
/// {name?, pointer, values | count/start/step}): the checks across fields.
std::optional<Axis> parse_axis(const json& a, const std::string& ptr, const json* base, Problems& ck) {
  Axis axis;
  axis.pointer = a["pointer"].get<std::string>();
  const json* base_value = base_field(a, ptr, base, ck);
  bool ok = base == nullptr || base_value != nullptr;
  if (a.contains("name")) {
    axis.name = a["name"].get<std::string>();
  } else {
    // The column name derived from the pointer obeys the schema's rule for a written one.
    json derived = column_from_pointer(axis.pointer);
    std::vector<SpecProblem> bad;
    spec::validator(spec::Schema::sweep).collect_definition(derived, "column", join(ptr, "pointer"), bad);
    if (!bad.empty()) {
      ck.add(join(ptr, "pointer"), a["pointer"],
             fmt::format("a pointer whose tokens make a column name (\"{}\" is not one), or an explicit \"name\" "
                         "[a-z_][a-z0-9_]*",
                         derived.get<std::string>()));
      ok = false;
    }
    axis.name = derived.get<std::string>();
  }
  std::optional<std::vector<json>> values;
  std::string values_ptr;
  if (a.contains("values")) {
    values = a["values"].get<std::vector<json>>();
    values_ptr = join(ptr, "values");
  } else if (a.contains("range")) {
    values_ptr = join(ptr, "range");
    values = range_values(a["range"], values_ptr, base_value && base_value->is_number_integer(), ck);
  } else {
    values_ptr = join(ptr, "count");
    values = repeat_values(a, ptr, base_value, axis.pointer, ck);
  }
  if (!values) return std::nullopt;
  axis.values = std::move(*values);
  if (!base_value) return ok ? std::optional<Axis>(std::move(axis)) : std::nullopt;

  // Each value: a value of the base field's kind; canonical form; no two the same.
  std::set<std::string> seen;
  for (std::size_t i = 0; i < axis.values.size(); ++i) {
    const json& v = axis.values[i];
    const std::string vp = a.contains("values") ? join(values_ptr, i) : values_ptr;
    if (!base_value->is_null() && value_kind(v) != value_kind(*base_value)) {
      ck.add(vp, v,
             fmt::format("a {} like the base value at {} ({})", value_kind(*base_value), axis.pointer,
                         base_value->dump()));
      ok = false;
      continue;
    }
    axis.values[i] = queue::canonicalize(v);
    if (ok && !seen.insert(queue::canonical_json(axis.values[i])).second) {
      ck.add(vp, axis.values[i], "values that differ from each other (this one repeats an earlier value)");
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return axis;
}

/// The base scenario: inline, or a file relative to the spec (read here). Nothing when it cannot be
/// read (reported).
std::optional<json> read_base(const json& doc, const std::filesystem::path& base_dir, Problems& ck) {
  if (doc["base"].is_object()) return doc["base"];
  const std::filesystem::path p = base_dir / doc["base"].get<std::string>();
  try {
    json base = spec::read_spec_file(p, spec::Schema::scenario);
    if (base.is_object()) return base;
    ck.add("/base", doc["base"],
           fmt::format("a file holding a JSON object ('{}' holds {})", p.string(), value_kind(base)));
  } catch (const SpecError& e) {
    ck.add("/base", doc["base"], fmt::format("{} ('{}' is {})", e.expected(), e.source(), e.found()));
  }
  return std::nullopt;
}

/// The axes and repeats into groups: a zip of equal lengths is one group; no column name or field
/// twice. Axes the schema found bad are skipped (already reported).
void read_axes(const json& doc, const json* base, const Problems& schema_problems, SweepSpec& spec, Problems& ck) {
  std::set<std::string> names, pointers;
  auto add_group = [&](AxisGroup g, const std::string& ptr) {
    for (const auto& a : g.axes) {
      if (!names.insert(a.name).second)
        ck.add_text(ptr, fmt::format("column name \"{}\" used twice", a.name), "distinct axis names");
      if (!pointers.insert(a.pointer).second)
        ck.add_text(ptr, fmt::format("pointer \"{}\" swept twice", a.pointer), "each field swept by one axis only");
    }
    spec.groups.push_back(std::move(g));
  };
  const json axes = doc.value("axes", json::array());
  for (std::size_t i = 0; i < axes.size(); ++i) {
    const std::string ap = join("/axes", i);
    if (schema_problems.at_or_below(ap)) continue;
    if (!axes[i].contains("zip")) {
      if (auto axis = parse_axis(axes[i], ap, base, ck)) add_group(AxisGroup{{std::move(*axis)}}, ap);
      continue;
    }
    const json& z = axes[i]["zip"];
    AxisGroup g;
    bool ok = true;
    for (std::size_t k = 0; k < z.size(); ++k) {
      auto axis = parse_axis(z[k], join(join(ap, "zip"), k), base, ck);
      if (!axis) {
        ok = false;
      } else if (!g.axes.empty() && axis->values.size() != g.axes.front().values.size()) {
        ck.add_text(join(join(ap, "zip"), k), fmt::format("{} values", axis->values.size()),
                    fmt::format("{} values, as many as {}/zip/0", g.axes.front().values.size(), ap));
        ok = false;
      } else {
        g.axes.push_back(std::move(*axis));
      }
    }
    if (ok) add_group(std::move(g), ap);
  }
  if (doc.contains("repeats") && !schema_problems.at_or_below("/repeats"))
    if (auto axis = parse_axis(doc["repeats"], "/repeats", base, ck))
      add_group(AxisGroup{{std::move(*axis)}}, "/repeats");
}

/// Nodes of a JSON tree (every value, object and array counted once).
double json_nodes(const json& j) {
  double n = 1;
  if (j.is_structured())
    for (const auto& v : j) n += json_nodes(v);
  return n;
}

/// Refuses a sweep whose expansion would not fit this machine (expansion_cost), saying what it
/// would take and what is allowed.
void refuse_costly(const SweepSpec& spec, const std::string& file) {
  const ExpansionCost c = expansion_cost(spec);
  const double memory = machine_memory_bytes();
  const double max_bytes = memory > 0 ? kMaxExpansionMemoryFraction * memory : 8e9;
  if (c.memory_bytes <= max_bytes && c.seconds <= kMaxExpansionSeconds) return;
  const double fit =
      std::floor(c.points * std::min(max_bytes / c.memory_bytes, kMaxExpansionSeconds / std::max(c.seconds, 1e-9)));
  throw SpecError::sweep_spec(
      file, {{"/axes",
              fmt::format("{:.0f} points, which would take about {:.1f} GB of memory and {:.0f} min to expand and "
                          "validate ({:.0f} bytes and {:.0f} us a point)",
                          c.points, c.memory_bytes / 1e9, c.seconds / 60, c.memory_bytes / c.points,
                          1e6 * c.seconds / c.points),
              fmt::format("a sweep that fits in {:.0f} % of this machine's {:.1f} GB ({:.1f} GB) and {:.0f} min: about "
                          "{:.0f} points with this scenario; split it into several specs (submitted one after another)",
                          100 * kMaxExpansionMemoryFraction, memory / 1e9, max_bytes / 1e9, kMaxExpansionSeconds / 60,
                          fit)}});
}

}  // namespace

double machine_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
}

ExpansionCost expansion_cost(const SweepSpec& spec) {
  // Calibrated on examples/sweep_tiny.json's scenario swept to 200,000 points (BENCHMARKS.md,
  // "Sweep expansion"): bytes and seconds per node of the base scenario, and per point. The bytes
  // are mostly each job's stored scenario, validated with its defaults filled (2 kB of text here).
  constexpr double kBytesPerNode = 140, kBytesPerPoint = 950, kSecondsPerNode = 1e-5, kSecondsPerPoint = 2.5e-5;
  ExpansionCost c;
  c.points = 1;
  for (const auto& g : spec.groups) c.points *= static_cast<double>(g.size());
  const double nodes = json_nodes(spec.base);
  c.memory_bytes = c.points * (kBytesPerNode * nodes + kBytesPerPoint);
  c.seconds = c.points * (kSecondsPerNode * nodes + kSecondsPerPoint);
  return c;
}

std::size_t SweepSpec::points() const {
  std::size_t n = 1;
  for (const auto& g : groups) n *= g.size();
  return n;
}

std::string column_from_pointer(const std::string& pointer) {
  std::string out;
  for (char c : pointer) {
    if (c == '/') {
      if (!out.empty()) out.push_back('_');
    } else if (std::isalnum(static_cast<unsigned char>(c)) || c == '_') {
      out.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
    } else {
      out.push_back('_');
    }
  }
  return out;
}

namespace {

/// The one reader of a spec's parsed text: schema-checked (its defaults filled in `doc`), the
/// rules across fields, then the record. `doc` is the parse of the text and goes no further.
SweepSpec spec_of(json doc, const std::string& file, const std::filesystem::path& base_dir) {
  json written = doc;  // the spec as written, before the schema fills its defaults: the stored text
  Problems problems;   // the schema's; then the rules across fields add theirs to `ck`
  spec::validator(spec::Schema::sweep).collect(doc, problems.list());
  if (!doc.is_object()) throw SpecError::sweep_spec(file, problems.list());
  SweepSpec spec;
  auto sound = [&](const char* ptr) { return doc.contains(ptr + 1) && !problems.at_or_below(ptr); };
  if (sound("/sweep")) spec.name = doc["sweep"].get<std::string>();
  if (sound("/job")) spec.job_kind = doc["job"].get<std::string>();
  if (sound("/max_attempts")) spec.max_attempts = doc["max_attempts"].get<int>();
  if (sound("/priority")) spec.priority = doc["priority"].get<int>();

  Problems ck;
  std::optional<json> base;
  if (sound("/base")) base = read_base(doc, base_dir, ck);
  if (base) {
    try {
      spec.base = queue::canonicalize(*base);
    } catch (const queue::CanonicalError& e) {
      ck.add_text("/base", e.what(), "finite numbers only");
      base.reset();
    }
  }
  read_axes(doc, base ? &spec.base : nullptr, problems, spec, ck);
  problems.append(ck);
  if (!problems.empty()) throw SpecError::sweep_spec(file, problems.list());
  refuse_costly(spec, file);
  written["base"] = spec.base;
  spec.spec_json = queue::canonical_json(written);
  for (const auto& g : spec.groups)
    for (const auto& a : g.axes) spec.columns.emplace_back(a.name, a.values);
  spec.file = file;
  return spec;
}

}  // namespace

SweepSpec load_spec(const std::filesystem::path& path) {
  return spec_of(spec::read_spec_file(path, spec::Schema::sweep), path.string(), path.parent_path());
}

SweepSpec load_spec_text(const std::string& text, const std::string& file, const std::filesystem::path& base_dir) {
  return spec_of(spec::parse_spec_text(text, file, spec::Schema::sweep), file, base_dir);
}

namespace {

/// The scenario of point p as written (the base with its swept values: its mixed-radix digits,
/// last group fastest) into `scenario`, and its job with the swept values.
queue::PlannedJob point_job(const SweepSpec& spec, std::size_t p, json& scenario) {
  queue::PlannedJob job;
  scenario = spec.base;
  job.params = json::object();
  std::size_t rem = p;
  for (std::size_t g = spec.groups.size(); g-- > 0;) {
    const std::size_t i = rem % spec.groups[g].size();
    rem /= spec.groups[g].size();
    for (const auto& axis : spec.groups[g].axes) {
      scenario[json::json_pointer(axis.pointer)] = axis.values[i];
      job.params[axis.name] = axis.values[i];
    }
  }
  job.priority = spec.priority;
  return job;
}

}  // namespace

std::vector<queue::PlannedJob> expand(const SweepSpec& spec, const SweepKind& kind, const ExpandProgress& progress) {
  const std::string file = spec.file.empty() ? spec.name : spec.file;
  if (kind.check_base) {
    auto problems = kind.check_base(spec);
    if (!problems.empty()) throw SpecError::sweep_spec(file, problems);
  }
  Plan plan;
  const std::size_t n = spec.points();
  for (std::size_t p = 0; p < n; ++p) {
    if (progress && p % kExpandProgressEvery == 0) progress(p, n);
    json scenario;
    queue::PlannedJob job = point_job(spec, p, scenario);
    kind.plan_point(spec, scenario, std::move(job), plan);
  }
  if (progress) progress(n, n);
  return plan.finish(file);
}

std::vector<queue::PlannedJob> expand(const SweepSpec& spec, const ExpandProgress& progress) {
  return expand(spec, sweep_kind(spec.job_kind, spec.file.empty() ? spec.name : spec.file), progress);
}

}  // namespace gravsweep::sweep
