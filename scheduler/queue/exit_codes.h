// Exit codes of `gravsweep` and of its worker processes, stable so that scripts can trust them
// (documented in docs/reference.md). Here, below the CLI, because the queue records them too (a job's
// attempt: the code its error maps to) and forks processes; scheduler/cli/exit_codes.h is the
// CLI's front and re-exports them.
#pragma once

namespace gravsweep::queue {

inline constexpr int kExitOk = 0;             ///< success
inline constexpr int kExitFailure = 1;        ///< runtime failure (I/O, database, internal)
inline constexpr int kExitUsage = 2;          ///< bad command line, bad spec or bad input file (ConfigError)
inline constexpr int kExitNumerical = 3;      ///< the simulation broke down (NaN, overlap, escape)
inline constexpr int kExitIncomplete = 4;     ///< finished, but some jobs/trials failed
inline constexpr int kExitExecFailed = 127;   ///< a forked child could not exec (the shell's code)
inline constexpr int kExitSignalBase = 128;   ///< a process killed by signal s reports 128 + s
inline constexpr int kExitInterrupted = 130;  ///< stopped by SIGINT/SIGTERM (128 + SIGINT)

}  // namespace gravsweep::queue
