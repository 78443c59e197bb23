// Exit codes of `gravsweep`, stable so that scripts can trust them (documented in README.md).
#pragma once
#include <stdexcept>

namespace gravsweep::cli {

inline constexpr int kExitOk = 0;           ///< success
inline constexpr int kExitFailure = 1;      ///< runtime failure (I/O, database, internal)
inline constexpr int kExitUsage = 2;        ///< bad command line, bad spec or bad input file
inline constexpr int kExitNumerical = 3;    ///< the simulation broke down (NaN, overlap, escape)
inline constexpr int kExitIncomplete = 4;   ///< finished, but some jobs/trials failed
inline constexpr int kExitInterrupted = 130;  ///< stopped by SIGINT/SIGTERM

/// Thrown by verbs for bad user input (spec, file, option value); maps to kExitUsage.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace gravsweep::cli
