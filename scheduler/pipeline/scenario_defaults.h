// Versioned defaults of the impact scenario: a default that changes what a job runs comes with a
// new defaults version, recorded in the scenario (/defaults_version), so that a job stored before
// the change runs as it was submitted and keeps its id (docs/queue.md, "Defaults versions").
#pragma once
#include <nlohmann/json.hpp>

namespace gravsweep::pipeline {

/// The defaults a scenario without /defaults_version had before versions existed: the fixed step.
inline constexpr int kLegacyDefaultsVersion = 1;
/// What `submit` and `run` give a scenario that does not name its version: version 2 adds the
/// adaptive step (/time_step) where its dt check holds (fill_versioned_defaults).
inline constexpr int kCurrentDefaultsVersion = 2;

/// Version 2's adaptive step, checked against the fixed 5 us step over 16 sites (12 at
/// 0.001 m/s2) on the Hertz law with the semi-implicit Euler integrator (BENCHMARKS.md, "The
/// adaptive step's dt check"): zstop within 2 % at 0.1, 0.01 and 0.001 m/s2, tstop within 2 % at
/// 0.01 and 0.001 and within the site scatter at 0.1 m/s2; 1.19-1.22x fewer steps than the
/// fastest-particle bound and 2.7-5.3x fewer than the fixed 5 us step.
inline constexpr double kDefaultStepsPerContact = 20;
inline constexpr double kDefaultDtMax_s = 5e-5;
/// The gravity range of the check (m/s2): above it (1.62 unchecked; 9.81 moved tstop by
/// +5.9 +- 1.8 %, BENCHMARKS.md) and below it the drop keeps the fixed step.
inline constexpr double kDefaultStepMinGravity_m_s2 = 0.001;
inline constexpr double kDefaultStepMaxGravity_m_s2 = 0.1;

/// The scenario's defaults version (absent: kLegacyDefaultsVersion, how every job stored before
/// versions existed reads).
int defaults_version(const nlohmann::json& scenario);

/// The point as a new spec means it: kCurrentDefaultsVersion recorded when it names none.
nlohmann::json with_current_defaults(nlohmann::json as_written);

/// Fills the defaults of the scenario's version that the schema cannot express (they depend on
/// other fields): at version >= 2 with no /time_step, on the Hertz law and the semi-implicit Euler
/// integrator, dt_s <= kDefaultDtMax_s and gravity within [kDefaultStepMinGravity_m_s2,
/// kDefaultStepMaxGravity_m_s2], the adaptive step {steps_per_contact 20, dt_max_s 5e-5,
/// speed_bound normal_approach}. Fields of the wrong type are left for the checks to report.
void fill_versioned_defaults(nlohmann::json& scenario);

/// The point a job keeps and its id is computed from: the point as written without
/// /defaults_version when its version changes nothing in the validated scenario (the ids of sweeps
/// submitted before versions existed stay, and a worker of a build before versions runs the job),
/// with it when it does (a job that runs differently gets another id; such a worker refuses it).
nlohmann::json id_point(const nlohmann::json& as_written, const nlohmann::json& validated);

}  // namespace gravsweep::pipeline
