// Exit codes of `gravsweep` (docs/reference.md), the CLI's front to scheduler/queue/exit_codes.h, and the
// two ways a verb ends with one: an exception main() maps (UsageError, ConfigError, ...), or an
// ExitWith for a verb that finished with an outcome other than success. A verb never calls
// std::exit or _exit itself (forked children before exec aside): that would skip main's mapping.
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

/// Thrown by a verb that finished, after its scopes closed every file and database, to leave with
/// `code` (kExitIncomplete, kExitInterrupted, ...); main() prints nothing and returns it. Not a
/// std::exception, so no `catch (const std::exception&)` on the way takes it for a failure.
/// skip_exit_handlers: leave with _exit, after flushing (see main.cpp: HDF5's clean-up at exit
/// after a failed job).
struct ExitWith {
  int code = kExitOk;
  bool skip_exit_handlers = false;
};

}  // namespace gravsweep::cli
