#include "scheduler/pipeline/json_schema.h"

#include <fmt/format.h>

#include <cmath>
#include <vector>

namespace gravsweep::pipeline {

using nlohmann::json;

namespace {

std::string shown(const json& v) {
  std::string s = v.dump();
  if (s.size() > 80) s = s.substr(0, 77) + "...";
  return s;
}

/// A bound as written in the schema: integers in full (9007199254740991, not 9.0072e+15).
std::string number(double v) {
  constexpr double kExactIntegers = 9007199254740992.0;  // 2^53: every integer below is a double
  if (std::floor(v) == v && std::fabs(v) <= kExactIntegers) return fmt::format("{}", static_cast<long long>(v));
  return fmt::format("{:g}", v);
}

std::string problem_line(const SpecProblem& p) {
  return fmt::format("{} = {} is invalid: expected {}", p.pointer.empty() ? std::string("(document root)") : p.pointer,
                     p.found, p.expected);
}

/// One problem: "FILE: POINTER = FOUND is invalid: expected X"; several: a count, then one per line.
std::string problems_message(const std::string& source, const std::vector<SpecProblem>& problems) {
  constexpr std::size_t kMaxListed = 50;
  if (problems.size() == 1) return fmt::format("{}: {}", source, problem_line(problems.front()));
  std::string m = fmt::format("{}: {} problems", source, problems.size());
  for (std::size_t i = 0; i < problems.size() && i < kMaxListed; ++i) m += "\n  " + problem_line(problems[i]);
  if (problems.size() > kMaxListed) m += fmt::format("\n  ... and {} more", problems.size() - kMaxListed);
  return m;
}

/// A sweep spec's: "FILE: invalid sweep spec (N problems); nothing was written", one line each.
std::string sweep_problems_message(const std::string& file, const std::vector<SpecProblem>& problems) {
  std::string m = fmt::format("{}: invalid sweep spec ({} problem{}); nothing was written", file, problems.size(),
                              problems.size() == 1 ? "" : "s");
  for (const auto& p : problems)
    m += fmt::format("\n  {}: found {}, expected {}", p.pointer.empty() ? "/" : p.pointer, p.found, p.expected);
  return m;
}

}  // namespace

SpecError::SpecError(std::string source, std::string pointer, std::string found, std::string expected)
    : SpecError(std::move(source), std::vector<SpecProblem>{{std::move(pointer), std::move(found), std::move(expected)}}) {}

SpecError::SpecError(std::string source, std::vector<SpecProblem> problems)
    // Braces: the message is made before the arguments are moved (left to right).
    : SpecError{Message{problems_message(source, problems)}, std::move(source), std::move(problems)} {}

SpecError SpecError::sweep_spec(std::string file, std::vector<SpecProblem> problems) {
  return {Message{sweep_problems_message(file, problems)}, std::move(file), std::move(problems)};
}

SpecError::SpecError(Message message, std::string source, std::vector<SpecProblem> problems)
    : ConfigError(std::move(message.text)), source_(std::move(source)), problems_(std::move(problems)) {
  if (problems_.empty()) throw std::logic_error("SpecError without a problem");
}

SchemaValidator::SchemaValidator(json schema) : schema_(std::move(schema)) {}

json SchemaValidator::resolve(const json& s) const {
  if (!s.is_object() || !s.contains("$ref")) return s;
  const std::string ref = s.at("$ref").get<std::string>();
  const std::string prefix = "#/$defs/";
  if (ref.rfind(prefix, 0) != 0 || !schema_.contains("$defs") || !schema_["$defs"].contains(ref.substr(prefix.size())))
    throw std::logic_error(fmt::format("schema: unsupported or dangling $ref '{}'", ref));
  json merged = resolve(schema_["$defs"][ref.substr(prefix.size())]);
  for (auto it = s.begin(); it != s.end(); ++it)
    if (it.key() != "$ref") merged[it.key()] = it.value();
  return merged;
}

void SchemaValidator::validate(json& instance, const std::string& source) const {
  std::vector<SpecProblem> problems;
  collect(instance, problems);
  if (!problems.empty()) throw SpecError(source, std::move(problems));
}

void SchemaValidator::collect(json& instance, std::vector<SpecProblem>& problems) const {
  check(instance, schema_, "", problems);
}

void SchemaValidator::check(json& node, const json& schema_in, const std::string& ptr,
                            std::vector<SpecProblem>& problems) const {
  const json s = resolve(schema_in);
  auto fail = [&](const std::string& found, const std::string& expected) {
    problems.push_back({ptr, found, expected});
  };
  const std::string desc = s.contains("description") ? s["description"].get<std::string>() : "";
  auto expect = [&](const std::string& what) {
    return desc.empty() ? what : fmt::format("{} ({})", what, desc);
  };
  if (s.contains("type")) {
    const std::string type = s["type"].get<std::string>();
    bool ok = false;
    if (type == "object") ok = node.is_object();
    else if (type == "number") ok = node.is_number();
    else if (type == "integer")
      ok = node.is_number_integer() ||
           (node.is_number_float() && std::isfinite(node.get<double>()) &&
            std::floor(node.get<double>()) == node.get<double>());
    else if (type == "string") ok = node.is_string();
    else if (type == "boolean") ok = node.is_boolean();
    else if (type == "array") ok = node.is_array();
    if (!ok) return fail(shown(node), expect(fmt::format("a JSON {}", type)));  // nothing below to check
    // An integral float becomes an integer where long long holds it exactly; a larger one (2^64)
    // stays a float and the range check below reports it as written, never wrapped around.
    constexpr double kLongLongLimit = 9223372036854775808.0;  // 2^63
    if (type == "integer" && node.is_number_float() && std::fabs(node.get<double>()) < kLongLongLimit)
      node = static_cast<long long>(node.get<double>());
  }
  if (s.contains("enum")) {
    bool ok = false;
    for (const auto& e : s["enum"]) ok = ok || e == node;
    if (!ok) return fail(shown(node), fmt::format("one of {}", s["enum"].dump()));
  }
  if (node.is_number()) {
    const double v = node.get<double>();
    if (!std::isfinite(v)) return fail(shown(node), "a finite number");
    std::vector<std::string> bounds;
    bool ok = true;
    if (s.contains("minimum")) {
      ok = ok && v >= s["minimum"].get<double>();
      bounds.push_back(">= " + number(s["minimum"].get<double>()));
    }
    if (s.contains("exclusiveMinimum")) {
      ok = ok && v > s["exclusiveMinimum"].get<double>();
      bounds.push_back("> " + number(s["exclusiveMinimum"].get<double>()));
    }
    if (s.contains("maximum")) {
      ok = ok && v <= s["maximum"].get<double>();
      bounds.push_back("<= " + number(s["maximum"].get<double>()));
    }
    if (s.contains("exclusiveMaximum")) {
      ok = ok && v < s["exclusiveMaximum"].get<double>();
      bounds.push_back("< " + number(s["exclusiveMaximum"].get<double>()));
    }
    if (!ok) {
      std::string b;
      for (std::size_t i = 0; i < bounds.size(); ++i) b += (i ? " and " : "") + bounds[i];
      fail(shown(node), expect(fmt::format("a number {}", b)));
    }
  }
  if (node.is_object() && s.contains("properties")) {
    const json& props = s["properties"];
    if (s.contains("additionalProperties") && s["additionalProperties"].is_boolean() &&
        !s["additionalProperties"].get<bool>()) {
      for (auto it = node.begin(); it != node.end(); ++it) {
        if (props.contains(it.key())) continue;
        std::string known;
        for (auto p = props.begin(); p != props.end(); ++p) known += (known.empty() ? "" : ", ") + p.key();
        problems.push_back({pointer_child(ptr, it.key()), shown(it.value()) + " (unknown field)",
                            fmt::format("one of the fields {}", known)});
      }
    }
    if (s.contains("required"))
      for (const auto& r : s["required"]) {
        const std::string key = r.get<std::string>();
        if (!node.contains(key))
          problems.push_back({pointer_child(ptr, key), "nothing (missing)", "a value: the field is required"});
      }
    for (auto p = props.begin(); p != props.end(); ++p) {
      const std::string child_ptr = pointer_child(ptr, p.key());
      if (node.contains(p.key())) {
        check(node[p.key()], p.value(), child_ptr, problems);
      } else {
        const json ps = resolve(p.value());
        if (ps.contains("default")) {
          node[p.key()] = ps["default"];
          check(node[p.key()], p.value(), child_ptr, problems);
        }
      }
    }
  }
}

}  // namespace gravsweep::pipeline
