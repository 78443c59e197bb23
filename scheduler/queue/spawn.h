// Starting and waiting for gravsweep's own worker processes (fork + exec of /proc/self/exe, so
// that no SQLite connection or thread crosses a fork).
#pragma once
#include <sys/types.h>

#include <string>
#include <vector>

namespace gravsweep::queue {

/// Path of the running executable.
std::string self_exe();
/// fork + execv(program, args); returns the child's pid. stdout/stderr are inherited unless
/// `quiet` (then /dev/null).
pid_t spawn_process(const std::string& program, const std::vector<std::string>& args, bool quiet = false);
/// Waits for the child; returns its exit code, or 128 + signal number if it was killed.
int wait_process(pid_t pid);

}  // namespace gravsweep::queue
