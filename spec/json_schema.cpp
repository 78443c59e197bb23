#include "spec/json_schema.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <regex>
#include <set>
#include <vector>

namespace gravsweep::spec {

using nlohmann::json;

namespace {

/// An ECMAScript pattern, compiled once per pattern and thread (a sweep checks the same few
/// patterns at each of its points).
const std::regex& compiled_pattern(const std::string& pattern) {
  thread_local std::map<std::string, std::regex> cache;
  auto it = cache.find(pattern);
  if (it == cache.end()) it = cache.emplace(pattern, std::regex(pattern, std::regex::ECMAScript)).first;
  return it->second;
}

std::string joined(const std::vector<std::string>& items, const char* separator = ", ") {
  std::string out;
  for (const auto& i : items) out += (out.empty() ? "" : separator) + i;
  return out;
}

/// The keywords this validator implements (json_schema.h); anything else in a schema is refused.
const std::set<std::string>& known_keywords() {
  static const std::set<std::string> k = {"$schema",
                                          "$id",
                                          "$ref",
                                          "$defs",
                                          "title",
                                          "description",
                                          "examples",
                                          "default",
                                          "type",
                                          "enum",
                                          "not",
                                          "oneOf",
                                          "properties",
                                          "additionalProperties",
                                          "required",
                                          "minimum",
                                          "maximum",
                                          "exclusiveMinimum",
                                          "exclusiveMaximum",
                                          "minLength",
                                          "maxLength",
                                          "pattern",
                                          "items",
                                          "minItems",
                                          "uniqueItems"};
  return k;
}

/// Refuses a schema keyword outside the subset, naming where it is (a keyword silently ignored
/// would let bad specs through).
void check_keywords(const json& s, const std::string& where) {
  if (!s.is_object()) return;
  for (auto it = s.begin(); it != s.end(); ++it) {
    if (!known_keywords().count(it.key()))
      throw std::logic_error(
          fmt::format("schema: keyword '{}' at '{}' is not supported by spec/json_schema.cpp", it.key(), where));
    const std::string at = pointer_child(where, it.key());
    if (it.key() == "properties" || it.key() == "$defs") {
      for (auto p = it->begin(); p != it->end(); ++p) check_keywords(p.value(), pointer_child(at, p.key()));
    } else if (it.key() == "items" || it.key() == "not") {
      check_keywords(it.value(), at);
    } else if (it.key() == "oneOf") {
      for (std::size_t i = 0; i < it->size(); ++i) check_keywords((*it)[i], at + "/" + std::to_string(i));
    }
  }
}

/// "an integer", "a number", "an object", ...: what a value of a schema type is called in messages.
std::string type_phrase(const std::string& type) {
  const bool vowel = !type.empty() && std::string("aeiou").find(type[0]) != std::string::npos;
  return (vowel ? "an " : "a ") + type;
}

/// The fields a oneOf branch requires, when that is all the branch says ({"required": [...]}).
std::vector<std::string> required_only(const json& branch) {
  if (!branch.is_object() || branch.size() != 1 || !branch.contains("required")) return {};
  return branch["required"].get<std::vector<std::string>>();
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
    : SpecError(std::move(source),
                std::vector<SpecProblem>{{std::move(pointer), std::move(found), std::move(expected)}}) {}

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

std::string type_name(const json& v) {
  switch (v.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return "boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
      return "integer";
    case json::value_t::number_float:
      return "number";
    case json::value_t::string:
      return "string";
    case json::value_t::array:
      return "array";
    case json::value_t::object:
      return "object";
    default:
      return "value";
  }
}

bool is_exact_integer(const json& v) {
  constexpr double kExactIntegers = 9007199254740992.0;  // 2^53
  if (v.is_number_integer()) return true;
  if (!v.is_number_float()) return false;
  const double d = v.get<double>();
  return std::isfinite(d) && std::floor(d) == d && std::abs(d) < kExactIntegers;
}

std::string shown_value(const json& v) {
  std::string s = v.dump();
  if (s.size() > 80) s = s.substr(0, 77) + "...";
  return s + " (" + type_name(v) + ")";
}

SchemaValidator::SchemaValidator(json schema) : schema_(std::move(schema)) { check_keywords(schema_, ""); }

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

void SchemaValidator::collect_definition(json& node, const std::string& definition, const std::string& pointer,
                                         std::vector<SpecProblem>& problems) const {
  check(node, json{{"$ref", "#/$defs/" + definition}}, pointer, problems);
}

namespace {

/// "what (the schema's description)", or `what` alone.
std::string described(const json& s, const std::string& what) {
  return s.contains("description") ? fmt::format("{} ({})", what, s["description"].get<std::string>()) : what;
}

}  // namespace

const json& SchemaValidator::resolved(const json& s, json& storage) const {
  if (!s.is_object() || !s.contains("$ref")) return s;
  storage = resolve(s);
  return storage;
}

void SchemaValidator::check(json& node, const json& schema_in, const std::string& ptr,
                            std::vector<SpecProblem>& problems) const {
  // The schema node itself, not a copy (a copy of every subschema at every node of every
  // instance was most of a large sweep's validation time); a merge only at a $ref.
  json merged;
  const json& s = resolved(schema_in, merged);
  if (!check_type(node, s, ptr, problems)) return;  // nothing below a wrong type is checked
  if (s.contains("oneOf")) check_one_of(node, s, ptr, problems);
  if (node.is_number()) check_number(node, s, ptr, problems);
  if (node.is_string()) check_string(node, s, ptr, problems);
  if (node.is_array()) check_array(node, s, ptr, problems);
  if (node.is_object()) check_object(node, s, ptr, problems);
}

bool SchemaValidator::check_type(json& node, const json& s, const std::string& ptr,
                                 std::vector<SpecProblem>& problems) const {
  if (s.contains("type")) {
    const std::string type = s["type"].get<std::string>();
    bool ok = false;
    if (type == "object")
      ok = node.is_object();
    else if (type == "number")
      ok = node.is_number();
    else if (type == "integer")
      ok = node.is_number_integer() || (node.is_number_float() && std::isfinite(node.get<double>()) &&
                                        std::floor(node.get<double>()) == node.get<double>());
    else if (type == "string")
      ok = node.is_string();
    else if (type == "boolean")
      ok = node.is_boolean();
    else if (type == "array")
      ok = node.is_array();
    if (!ok) {
      // (the document's own description is its schema's title text, too long for a message)
      problems.push_back({ptr, shown_value(node), ptr.empty() ? type_phrase(type) : described(s, type_phrase(type))});
      return false;
    }
    // An integral float becomes an integer where long long holds it exactly; a larger one (2^64)
    // stays a float and the range check reports it as written, never wrapped around.
    constexpr double kLongLongLimit = 9223372036854775808.0;  // 2^63
    if (type == "integer" && node.is_number_float() && std::fabs(node.get<double>()) < kLongLongLimit)
      node = static_cast<long long>(node.get<double>());
  }
  if (s.contains("enum")) {
    const auto& options = s["enum"];
    if (std::find(options.begin(), options.end(), node) == options.end()) {
      problems.push_back({ptr, shown_value(node), described(s, fmt::format("one of {}", options.dump()))});
      return false;
    }
  }
  if (s.contains("not")) {
    json copy = node;
    std::vector<SpecProblem> inner;
    check(copy, s["not"], ptr, inner);
    if (inner.empty()) {
      const json n = resolve(s["not"]);
      const std::string what = n.contains("enum") ? fmt::format("none of {}", n["enum"].dump()) : "another value";
      problems.push_back({ptr, shown_value(node), described(s, what)});
      return false;
    }
  }
  return true;
}

void SchemaValidator::check_number(const json& node, const json& s, const std::string& ptr,
                                   std::vector<SpecProblem>& problems) const {
  const double v = node.get<double>();
  if (!std::isfinite(v)) return problems.push_back({ptr, shown_value(node), "a finite number"});
  std::vector<std::string> bounds;
  bool ok = true;
  auto bound = [&](const char* keyword, const char* op, bool holds) {
    if (!s.contains(keyword)) return;
    ok = ok && holds;
    bounds.push_back(std::string(op) + " " + number(s[keyword].get<double>()));
  };
  bound("minimum", ">=", s.contains("minimum") && v >= s["minimum"].get<double>());
  bound("exclusiveMinimum", ">", s.contains("exclusiveMinimum") && v > s["exclusiveMinimum"].get<double>());
  bound("maximum", "<=", s.contains("maximum") && v <= s["maximum"].get<double>());
  bound("exclusiveMaximum", "<", s.contains("exclusiveMaximum") && v < s["exclusiveMaximum"].get<double>());
  if (ok) return;
  // An integer between two inclusive bounds reads as such; anything else lists the bounds.
  const bool integer = s.value("type", "") == "integer";
  const std::string what = integer && s.contains("minimum") && s.contains("maximum") && bounds.size() == 2
                               ? fmt::format("an integer between {} and {}", number(s["minimum"].get<double>()),
                                             number(s["maximum"].get<double>()))
                               : fmt::format("{} {}", integer ? "an integer" : "a number", joined(bounds, " and "));
  problems.push_back({ptr, shown_value(node), described(s, what)});
}

void SchemaValidator::check_string(const json& node, const json& s, const std::string& ptr,
                                   std::vector<SpecProblem>& problems) const {
  const auto& text = node.get_ref<const std::string&>();
  if (s.contains("minLength") && text.size() < s["minLength"].get<std::size_t>())
    problems.push_back(
        {ptr, shown_value(node),
         described(s, fmt::format("a string of at least {} characters", s["minLength"].get<std::size_t>()))});
  if (s.contains("maxLength") && text.size() > s["maxLength"].get<std::size_t>())
    problems.push_back(
        {ptr, shown_value(node),
         described(s, fmt::format("a string of at most {} characters", s["maxLength"].get<std::size_t>()))});
  if (s.contains("pattern")) {
    const std::string pattern = s["pattern"].get<std::string>();
    constexpr std::size_t kShownPatternChars = 40;  // a longer pattern is left to the description
    if (!std::regex_search(text, compiled_pattern(pattern)))
      problems.push_back({ptr, shown_value(node),
                          described(s, pattern.size() <= kShownPatternChars || !s.contains("description")
                                           ? fmt::format("a string matching {}", pattern)
                                           : std::string("a string"))});
  }
}

void SchemaValidator::check_array(json& node, const json& s, const std::string& ptr,
                                  std::vector<SpecProblem>& problems) const {
  if (s.contains("minItems") && node.size() < s["minItems"].get<std::size_t>()) {
    const auto n = s["minItems"].get<std::size_t>();
    problems.push_back(
        {ptr, shown_value(node),
         described(s, n == 1 ? std::string("a non-empty array") : fmt::format("an array of at least {} items", n))});
  }
  if (s.contains("items"))
    for (std::size_t i = 0; i < node.size(); ++i) check(node[i], s["items"], ptr + "/" + std::to_string(i), problems);
  if (s.value("uniqueItems", false))
    for (std::size_t i = 1; i < node.size(); ++i)  // json's == compares numbers by value: 1 == 1.0
      if (std::find(node.begin(), node.begin() + static_cast<std::ptrdiff_t>(i), node[i]) !=
          node.begin() + static_cast<std::ptrdiff_t>(i))
        problems.push_back({ptr + "/" + std::to_string(i), shown_value(node[i]),
                            "values that differ from each other (this one repeats an earlier value)"});
}

void SchemaValidator::check_object(json& node, const json& s, const std::string& ptr,
                                   std::vector<SpecProblem>& problems) const {
  static const json kNoProperties = json::object();
  const json& props = s.contains("properties") ? s.at("properties") : kNoProperties;
  if (s.contains("additionalProperties") && s["additionalProperties"].is_boolean() &&
      !s["additionalProperties"].get<bool>()) {
    std::vector<std::string> known;
    for (auto p = props.begin(); p != props.end(); ++p) known.push_back(p.key());
    for (auto it = node.begin(); it != node.end(); ++it)
      if (!props.contains(it.key()))
        problems.push_back(
            {pointer_child(ptr, it.key()), fmt::format("unknown key \"{}\"", it.key()), "one of: " + joined(known)});
  }
  if (s.contains("required"))
    for (const auto& r : s["required"]) {
      const std::string key = r.get<std::string>();
      if (!node.contains(key)) {
        const json field = props.contains(key) ? resolve(props.at(key)) : json::object();
        problems.push_back(
            {pointer_child(ptr, key), "nothing (missing)", described(field, "a value: the field is required")});
      }
    }
  for (auto p = props.begin(); p != props.end(); ++p) {
    const std::string child_ptr = pointer_child(ptr, p.key());
    if (node.contains(p.key())) {
      check(node[p.key()], p.value(), child_ptr, problems);
    } else {
      json merged;
      const json& ps = resolved(p.value(), merged);
      if (ps.contains("default")) {
        node[p.key()] = ps.at("default");
        check(node[p.key()], p.value(), child_ptr, problems);
      }
    }
  }
}

/// Exactly one branch must hold. When none does, the problems of the branch the node was most
/// likely meant for are reported (the one whose required fields are all present, else the one
/// with the fewest problems); branches that only require fields ({"required": ["values"]}) are
/// reported as "exactly one of the fields ...".
void SchemaValidator::check_one_of(json& node, const json& s, const std::string& ptr,
                                   std::vector<SpecProblem>& problems) const {
  const json& branches = s["oneOf"];
  std::vector<std::vector<SpecProblem>> found(branches.size());
  std::vector<std::size_t> holding;
  bool fields_only = true;
  std::vector<std::string> field_names;
  for (std::size_t b = 0; b < branches.size(); ++b) {
    json copy = node;
    check(copy, branches[b], ptr, found[b]);
    if (found[b].empty()) holding.push_back(b);
    const auto fields = required_only(resolve(branches[b]));
    fields_only = fields_only && !fields.empty();
    for (const auto& f : fields) field_names.push_back("\"" + f + "\"");
  }
  if (holding.size() == 1) {
    check(node, branches[holding.front()], ptr, problems);  // again on the node: its defaults go in
    return;
  }
  if (fields_only) {
    std::vector<std::string> present;
    if (node.is_object())
      for (const auto& f : field_names)
        if (node.contains(f.substr(1, f.size() - 2))) present.push_back(f);
    const std::string what =
        present.empty() ? "none of " + joined(field_names, "/") : "more than one of " + joined(present, "/");
    problems.push_back({ptr, what, described(s, "exactly one of " + joined(field_names, " or "))});
    return;
  }
  if (!holding.empty()) {
    problems.push_back({ptr, shown_value(node), described(s, "a value matching exactly one form, not several")});
    return;
  }
  // Most likely meant: the node has the branch's type (2), and all the fields it requires (1).
  auto score = [&](std::size_t b) {
    const json br = resolve(branches[b]);
    const bool type_ok = !br.contains("type") || !(found[b].size() == 1 && found[b].front().pointer == ptr &&
                                                   found[b].front().expected.rfind(type_phrase(br["type"]), 0) == 0);
    bool fields_ok = br.contains("required") && node.is_object();
    if (fields_ok)
      for (const auto& r : br["required"]) fields_ok = fields_ok && node.contains(r.get<std::string>());
    return (type_ok ? 2 : 0) + (fields_ok ? 1 : 0);
  };
  std::size_t best = 0;
  for (std::size_t b = 1; b < branches.size(); ++b)
    if (score(b) > score(best) || (score(b) == score(best) && found[b].size() < found[best].size())) best = b;
  // Of none of the branches' types, or equally near several (one problem each, at the node): list them.
  std::vector<std::string> forms;
  for (std::size_t b = 0; b < branches.size(); ++b)
    if ((score(best) < 2 || score(b) == score(best)) && found[b].size() == 1 && found[b].front().pointer == ptr)
      forms.push_back(found[b].front().expected);
  if (score(best) < 2 || forms.size() > 1) {
    problems.push_back({ptr, shown_value(node), "either " + joined(forms, "; or ")});
    return;
  }
  check(node, branches[best], ptr, problems);
}

}  // namespace gravsweep::spec
