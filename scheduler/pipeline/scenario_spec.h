// The impact scenario spec (schemas/scenario.schema.json, compiled in): validation with defaults,
// cross-field checks, and what a job stores of it. The engine's inputs are made from the typed
// record (scenario.h) by its member functions.
#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "scheduler/pipeline/scenario.h"
#include "spec/json_schema.h"

namespace gravsweep::pipeline {

using spec::SpecError;
using spec::SpecProblem;

/// Validates a scenario against the schema and the cross-field rules (exactly one of
/// impact_speed_m_s / drop_height_m, grains fit the container, the projectile and its offsets fit,
/// dt within the contact law's stability bound, sample rate <= 1/dt, ...) and returns it with
/// every default filled in. Throws SpecError (a ConfigError) naming `source` and, for every
/// problem (not only the first), the JSON pointer of the field, the value found and what was
/// expected; a rule that needs a field already found bad is skipped rather than reported twice.
nlohmann::json validate_scenario(const nlohmann::json& scenario, const std::string& source = "scenario");

/// This build's validation: "<build version> schema:<first 12 hex of the schema's SHA-256>".
const std::string& validated_by();
/// False when validated_by() does not name one build's rules: a build with uncommitted changes
/// ("-dirty") or outside a git checkout ("+unknown"), which other such builds share. Its marks are
/// never trusted: its workers validate every job again.
bool validation_is_named();

/// A job's stored scenario: the scenario validated at submit, the validation it passed (which
/// tells a worker of the same build that the stored defaults are its own) and the point as the
/// sweep wrote it (which another build validates with its own rules and defaults). Stored as one
/// JSON object, the validated scenario with the two marks as keys beside its fields, the form
/// every job has had since submit validated scenarios; a job stored before has neither mark.
struct StoredScenario {
  /// The keys of the marks in the stored object.
  static constexpr const char* kValidatedByKey = "$validated_by";
  static constexpr const char* kAsWrittenKey = "$as_written";

  nlohmann::json validated;                  ///< as validate_scenario returned it
  std::optional<std::string> validated_by;   ///< absent: a job stored unmarked
  std::optional<nlohmann::json> as_written;  ///< absent: unmarked, or a build that kept none

  /// Marked by this build (validated_by()), with the point as written (sweep expansion at submit).
  static StoredScenario of_this_build(nlohmann::json validated, nlohmann::json as_written);
  /// The parts of a stored object (a mark of the wrong type is a SpecError naming its key).
  static StoredScenario parse(const nlohmann::json& stored);
  /// The stored object.
  [[nodiscard]] nlohmann::json to_json() const;
};

/// The validated scenario of a job (what validate_scenario returns, without the keys above): the
/// stored one, checked again, when this build validated it at submit (and validation_is_named()),
/// else the point as written validated now (a job submitted by another build; one that stored no
/// point as written has its validated scenario validated again), or the stored text itself
/// validated now (unmarked: a job submitted before scenarios were stored validated). The
/// database is a trust boundary (on PostgreSQL many users write to it): a mark never skips the
/// checks that bound a job's resources and types; they take milliseconds, a job minutes.
/// Throws as validate_scenario (a SpecError naming the field's JSON pointer: a permanent failure).
nlohmann::json job_scenario(const nlohmann::json& stored);
/// The typed record of a job's scenario: scenario_of(job_scenario(stored)).
Scenario job_scenario_record(const nlohmann::json& stored);

/// Memory per grain of a bed in the engine (state, Verlet pairs with their contact histories,
/// per-thread force buffers): a bound, measured at 1.1-1.6 kB on the paper's and the sweep's beds.
inline constexpr double kBytesPerGrain = 2048;
/// The most grains a validated (or stored) scenario's bed can hold while it is poured: random close
/// packing (0.64) of the fill, twice over for the lattice poured above the fill height.
double bed_grain_bound(const Scenario& s);
/// The memory a bed or drop job of that scenario needs at most (bytes): bed_grain_bound grains at
/// kBytesPerGrain. `work --max-memory` refuses a job above its limit, `submit --dry-run` prints it.
double job_memory_bytes(const Scenario& s);

/// How many times validation has run the engine's own checks (each builds an engine System four
/// times) in this process: once per distinct set of the fields they read, not once per scenario.
std::size_t engine_check_runs();

/// Reads a scenario file (JSON) and validates it; parse errors name the file, line and column. A
/// file that names no /defaults_version takes the current defaults (scenario_defaults.h).
nlohmann::json load_scenario(const std::filesystem::path& path);

}  // namespace gravsweep::pipeline
