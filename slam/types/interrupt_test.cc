#include "slam/types/interrupt.h"

#include <gtest/gtest.h>
#include <signal.h>

#include <cstdlib>

namespace slamrig {
namespace {

// Each case runs in a child process (a death test): the flag cannot be cleared, and the test
// binary's other cases must not see it set.
TEST(InterruptTest, ASignalIsRecordedAndThrownOnce) {
  EXPECT_EXIT(
      {
        InstallInterruptHandlers();
        if (InterruptSignal() != 0) std::exit(1);
        ThrowIfInterrupted();  // nothing yet
        ::raise(SIGTERM);
        ::raise(SIGINT);  // the first signal wins: the exit code stays SIGTERM's
        try {
          ThrowIfInterrupted();
        } catch (const Interrupted& e) {
          std::exit(e.signal() == SIGTERM && InterruptSignal() == SIGTERM &&
                            std::string(e.what()) == "interrupted by SIGTERM"
                        ? 0
                        : 2);
        }
        std::exit(3);
      },
      ::testing::ExitedWithCode(0), "");
}

TEST(InterruptTest, SigintIsNamed) {
  EXPECT_EQ(SignalName(SIGINT), "SIGINT");
  EXPECT_EQ(SignalName(SIGTERM), "SIGTERM");
  EXPECT_EQ(SignalName(SIGHUP), "signal " + std::to_string(SIGHUP));
}

}  // namespace
}  // namespace slamrig
