// What a contact law and a rolling model must provide, as C++20 concepts: the registry
// (engine/system/law_registry.cpp) builds a row from each of these members and the pair loop
// (engine/system/force_loop.h) calls them, so a law that lacks one is refused by the compiler with
// the member named, at the registry's list, not deep inside a template.
#pragma once
#include <concepts>

#include "engine/contact/contact.h"
#include "engine/core/material.h"

namespace gravsweep {

/// A contact law (engine/contact/<name>.h, a struct of static members; hertz_chrono.h is the
/// example): its name and one-line description (`gravsweep --help`, schema errors), whether it
/// keeps a FrameHistory, the pair coefficients it derives once (`prepare`), its time-step check
/// against the contact time (`check`, throws naming the pair), the shortest contact time at a
/// relative speed (the adaptive step), the normal elastic energy of a contact, and the force of a
/// contact from its geometry (`evaluate`, updating the contact's history). A vectorised kernel
/// (`using Batch = ...`) is optional (force_loop.h, kHasBatch).
template <class L>
concept ContactLaw = requires(PairCoefficients& prepared, const PairCoefficients& c, const LawSetup& setup,
                              const ContactGeometry& g, const ContactOptions& opt, ContactHistory& h, FrameHistory& fh,
                              double dt_s, ContactForce& out) {
  { L::name } -> std::convertible_to<const char*>;
  { L::description } -> std::convertible_to<const char*>;
  { L::uses_frame_history } -> std::convertible_to<bool>;
  L::prepare(prepared);
  L::check(setup);
  { L::shortest_contact_time_s(setup, dt_s) } -> std::convertible_to<double>;
  { L::normal_energy_J(g, c) } -> std::convertible_to<double>;
  L::evaluate(g, c, opt, h, fh, dt_s, out);
};

/// A rolling (and twisting) model (engine/rolling/rolling_<name>.h): its name, description,
/// whether it keeps a FrameHistory, and the torque it adds to a contact's force (`apply`).
template <class R>
concept RollingModel = requires(const PairCoefficients& c, const ContactGeometry& g, const ContactOptions& opt,
                                ContactHistory& h, FrameHistory& fh, double dt_s, ContactForce& out) {
  { R::name } -> std::convertible_to<const char*>;
  { R::description } -> std::convertible_to<const char*>;
  { R::uses_frame_history } -> std::convertible_to<bool>;
  R::apply(g, c, opt, h, fh, dt_s, out);
};

}  // namespace gravsweep
