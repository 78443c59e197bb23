// Exit codes of `gravsweep` (README.md): the CLI's front to scheduler/queue/exit_codes.h.
#pragma once
#include <stdexcept>

#include "scheduler/queue/exit_codes.h"

namespace gravsweep::cli {

using queue::kExitExecFailed;
using queue::kExitFailure;
using queue::kExitIncomplete;
using queue::kExitInterrupted;
using queue::kExitNumerical;
using queue::kExitOk;
using queue::kExitSignalBase;
using queue::kExitUsage;

/// Thrown by verbs for bad user input (spec, file, option value); maps to kExitUsage.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace gravsweep::cli
