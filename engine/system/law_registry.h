// The registry of contact laws and rolling models: one table each (law_registry.cpp).
//
// To add a contact law: write engine/contact/<name>.h with a struct that has the members of the
// ContactLaw concept (engine/contact/law_concepts.h; see hertz_chrono.h), then add the struct to the
// ContactLaws list in law_registry.cpp. A rolling model is the same with the RollingModel concept
// (see engine/rolling/) and the RollingModels list. The compiler names a missing member.
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "engine/contact/contact.h"
#include "engine/core/material.h"
#include "engine/system/force_function.h"

namespace gravsweep {

/// Names of the registered contact laws and rolling models, and their one-line descriptions.
std::vector<std::string> contact_law_names();
std::vector<std::string> rolling_model_names();
std::string contact_law_description(const std::string& name);
std::string rolling_model_description(const std::string& name);

/// The force function for a (contact law, rolling model) pair; unknown names are ConfigErrors
/// that list the valid names.
ForceFunction select_force_function(std::string_view law, std::string_view rolling);

/// True when the law or the rolling model keeps a FrameHistory per contact (contact.h).
bool uses_frame_history(std::string_view law, std::string_view rolling);

/// Lets the named law cache its per-pair constants (PairCoefficients::damping_prefactor_n, _t).
void prepare_contact_law(std::string_view law, PairTable& pairs);

/// Runs the named law's parameter and time-step checks.
void check_contact_law(std::string_view law, const LawSetup& setup);

/// The named law's shortest contact time over the pairs present at relative normal speed v_rel_m_s
/// (infinite when no pair can touch or the speed is 0 for a speed-dependent law).
double shortest_contact_time_s(std::string_view law, const LawSetup& setup, double v_rel_m_s);

}  // namespace gravsweep
