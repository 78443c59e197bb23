#include "engine/system/law_registry.h"

#include <fmt/format.h>

#include <array>
#include <tuple>

#include "engine/contact/hertz_chrono.h"
#include "engine/contact/hooke_pkdgrav.h"
#include "engine/contact/law_concepts.h"
#include "engine/core/error.h"
#include "engine/core/registry.h"
#include "engine/rolling/rolling_none.h"
#include "engine/rolling/rolling_sunday.h"
#include "engine/rolling/rolling_zhang.h"
#include "engine/system/force_loop.h"

namespace gravsweep {

// ---- The lists: one entry per law / model. ------------------------------------------------------
using ContactLaws = std::tuple<HertzChrono, HookePkdgrav>;
using RollingModels = std::tuple<RollingNone, RollingSunday, RollingZhang>;
// -------------------------------------------------------------------------------------------------

// Each entry's row is built by a template constrained by its concept (engine/contact/law_concepts.h):
// an entry that lacks a member is refused here, with the member named.

namespace {

/// A rolling model's row: what is known of it by name.
struct RollingRow {
  const char* name;
  const char* description;
  bool uses_frame_history;
};

/// A contact law's row: its static functions, and its force function with each rolling model
/// (force_loop<Law, Rolling>, in the order of RollingModels).
struct LawRow {
  const char* name;
  const char* description;
  bool uses_frame_history;
  void (*prepare)(PairCoefficients&);
  void (*check)(const LawSetup&);
  double (*shortest_contact_time_s)(const LawSetup&, double);
  std::array<ForceFunction, std::tuple_size_v<RollingModels>> force_with_rolling;
};

template <ContactLaw Law>
LawRow law_row() {
  return std::apply(
      [](auto... r) {
        return LawRow{Law::name,
                      Law::description,
                      Law::uses_frame_history,
                      &Law::prepare,
                      &Law::check,
                      &Law::shortest_contact_time_s,
                      {&force_loop<Law, decltype(r)>...}};
      },
      RollingModels{});
}

/// The tables, built once from the lists above.
const std::vector<LawRow>& law_rows() {
  static const std::vector<LawRow> rows =
      std::apply([](auto... l) { return std::vector<LawRow>{law_row<decltype(l)>()...}; }, ContactLaws{});
  return rows;
}

template <RollingModel Rolling>
RollingRow rolling_row() {
  return RollingRow{Rolling::name, Rolling::description, Rolling::uses_frame_history};
}

const std::vector<RollingRow>& rolling_rows() {
  static const std::vector<RollingRow> rows =
      std::apply([](auto... r) { return std::vector<RollingRow>{rolling_row<decltype(r)>()...}; }, RollingModels{});
  return rows;
}

const LawRow& law(std::string_view name) { return find_row(law_rows(), name, "contact law"); }
const RollingRow& rolling(std::string_view name) { return find_row(rolling_rows(), name, "rolling model"); }

template <class Rows>
std::string description_of(const Rows& rows, const std::string& name) {
  const auto* row = find_row_or_null(rows, name);
  return row ? row->description : "";
}

}  // namespace

std::vector<std::string> contact_law_names() { return row_name_list(law_rows()); }
std::vector<std::string> rolling_model_names() { return row_name_list(rolling_rows()); }
std::string contact_law_description(const std::string& n) { return description_of(law_rows(), n); }
std::string rolling_model_description(const std::string& n) { return description_of(rolling_rows(), n); }

ForceFunction select_force_function(std::string_view law_name, std::string_view rolling_name) {
  const LawRow& l = law(law_name);
  const RollingRow& r = rolling(rolling_name);
  return l.force_with_rolling[static_cast<std::size_t>(&r - rolling_rows().data())];
}

bool uses_frame_history(std::string_view law_name, std::string_view rolling_name) {
  return law(law_name).uses_frame_history || rolling(rolling_name).uses_frame_history;
}

void prepare_contact_law(std::string_view law_name, PairTable& pairs) { pairs.for_each(law(law_name).prepare); }

void check_contact_law(std::string_view law_name, const LawSetup& setup) { law(law_name).check(setup); }

double shortest_contact_time_s(std::string_view law_name, const LawSetup& setup, double v_rel_m_s) {
  return law(law_name).shortest_contact_time_s(setup, v_rel_m_s);
}

}  // namespace gravsweep
