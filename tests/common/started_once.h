// The one instance of a test fixture that a whole test process shares (a PostgreSQL server, a
// Slurm cluster): started on first use, kept to the process's end, or its reason for not running.
#pragma once
#include <memory>
#include <string>

namespace gravsweep::test {

/// The process's one `T`, made by `make()` and started by `(t->*start)()` (which returns "" when it
/// runs, else why not) on the first call; later calls return the same. nullptr, with `why` filled
/// in, when it cannot run here (the failed start is not tried again).
template <class T, class Make>
T* started_once(std::string& why, Make make, std::string (T::*start)()) {
  static std::string reason;
  static std::unique_ptr<T> instance = [&] {
    std::unique_ptr<T> t = make();
    reason = (t.get()->*start)();
    if (!reason.empty()) t.reset();
    return t;
  }();
  why = reason;
  return instance.get();
}

}  // namespace gravsweep::test
