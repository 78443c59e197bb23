#include "scheduler/sweep/spec.h"

#include "scheduler/sweep/json_text.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "scheduler/pipeline/json_pointer.h"
#include "scheduler/pipeline/json_schema.h"
#include "scheduler/sweep/canonical.h"

namespace gravsweep::sweep {

using nlohmann::json;

namespace {

std::string type_name(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return "boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned: return "integer";
    case json::value_t::number_float: return "number";
    case json::value_t::string: return "string";
    case json::value_t::array: return "array";
    case json::value_t::object: return "object";
    default: return "value";
  }
}

std::string show(const json& v) {
  std::string s = v.dump();
  if (s.size() > 80) s = s.substr(0, 77) + "...";
  return s + " (" + type_name(v) + ")";
}

std::string join(const std::string& ptr, const std::string& token) { return pipeline::pointer_child(ptr, token); }
std::string join(const std::string& ptr, std::size_t i) { return ptr + "/" + std::to_string(i); }

bool is_int(const json& v) {
  if (v.is_number_integer()) return true;
  if (v.is_number_float()) {
    const double d = v.get<double>();
    return std::isfinite(d) && std::floor(d) == d && std::abs(d) < 9007199254740992.0;
  }
  return false;
}

/// Collects problems while walking the document.
struct Checker {
  std::vector<SpecProblem> problems;
  void add(const std::string& ptr, const json* found, std::string expected) {
    problems.push_back({ptr, found ? show(*found) : std::string("missing"), std::move(expected)});
  }
  void add_text(const std::string& ptr, std::string found, std::string expected) {
    problems.push_back({ptr, std::move(found), std::move(expected)});
  }
  /// Unknown keys are errors (a typo in a key silently ignored is the worst outcome).
  void known_keys(const json& obj, const std::string& ptr, const std::set<std::string>& keys) {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      if (keys.count(it.key())) continue;
      std::string list;
      for (const auto& k : keys) list += (list.empty() ? "" : ", ") + k;
      add_text(join(ptr, it.key()), fmt::format("unknown key \"{}\"", it.key()), "one of: " + list);
    }
  }
};

/// Problems of a no-op job's scenario: (pointer, found, expected). sleep_s and fail_attempts are
/// what the no-op runner reads; anything else is carried along (an axis may sweep any field).
std::vector<SpecProblem> noop_problems(const json& s, const std::string& ptr) {
  std::vector<SpecProblem> out;
  if (!s.is_object()) return {{ptr, show(s), "an object (the no-op job's scenario)"}};
  if (s.contains("sleep_s") && (!s["sleep_s"].is_number() || !(s["sleep_s"].get<double>() >= 0) ||
                                s["sleep_s"].get<double>() > 86400))
    out.push_back({join(ptr, "sleep_s"), show(s["sleep_s"]), "a number of seconds between 0 and 86400"});
  if (s.contains("fail_attempts") && (!is_int(s["fail_attempts"]) || s["fail_attempts"].get<double>() < 0 ||
                                      s["fail_attempts"].get<double>() > 100))
    out.push_back({join(ptr, "fail_attempts"), show(s["fail_attempts"]), "an integer between 0 and 100"});
  return out;
}

std::string pointer_kind(const json& v) {
  if (v.is_number()) return "number";
  return type_name(v);
}

