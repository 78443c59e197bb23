#include "engine/system/law_registry.h"

#include <fmt/format.h>

#include <tuple>

#include "engine/contact/hertz_chrono.h"
#include "engine/contact/hooke_pkdgrav.h"
#include "engine/core/error.h"
#include "engine/rolling/rolling_none.h"
#include "engine/rolling/rolling_sunday.h"
#include "engine/rolling/rolling_zhang.h"
#include "engine/system/force_loop.h"

namespace gravsweep {

// ---- The tables: one row per law / model. ------------------------------------------------------
using ContactLaws = std::tuple<HertzChrono, HookePkdgrav>;
using RollingModels = std::tuple<RollingNone, RollingSunday, RollingZhang>;
// -------------------------------------------------------------------------------------------------

namespace {

template <class Tuple>
std::vector<std::string> names_of() {
  std::vector<std::string> out;
  std::apply([&](auto... e) { (out.emplace_back(decltype(e)::name), ...); }, Tuple{});
  return out;
}

template <class Tuple>
std::string description_of(const std::string& name) {
  std::string d;
  std::apply([&](auto... e) { ((name == decltype(e)::name ? (d = decltype(e)::description, 0) : 0), ...); }, Tuple{});
  return d;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

template <class Law>
ForceFunction with_rolling(std::string_view rolling) {
  ForceFunction f = nullptr;
  std::apply([&](auto... r) { ((rolling == decltype(r)::name ? (f = &force_loop<Law, decltype(r)>, 0) : 0), ...); },
             RollingModels{});
  return f;
}

}  // namespace

std::vector<std::string> contact_law_names() { return names_of<ContactLaws>(); }
std::vector<std::string> rolling_model_names() { return names_of<RollingModels>(); }
std::string contact_law_description(const std::string& n) { return description_of<ContactLaws>(n); }
std::string rolling_model_description(const std::string& n) { return description_of<RollingModels>(n); }

ForceFunction select_force_function(std::string_view law, std::string_view rolling) {
  ForceFunction f = nullptr;
  bool law_found = false;
  std::apply(
      [&](auto... l) {
        ((law == decltype(l)::name ? (law_found = true, f = with_rolling<decltype(l)>(rolling), 0) : 0), ...);
      },
      ContactLaws{});
  if (!law_found)
    throw ConfigError(fmt::format("unknown contact law '{}'; valid contact laws: {}", law, join(contact_law_names())));
  if (f == nullptr)
    throw ConfigError(
        fmt::format("unknown rolling model '{}'; valid rolling models: {}", rolling, join(rolling_model_names())));
  return f;
}

bool uses_frame_history(std::string_view law, std::string_view rolling) {
  bool uses = false;
  std::apply([&](auto... l) { ((law == decltype(l)::name ? (uses |= decltype(l)::uses_frame_history, 0) : 0), ...); },
             ContactLaws{});
  std::apply(
      [&](auto... r) { ((rolling == decltype(r)::name ? (uses |= decltype(r)::uses_frame_history, 0) : 0), ...); },
      RollingModels{});
  return uses;
}

void prepare_contact_law(std::string_view law, PairTable& pairs) {
  std::apply(
      [&](auto... l) {
        ((law == decltype(l)::name ? (pairs.for_each([](PairCoefficients& c) { decltype(l)::prepare(c); }), 0) : 0),
         ...);
      },
      ContactLaws{});
}

void check_contact_law(std::string_view law, const LawSetup& setup) {
  bool found = false;
  std::apply([&](auto... l) { ((law == decltype(l)::name ? (found = true, decltype(l)::check(setup), 0) : 0), ...); },
             ContactLaws{});
  if (!found)
    throw ConfigError(fmt::format("unknown contact law '{}'; valid contact laws: {}", law, join(contact_law_names())));
}

double shortest_contact_time_s(std::string_view law, const LawSetup& setup, double v_rel_m_s) {
  double t = 0;
  bool found = false;
  std::apply(
      [&](auto... l) {
        ((law == decltype(l)::name ? (found = true, t = decltype(l)::shortest_contact_time_s(setup, v_rel_m_s), 0) : 0),
         ...);
      },
      ContactLaws{});
  if (!found)
    throw ConfigError(fmt::format("unknown contact law '{}'; valid contact laws: {}", law, join(contact_law_names())));
  return t;
}

}  // namespace gravsweep
