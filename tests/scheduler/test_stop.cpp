// The one stop request of the process (scheduler/queue/stop.h): a real signal sets it, a scope
// clears it on entry and gives the previous handlers back.
#include <gtest/gtest.h>

#include <csignal>

#include "scheduler/queue/stop.h"

using namespace gravsweep;

TEST(StopRequest, ARealSignalSetsTheOneFlagAndTheScopeRestoresThePreviousHandlers) {
  struct sigaction ignore {
  }, before{}, after{};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGTERM, &ignore, &before);
  queue::stop_requested().store(true);
  {
    const queue::ScopedStopSignals scope;
    EXPECT_FALSE(queue::stop_requested().load()) << "cleared on entry";
    std::raise(SIGTERM);
    EXPECT_TRUE(queue::stop_requested().load()) << "SIGTERM sets the flag, and the process lives";
  }
  sigaction(SIGTERM, nullptr, &after);
  EXPECT_EQ(after.sa_handler, SIG_IGN) << "the handler before the scope is back";
  sigaction(SIGTERM, &before, nullptr);
  queue::stop_requested().store(false);
}