/// Reads one axis (object with name?, pointer, values | range | count/start for repeats).
std::optional<Axis> parse_axis(const json& a, const std::string& ptr, const json& base, Checker& ck,
                               bool repeats) {
  if (!a.is_object()) {
    ck.add(ptr, &a, repeats ? "an object {pointer, count[, start]} or {pointer, values}"
                            : "an object {name?, pointer, values | range} or {zip: [...]}");
    return std::nullopt;
  }
  ck.known_keys(a, ptr, repeats ? std::set<std::string>{"name", "pointer", "values", "count", "start", "step"}
                                : std::set<std::string>{"name", "pointer", "values", "range", "description"});
  Axis axis;
  bool ok = true;
  const json* base_value = nullptr;
  if (!a.contains("pointer")) {
    ck.add(join(ptr, "pointer"), nullptr, "a JSON pointer string into the base scenario, e.g. \"/gravity_m_s2\"");
    ok = false;
  } else if (!a["pointer"].is_string() || a["pointer"].get<std::string>().empty() ||
             a["pointer"].get<std::string>()[0] != '/') {
    ck.add(join(ptr, "pointer"), &a["pointer"], "a JSON pointer string starting with '/', e.g. \"/gravity_m_s2\"");
    ok = false;
  } else {
    axis.pointer = a["pointer"].get<std::string>();
    try {
      const json::json_pointer jp(axis.pointer);
      if (!base.is_object()) {
        // The base could not be read (its problem is reported at /base): nothing to look the pointer up in.
      } else if (!base.contains(jp)) {
        ck.add(join(ptr, "pointer"), &a["pointer"], "a pointer to a field present in the base scenario (to sweep a default, write the field into the base)");
        ok = false;
      } else {
        base_value = &base.at(jp);
      }
    } catch (const json::exception&) {
      ck.add(join(ptr, "pointer"), &a["pointer"], "a valid JSON pointer (RFC 6901)");
      ok = false;
    }
  }
  if (a.contains("name")) {
    if (!a["name"].is_string() || !valid_column_name(a["name"].get<std::string>())) {
      ck.add(join(ptr, "name"), &a["name"], "a column name [a-z_][a-z0-9_]* with units, e.g. \"gravity_m_s2\", not one of the fixed results columns (job_id, sweep, kind, attempt, ...)");
      ok = false;
    } else {
      axis.name = a["name"].get<std::string>();
    }
  } else if (!axis.pointer.empty()) {
    axis.name = column_from_pointer(axis.pointer);
    if (!valid_column_name(axis.name)) {
      ck.add(join(ptr, "pointer"), &a["pointer"],
             "a pointer whose tokens make a column name, or an explicit \"name\" [a-z_][a-z0-9_]*");
      ok = false;
    }
  }

  // Values.
  const int sources = int(a.contains("values")) + int(a.contains("range")) + int(a.contains("count"));
  if (sources != 1) {
    ck.add_text(ptr, sources == 0 ? "none of values/range" + std::string(repeats ? "/count" : "")
                                  : "more than one of values/range/count",
                repeats ? "exactly one of \"values\" or \"count\"" : "exactly one of \"values\" or \"range\"");
    return std::nullopt;
  }
  if (a.contains("values")) {
    const json& vs = a["values"];
    if (!vs.is_array() || vs.empty()) {
      ck.add(join(ptr, "values"), &vs, "a non-empty array of values");
      return std::nullopt;
    }
    for (std::size_t i = 0; i < vs.size(); ++i) axis.values.push_back(vs[i]);
  } else if (a.contains("range")) {
    const json& r = a["range"];
    const std::string rp = join(ptr, "range");
    if (!r.is_object()) {
      ck.add(rp, &r, "an object {start, stop, step} or {start, stop, num}");
      return std::nullopt;
    }
    ck.known_keys(r, rp, {"start", "stop", "step", "num"});
    bool rok = true;
    for (const char* k : {"start", "stop"}) {
      if (!r.contains(k) || !r[k].is_number()) {
        ck.add(join(rp, k), r.contains(k) ? &r[k] : nullptr, "a number");
        rok = false;
      }
    }
    if (r.contains("step") == r.contains("num")) {
      ck.add_text(rp, r.contains("step") ? "both step and num" : "neither step nor num",
                  "exactly one of \"step\" (positive number) or \"num\" (integer >= 1)");
      rok = false;
    }
    if (r.contains("step") && (!r["step"].is_number() || !(r["step"].get<double>() > 0))) {
      ck.add(join(rp, "step"), &r["step"], "a positive number");
      rok = false;
    }
    if (r.contains("num") && (!is_int(r["num"]) || r["num"].get<double>() < 1 || r["num"].get<double>() > 1e6)) {
      ck.add(join(rp, "num"), &r["num"], "an integer between 1 and 1000000");
      rok = false;
    }
    if (!rok) return std::nullopt;
    const double start = r["start"].get<double>(), stop = r["stop"].get<double>();
    const bool ints = is_int(r["start"]) && is_int(r["stop"]) && (!r.contains("step") || is_int(r["step"])) &&
                      base_value && base_value->is_number_integer();
    if (r.contains("step")) {
      const double step = r["step"].get<double>();
      if (stop < start) {
        ck.add(join(rp, "stop"), &r["stop"], fmt::format("a number >= start ({})", start));
        return std::nullopt;
      }
      // Inclusive of stop up to rounding: n = floor((stop - start) / step + 1e-9) + 1.
      const double n = std::floor((stop - start) / step + 1e-9) + 1;
      if (n > 1e6) {
        ck.add(join(rp, "step"), &r["step"], "a step giving at most 1000000 values");
        return std::nullopt;
      }
      for (long i = 0; i < static_cast<long>(n); ++i) {
        const double v = round_decimal(start + static_cast<double>(i) * step);
        axis.values.push_back(ints ? json(static_cast<std::int64_t>(std::llround(v))) : json(v));
      }
    } else {
      const long num = static_cast<long>(r["num"].get<double>());
      for (long i = 0; i < num; ++i) {
        const double v = num == 1 ? start : round_decimal(start + (stop - start) * static_cast<double>(i) /
                                                                      static_cast<double>(num - 1));
        axis.values.push_back(json(v));
      }
    }
  } else {  // repeats: count/start/step
    const json& c = a["count"];
    if (!is_int(c) || c.get<double>() < 1 || c.get<double>() > 1e6) {
      ck.add(join(ptr, "count"), &c, "an integer between 1 and 1000000");
      return std::nullopt;
    }
    json start = a.value("start", json(0)), step = a.value("step", json(1));
    if (!start.is_number()) {
      ck.add(join(ptr, "start"), &a["start"], "a number");
      return std::nullopt;
    }
    if (!step.is_number()) {
      ck.add(join(ptr, "step"), &a["step"], "a number");
      return std::nullopt;
    }
    // Repeats number seeds: an integer base value needs integer start and step (reported there).
    if (base_value && base_value->is_number_integer()) {
      bool iok = true;
      for (const char* k : {"start", "step"})
        if (a.contains(k) && !is_int(a[k])) {
          ck.add(join(ptr, k), &a[k], fmt::format("an integer like the base value at {} ({})", axis.pointer,
                                                  base_value->dump()));
          iok = false;
        }
      if (!iok) return std::nullopt;
    }
    const bool ints = is_int(start) && is_int(step);
    for (long i = 0; i < static_cast<long>(c.get<double>()); ++i) {
      if (ints)
        axis.values.push_back(json(static_cast<std::int64_t>(std::llround(start.get<double>())) +
                                   i * static_cast<std::int64_t>(std::llround(step.get<double>()))));
      else
        axis.values.push_back(json(round_decimal(start.get<double>() + static_cast<double>(i) * step.get<double>())));
    }
  }

  // Each value: a finite value of the base field's type; canonical form.
  if (base_value) {
    const std::string values_ptr = a.contains("values") ? join(ptr, "values") : a.contains("range") ? join(ptr, "range") : join(ptr, "count");
    for (std::size_t i = 0; i < axis.values.size(); ++i) {
      const json& v = axis.values[i];
      const std::string vp = a.contains("values") ? join(values_ptr, i) : values_ptr;
      if (!base_value->is_null() && pointer_kind(v) != pointer_kind(*base_value)) {
        ck.add(vp, &v, fmt::format("a {} like the base value at {} ({})", pointer_kind(*base_value), axis.pointer,
                                   base_value->dump()));
        ok = false;
      } else {  // numbers are numbers: 10 in the base and 9.81 on an axis are both numbers
        axis.values[i] = canonicalize(v);
      }
    }
    // Duplicate values make duplicate jobs: refuse them.
    std::set<std::string> seen;
    for (std::size_t i = 0; i < axis.values.size() && ok; ++i) {
      if (!seen.insert(canonical_json(axis.values[i])).second) {
        ck.add(a.contains("values") ? join(values_ptr, i) : values_ptr, &axis.values[i],
               "values that differ from each other (this one repeats an earlier value)");
        ok = false;
      }
    }
  }
  if (!ok) return std::nullopt;
  return axis;
}

}  // namespace

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

