#include "db/where.h"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>

namespace gravsweep::db {

using nlohmann::json;

namespace {

struct Lexer {
  const std::string& s;
  std::size_t i = 0;
  void skip() {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  }
  [[noreturn]] void fail(const std::string& expected) const {
    const std::string found = i < s.size() ? fmt::format("'{}'", s.substr(i, 20)) : "the end";
    throw std::invalid_argument(
        fmt::format("--where '{}': at character {}: found {}, expected {}", s, i + 1, found, expected));
  }
  std::string ident() {
    skip();
    const std::size_t b = i;
    while (i < s.size() && (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '_')) ++i;
    if (b == i || std::isdigit(static_cast<unsigned char>(s[b]))) {
      i = b;
      fail("a column name");
    }
    return s.substr(b, i - b);
  }
  std::string op() {
    skip();
    for (const char* o : {"<=", ">=", "==", "!=", "<>", "<", ">", "=", "~"}) {
      const std::size_t n = std::char_traits<char>::length(o);
      if (s.compare(i, n, o) == 0) {
        i += n;
        std::string r = o;
        if (r == "==") r = "=";
        if (r == "<>") r = "!=";
        return r;
      }
    }
    fail("an operator (< <= > >= = != ~)");
  }
  /// The value, and in `text` the value as typed (without its quotes).
  json value(std::string& text) {
    skip();
    if (i >= s.size()) fail("a value");
    if (s[i] == '\'' || s[i] == '"') {
      const char q = s[i++];
      std::string out;
      while (i < s.size() && s[i] != q) out.push_back(s[i++]);
      if (i >= s.size()) fail(fmt::format("a closing {}", q));
      ++i;
      text = out;
      return out;
    }
    const std::size_t b = i;
    while (i < s.size() && !std::isspace(static_cast<unsigned char>(s[i])) && s[i] != ',' && s[i] != '&') ++i;
    const std::string word = s.substr(b, i - b);
    text = word;
    if (word == "true") return true;
    if (word == "false") return false;
    char* end = nullptr;
    const double d = std::strtod(word.c_str(), &end);
    if (end && *end == '\0' && !word.empty()) {
      if (!std::isfinite(d)) {
        i = b;
        fail("a finite number (nan and inf compare with nothing)");
      }
      if (word.find_first_of(".eE") == std::string::npos && std::abs(d) < 9e15) return static_cast<std::int64_t>(d);
      return d;
    }
    return word;  // bare word: text
  }
  bool connector() {
    skip();
    if (i >= s.size()) return false;
    if (s[i] == ',') {
      ++i;
      return true;
    }
    if (s.compare(i, 2, "&&") == 0) {
      i += 2;
      return true;
    }
    if (i + 3 <= s.size() && (s.compare(i, 3, "and") == 0 || s.compare(i, 3, "AND") == 0) &&
        (i + 3 == s.size() || std::isspace(static_cast<unsigned char>(s[i + 3])))) {
      i += 3;
      return true;
    }
    fail("'and', ',' or the end of the filter");
  }
};

}  // namespace

void require_number(const Condition& c, const std::string& where) {
  if (c.op == "~" || c.value.is_number() || c.value.is_boolean()) return;
  throw std::invalid_argument(
      fmt::format("--where '{}': column '{}' holds numbers, found '{}', expected a number", where, c.column, c.text));
}

std::vector<Condition> parse_where(const std::string& expr) {
  Lexer lx{expr};
  std::vector<Condition> out;
  do {
    Condition c;
    c.column = lx.ident();
    c.op = lx.op();
    c.value = lx.value(c.text);
    if (c.op == "~") c.value = c.text;
    out.push_back(std::move(c));
  } while (lx.connector());
  return out;
}

namespace {

bool holds(const json& v, const Condition& c) {
  if (c.op == "~")
    return v.is_string() ? v.get<std::string>().find(c.value.get<std::string>()) != std::string::npos
                         : v.dump().find(c.value.get<std::string>()) != std::string::npos;
  auto cmp = [&](auto a, auto b) {
    if (c.op == "<") return a < b;
    if (c.op == "<=") return a <= b;
    if (c.op == ">") return a > b;
    if (c.op == ">=") return a >= b;
    if (c.op == "=") return a == b;
    return a != b;
  };
  auto number = [](const json& j) { return j.is_boolean() ? double(j.get<bool>()) : j.get<double>(); };
  if ((v.is_number() || v.is_boolean()) && (c.value.is_number() || c.value.is_boolean()))
    return cmp(number(v), number(c.value));
  const std::string a = v.is_string() ? v.get<std::string>() : v.dump();
  const std::string b = c.value.is_string() ? c.value.get<std::string>() : c.value.dump();
  return cmp(a, b);
}

}  // namespace

bool row_matches(const json& row, const std::vector<std::string>& where) {
  bool ok = true;
  for (const auto& w : where)
    for (const auto& c : parse_where(w)) {
      if (!row.contains(c.column)) {
        std::string list;
        for (auto it = row.begin(); it != row.end(); ++it) list += (list.empty() ? "" : ", ") + it.key();
        throw std::invalid_argument(
            fmt::format("--where '{}': found column '{}', expected one of: {}", w, c.column, list));
      }
      const json& v = row.at(c.column);
      if (v.is_number() || v.is_boolean()) require_number(c, w);
      ok = ok && holds(v, c);
    }
  return ok;
}

}  // namespace gravsweep::db
