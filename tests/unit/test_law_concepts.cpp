// The members a contact law and a rolling model must have (engine/contact/law_concepts.h): every
// registered one has them, and a law or model that lacks one is refused at compile time.
#include <gtest/gtest.h>

#include <string>

#include "engine/contact/hertz_chrono.h"
#include "engine/contact/hooke_pkdgrav.h"
#include "engine/contact/law_concepts.h"
#include "engine/rolling/rolling_none.h"
#include "engine/rolling/rolling_sunday.h"
#include "engine/rolling/rolling_zhang.h"
#include "engine/system/law_registry.h"

namespace gravsweep {
namespace {

static_assert(ContactLaw<HertzChrono> && ContactLaw<HookePkdgrav>);
static_assert(RollingModel<RollingNone> && RollingModel<RollingSunday> && RollingModel<RollingZhang>);

/// A law with every member but the time-step check.
struct LawWithoutCheck {
  static constexpr const char* name = "nocheck";
  static constexpr const char* description = "a law that forgot its step check";
  static constexpr bool uses_frame_history = false;
  static void prepare(PairCoefficients&) {}
  static double shortest_contact_time_s(const LawSetup&, double) { return 1; }
  static double normal_energy_J(const ContactGeometry&, const PairCoefficients&) { return 0; }
  static void evaluate(const ContactGeometry&, const PairCoefficients&, const ContactOptions&, ContactHistory&,
                       FrameHistory&, double, ContactForce&) {}
};
static_assert(!ContactLaw<LawWithoutCheck>, "a law without check() is not a contact law");
static_assert(!RollingModel<HertzChrono>, "a contact law is not a rolling model (no apply)");
static_assert(!ContactLaw<RollingSunday>, "a rolling model is not a contact law");

TEST(LawConcepts, TheRegistryNamesEveryLawAndModelItChecked) {
  // The rows the concepts guard are the ones the registry serves by name.
  EXPECT_NE(std::string(contact_law_description("hertz")).size(), 0u);
  EXPECT_NE(std::string(contact_law_description("hooke")).size(), 0u);
  EXPECT_EQ(contact_law_description("nocheck"), "") << "a struct outside the list is no registered law";
}

}  // namespace
}  // namespace gravsweep
