// Errors raised by the engine. Every message names what failed and why, so that the CLI can print it
// as is (the CLI maps the kinds to exit codes).
#pragma once
#include <stdexcept>
#include <string>

namespace gravsweep {

/// A parameter or set-up value is invalid (wrong range, unknown name). Raised before any step runs.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The integration broke down (NaN, runaway overlap, a grain leaving the container).
/// Carries the step, the particle and the cause.
class NumericalFailure : public std::runtime_error {
 public:
  NumericalFailure(std::string message, long long step, long long particle)
      : std::runtime_error(std::move(message)), step_(step), particle_(particle) {}
  [[nodiscard]] long long step() const { return step_; }
  [[nodiscard]] long long particle() const { return particle_; }

 private:
  long long step_;
  long long particle_;
};

}  // namespace gravsweep