bool valid_column_name(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  static const std::set<std::string> reserved = {"job_id",     "sweep",        "kind",        "bed_job_id",
                                                 "attempt",    "trace_path",   "trace_sha256", "trace_bytes",
                                                 "runtime_s",  "finished_at",  "code_version"};
  if (reserved.count(name)) return false;
  if (!(std::islower(static_cast<unsigned char>(name[0])) || name[0] == '_')) return false;
  for (char c : name)
    if (!(std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) || c == '_'))
      return false;
  return true;
}

SweepSpec parse_spec(const json& doc, const std::string& file, const std::filesystem::path& base_dir) {
  Checker ck;
  SweepSpec spec;
  if (!doc.is_object()) {
    ck.add("", &doc, "an object {sweep, base, axes, ...}");
    throw SpecError::sweep_spec(file, ck.problems);
  }
  ck.known_keys(doc, "", {"$schema", "sweep", "description", "job", "base", "axes", "repeats", "max_attempts",
                          "priority"});
  if (!doc.contains("sweep")) {
    ck.add("/sweep", nullptr, "a sweep name string [A-Za-z0-9_.-]+");
  } else if (!doc["sweep"].is_string() || doc["sweep"].get<std::string>().empty() ||
             doc["sweep"].get<std::string>().find_first_not_of(
                 "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-") != std::string::npos) {
    ck.add("/sweep", &doc["sweep"], "a sweep name string [A-Za-z0-9_.-]+");
  } else {
    spec.name = doc["sweep"].get<std::string>();
  }
  if (doc.contains("description") && !doc["description"].is_string())
    ck.add("/description", &doc["description"], "a string");
  if (doc.contains("job")) {
    if (!doc["job"].is_string() || (doc["job"] != "impact" && doc["job"] != "noop"))
      ck.add("/job", &doc["job"], "\"impact\" (bed + drop jobs, the default) or \"noop\" (scheduler benchmark)");
    else
      spec.job_kind = doc["job"].get<std::string>();
  }
  for (const char* k : {"max_attempts", "priority"}) {
    if (!doc.contains(k)) continue;
    const bool attempts = std::string(k) == "max_attempts";
    if (!is_int(doc[k]) || (attempts && (doc[k].get<double>() < 1 || doc[k].get<double>() > 100)) ||
        std::abs(doc[k].get<double>()) > 1e6)
      ck.add(std::string("/") + k, &doc[k], attempts ? "an integer between 1 and 100" : "an integer");
    else if (attempts)
      spec.max_attempts = static_cast<int>(doc[k].get<double>());
    else
      spec.priority = static_cast<int>(doc[k].get<double>());
  }

  // Base scenario: inline object or a file name relative to the spec.
  json base;
  bool have_base = false;
  if (!doc.contains("base")) {
    ck.add("/base", nullptr, "the base scenario: an object, or a file name relative to the spec");
  } else if (doc["base"].is_string()) {
    const std::filesystem::path p = base_dir / doc["base"].get<std::string>();
    std::string why;
    const auto text = read_text_file(p, why);
    if (!text) {
      ck.add("/base", &doc["base"], fmt::format("a readable scenario file ('{}' is {})", p.string(), why));
    } else if (const auto err = parse_json_text(*text, base)) {
      ck.add("/base", &doc["base"], fmt::format("a JSON scenario file ('{}': {} at {})", p.string(), err->what, err->where()));
    } else if (!base.is_object()) {
      ck.add("/base", &doc["base"], fmt::format("a file holding a JSON object ('{}' holds {})", p.string(), type_name(base)));
    } else {
      have_base = true;
    }
  } else if (doc["base"].is_object()) {
    base = doc["base"];
    have_base = true;
  } else {
    ck.add("/base", &doc["base"], "an object (the base scenario) or a file name string");
  }
  if (have_base) {
    try {
      spec.base = canonicalize(base);
    } catch (const CanonicalError& e) {
      ck.add_text("/base", e.what(), "finite numbers only");
    }
  }

  if (have_base && spec.job_kind == "noop")
    for (auto& p : noop_problems(spec.base, "/base")) ck.problems.push_back(std::move(p));

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
  if (doc.contains("axes")) {
    const json& axes = doc["axes"];
    if (!axes.is_array()) {
      ck.add("/axes", &axes, "an array of axes");
    } else {
      for (std::size_t i = 0; i < axes.size(); ++i) {
        const std::string ap = join("/axes", i);
        const json& a = axes[i];
        if (a.is_object() && a.contains("zip")) {
          ck.known_keys(a, ap, {"zip", "description"});
          const json& z = a["zip"];
          if (!z.is_array() || z.size() < 2) {
            ck.add(join(ap, "zip"), &z, "an array of at least two axes that vary together");
            continue;
          }
          AxisGroup g;
          bool ok = true;
          for (std::size_t k = 0; k < z.size(); ++k) {
            auto axis = parse_axis(z[k], join(join(ap, "zip"), k), base, ck, false);
            if (!axis) {
              ok = false;
              continue;
            }
            if (!g.axes.empty() && axis->values.size() != g.axes.front().values.size()) {
              ck.add_text(join(join(ap, "zip"), k), fmt::format("{} values", axis->values.size()),
                          fmt::format("{} values, as many as {}/zip/0", g.axes.front().values.size(), ap));
              ok = false;
              continue;
            }
            g.axes.push_back(std::move(*axis));
          }
          if (ok) add_group(std::move(g), ap);
        } else if (auto axis = parse_axis(a, ap, base, ck, false)) {
          add_group(AxisGroup{{std::move(*axis)}}, ap);
        }
      }
    }
  }
  if (doc.contains("repeats")) {
    if (auto axis = parse_axis(doc["repeats"], "/repeats", base, ck, true))
      add_group(AxisGroup{{std::move(*axis)}}, "/repeats");
  }
  if (!ck.problems.empty()) throw SpecError::sweep_spec(file, ck.problems);
  if (spec.points() > 5'000'000)
    throw SpecError::sweep_spec(file,
                                {{"/axes", fmt::format("{} points", spec.points()), "at most 5000000 points per sweep"}});
  spec.source = doc;
  spec.source["base"] = spec.base;
  spec.file = file;
  return spec;
}

