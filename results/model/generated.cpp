// The generated family of candidate terms (see generated.h).
#include "results/model/generated.h"

#include "engine/core/error.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>

namespace gravsweep::results {

namespace {

/// One factor of a form; the kinds sort in the canonical order of a name.
struct Factor {
  enum Kind { depth_power, speed_power, decay, saturate } kind;
  double p;  ///< the power (depth_power, speed_power) or the length l in m (decay, saturate)
};

std::optional<double> number(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double d = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(d)) return std::nullopt;
  return d;
}

bool strip(const std::string& s, const std::string& head, const std::string& tail, std::string& inner) {
  if (s.size() < head.size() + tail.size() || s.compare(0, head.size(), head) != 0 ||
      s.compare(s.size() - tail.size(), tail.size(), tail) != 0)
    return false;
  inner = s.substr(head.size(), s.size() - head.size() - tail.size());
  return true;
}

/// One factor, or nullopt when `s` is not written as one; throws on a number out of range.
std::optional<Factor> parse_factor(const std::string& s) {
  std::string inner;
  Factor f{};
  if (strip(s, "z^", "", inner))
    f.kind = Factor::depth_power;
  else if (strip(s, "v^", "", inner))
    f.kind = Factor::speed_power;
  else if (strip(s, "(1-exp(-z/", "))", inner))
    f.kind = Factor::saturate;
  else if (strip(s, "exp(-z/", ")", inner))
    f.kind = Factor::decay;
  else
    return std::nullopt;
  const auto p = number(inner);
  if (!p) return std::nullopt;
  f.p = *p;
  const bool power = f.kind == Factor::depth_power || f.kind == Factor::speed_power;
  if (power && (f.p < 0 || f.p > 10))
    throw ConfigError(fmt::format("generated term '{}': a power in [0, 10] expected, found {:g}", s, f.p));
  if (!power && !(f.p > 0))
    throw ConfigError(fmt::format("generated term '{}': a length l > 0 (m) expected, found {:g}", s, f.p));
  return f;
}

/// The factors of a form in canonical order (zero powers dropped), or nullopt.
std::optional<std::vector<Factor>> parse_form(const std::string& name) {
  std::vector<Factor> out;
  int depth = 0;
  std::size_t begin = 0;
  for (std::size_t i = 0; i <= name.size(); ++i) {
    if (i < name.size() && name[i] == '(') ++depth;
    if (i < name.size() && name[i] == ')') --depth;
    if (i < name.size() && (name[i] != '*' || depth != 0)) continue;
    const auto f = parse_factor(name.substr(begin, i - begin));
    if (!f) return std::nullopt;
    out.push_back(*f);
    begin = i + 1;
  }
  if (out.empty()) return std::nullopt;
  std::stable_sort(out.begin(), out.end(),
                   [](const Factor& a, const Factor& b) { return a.kind != b.kind ? a.kind < b.kind : a.p < b.p; });
  std::vector<Factor> kept;
  for (const auto& f : out)
    if (!((f.kind == Factor::depth_power || f.kind == Factor::speed_power) && f.p == 0)) kept.push_back(f);
  if (kept.empty()) kept.push_back({Factor::depth_power, 0.0});  // the constant, written z^0
  return kept;
}

std::string name_of(const std::vector<Factor>& fs) {
  std::string s;
  for (const auto& f : fs) {
    if (!s.empty()) s += "*";
    switch (f.kind) {
      case Factor::depth_power:
        s += fmt::format("z^{:g}", f.p);
        break;
      case Factor::speed_power:
        s += fmt::format("v^{:g}", f.p);
        break;
      case Factor::decay:
        s += fmt::format("exp(-z/{:g})", f.p);
        break;
      case Factor::saturate:
        s += fmt::format("(1-exp(-z/{:g}))", f.p);
        break;
    }
  }
  return s;
}

std::string words_of(const std::vector<Factor>& fs) {
  std::string s;
  for (const auto& f : fs) {
    if (!s.empty()) s += " times ";
    switch (f.kind) {
      case Factor::depth_power:
        s += f.p == 0 ? "a constant" : fmt::format("depth to the power {:g}", f.p);
        break;
      case Factor::speed_power:
        s += fmt::format("speed to the power {:g}", f.p);
        break;
      case Factor::decay:
        s += fmt::format("a decay with depth over {:g} mm", 1e3 * f.p);
        break;
      case Factor::saturate:
        s += fmt::format("a rise with depth saturating over {:g} mm", 1e3 * f.p);
        break;
    }
  }
  return s;
}

/// phi(z, |v|): the product of the factors; depth below the surface only (z < 0 counts as 0).
double phi(const std::vector<Factor>& fs, double z_m, double v_m_s) {
  const double z = std::max(z_m, 0.0), v = std::abs(v_m_s);
  double r = 1.0;
  for (const auto& f : fs) {
    switch (f.kind) {
      case Factor::depth_power:
        r *= f.p == 0 ? 1.0 : std::pow(z, f.p);
        break;
      case Factor::speed_power:
        r *= f.p == 0 ? 1.0 : std::pow(v, f.p);
        break;
      case Factor::decay:
        r *= std::exp(-z / f.p);
        break;
      case Factor::saturate:
        r *= 1.0 - std::exp(-z / f.p);
        break;
    }
  }
  return r;
}

TermInfo make_term(const std::vector<Factor>& fs) {
  TermInfo t;
  t.name = name_of(fs);
  t.generated = true;
  t.meaning = fmt::format("generated form c * {} ({}): not a named effect", t.name, words_of(fs));
  t.references = "generated family (docs/physics/force-laws.md 2.6)";
  t.signature = "found by the search beyond the named library";
  t.params = {"c_N_per_phi"};
  t.per_gravity = true;
  t.features = [fs](const TermContext& c, double* out) { out[0] = phi(fs, c.z_m, c.v_m_s); };
  t.typical = [fs](double g, double m, double) {
    const double ref = phi(fs, kGeneratedRefDepth_m, kGeneratedRefSpeed_m_s);
    return std::vector<double>{ref > 0 ? m * g / ref : m * g};
  };
  return t;
}

}  // namespace