SweepSpec load_spec(const std::filesystem::path& path) {
  std::string why;
  const auto text = read_text_file(path, why);
  if (!text) throw SpecError::sweep_spec(path.string(), {{"", why, "a JSON sweep spec file"}});
  json doc;
  if (const auto err = parse_json_text(*text, doc))
    throw SpecError::sweep_spec(path.string(), {{"", fmt::format("{} at {}", err->what, err->where()), "valid JSON"}});
  return parse_spec(doc, path.string(), path.parent_path());
}

std::vector<PlannedJob> expand(const SweepSpec& spec, const BedKeyFn& bed_key) {
  std::vector<PlannedJob> beds, drops;
  std::map<std::string, std::size_t> bed_index;
  const std::size_t n = spec.points();
  std::vector<std::size_t> idx(spec.groups.size(), 0);
  std::vector<SpecProblem> problems;
  std::vector<std::size_t> repeats;
  // A problem of a base field no axis replaces is reported once, at its pointer under /base; a
  // swept field is checked at each point instead (its base value may be a placeholder).
  auto swept = [&](const std::string& pointer) {
    for (const auto& g : spec.groups)
      for (const auto& ax : g.axes)
        if (pointer == ax.pointer || pointer.rfind(ax.pointer + "/", 0) == 0 || ax.pointer.rfind(pointer + "/", 0) == 0)
          return true;
    return false;
  };
  if (spec.job_kind != "noop" && bed_key) {
    try {
      (void)bed_key(spec.base);
    } catch (const pipeline::SpecError& e) {
      for (const auto& p : e.problems())
        if (!swept(p.pointer)) problems.push_back({"/base" + p.pointer, p.found, p.expected});
      if (!problems.empty()) throw SpecError::sweep_spec(spec.file.empty() ? spec.name : spec.file, problems);
    } catch (const std::exception&) {
      // Not checkable alone (e.g. a field every axis sets): the points report it.
    }
  }
  drops.reserve(n);
  for (std::size_t p = 0; p < n; ++p) {
    // Mixed-radix digits of p, last group fastest.
    std::size_t rem = p;
    for (std::size_t g = spec.groups.size(); g-- > 0;) {
      idx[g] = rem % spec.groups[g].size();
      rem /= spec.groups[g].size();
    }
    PlannedJob job;
    job.scenario = spec.base;
    job.params = json::object();
    for (std::size_t g = 0; g < spec.groups.size(); ++g) {
      for (const auto& axis : spec.groups[g].axes) {
        job.scenario[json::json_pointer(axis.pointer)] = axis.values[idx[g]];
        job.params[axis.name] = axis.values[idx[g]];
      }
    }
    job.priority = spec.priority;
    if (spec.job_kind == "noop") {
      for (const auto& np : noop_problems(job.scenario, "/base")) {
        if (problems.size() >= 20) break;
        problems.push_back({np.pointer, np.found + " at point " + job.params.dump(), np.expected});
        repeats.push_back(0);
      }
      job.kind = queue::JobKind::noop;
      job.job_id = job_id(queue::kind_name(job.kind), job.scenario);
      drops.push_back(std::move(job));
      continue;
    }
    job.kind = queue::JobKind::drop;
    job.job_id = job_id(queue::kind_name(job.kind), job.scenario);
    json key;
    try {
      if (!bed_key) throw std::runtime_error("no bed key function (the impact pipeline is not built in)");
      key = bed_key(job.scenario);
    } catch (const pipeline::SpecError& e) {
      // The base was sound, so these are problems of swept values: one per field and reason,
      // counting the other points that have it.
      for (const auto& sp : e.problems()) {
        auto same = std::find_if(problems.begin(), problems.end(), [&](const SpecProblem& p) {
          return p.pointer == "/base" + sp.pointer && p.expected == sp.expected;
        });
        if (same != problems.end()) {
          ++repeats[static_cast<std::size_t>(same - problems.begin())];
        } else if (problems.size() < 20) {
          problems.push_back({"/base" + sp.pointer, sp.found + " at point " + job.params.dump(), sp.expected});
          repeats.push_back(0);
        }
      }
      continue;
    } catch (const std::exception& e) {
      // One problem per distinct message: a bad base field fails every point the same way.
      const std::string expected = std::string("a valid scenario: ") + e.what();
      auto same = std::find_if(problems.begin(), problems.end(),
                               [&](const SpecProblem& p) { return p.expected == expected; });
      if (same != problems.end()) {
        ++repeats[static_cast<std::size_t>(same - problems.begin())];
      } else if (problems.size() < 20) {
        problems.push_back({"/base", "the scenario at point " + job.params.dump(), expected});
        repeats.push_back(0);
      }
      continue;
    }
    const std::string bed_id = job_id(queue::kind_name(queue::JobKind::bed), key);
    auto [it, inserted] = bed_index.emplace(bed_id, beds.size());
    if (inserted) {
      PlannedJob bed;
      bed.kind = queue::JobKind::bed;
      bed.job_id = bed_id;
      bed.scenario = job.scenario;  // any scenario with this key prepares the same bed
      bed.params = json::object();
      for (auto pit = job.params.begin(); pit != job.params.end(); ++pit) bed.params[pit.key()] = pit.value();
      bed.priority = spec.priority + 1;  // beds first: drops wait for them
      beds.push_back(std::move(bed));
    } else {
      // Parameters that differ between drops of one bed are not bed parameters.
      auto& bp = beds[it->second].params;
      for (auto pit = job.params.begin(); pit != job.params.end(); ++pit)
        if (bp.contains(pit.key()) && bp[pit.key()] != pit.value()) bp[pit.key()] = nullptr;
    }
    job.deps.push_back(bed_id);
    drops.push_back(std::move(job));
  }
  for (std::size_t i = 0; i < problems.size(); ++i)
    if (repeats[i] > 0) problems[i].found += fmt::format(" (and {} more point{} with this problem)", repeats[i], repeats[i] == 1 ? "" : "s");
  if (!problems.empty()) throw SpecError::sweep_spec(spec.file.empty() ? spec.name : spec.file, problems);
  for (auto& b : beds) {  // drop the parameters that vary within the bed
    json kept = json::object();
    for (auto it = b.params.begin(); it != b.params.end(); ++it)
      if (!it.value().is_null()) kept[it.key()] = it.value();
    b.params = kept;
  }
  beds.insert(beds.end(), std::make_move_iterator(drops.begin()), std::make_move_iterator(drops.end()));
  return beds;
}

}  // namespace gravsweep::sweep