std::string canonical_generated_name(const std::string& name) {
  const auto fs = parse_form(name);
  return fs ? name_of(*fs) : std::string();
}

std::string generated_words(const std::string& name) {
  const auto fs = parse_form(name);
  return fs ? words_of(*fs) : std::string();
}

const TermInfo* generated_term(const std::string& name) {
  const auto fs = parse_form(name);
  if (!fs) return nullptr;
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<TermInfo>> built;  // stable addresses for ModelTerm
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = built[name_of(*fs)];
  if (!slot) slot = std::make_unique<TermInfo>(make_term(*fs));
  return slot.get();
}

const std::vector<std::string>& generated_family() {
  static const std::vector<std::string> family = [] {
    std::vector<std::string> f;
    auto add = [&f](std::vector<Factor> fs) { f.push_back(name_of(*parse_form(name_of(fs)))); };
    for (double a : {0.0, 0.5, 1.0, 1.5, 2.0, 3.0})
      for (double b : {0.0, 0.5, 1.0, 2.0}) {
        const bool named = (a == 0 && (b == 0 || b == 1 || b == 2)) || (a == 1 && b == 0);
        if (!named) add({{Factor::depth_power, a}, {Factor::speed_power, b}});
      }
    // With base's constant f0 and its v^2 drag in every model, exp(-z/l) and 1 - exp(-z/l) are
    // one form, and so are v^2 exp(-z/l) and v^2 (1 - exp(-z/l)): each pair is kept once.
    for (double l : {0.0025, 0.005, 0.01, 0.02, 0.04}) {
      add({{Factor::saturate, l}});
      add({{Factor::speed_power, 2.0}, {Factor::decay, l}});
      for (auto k : {Factor::decay, Factor::saturate}) {
        add({{Factor::depth_power, 1.0}, {k, l}});
        add({{Factor::speed_power, 1.0}, {k, l}});
      }
    }
    return f;
  }();
  return family;
}

}  // namespace gravsweep::results
