// Work run in a child process with a time limit (time_limited_child.h).
#include "base/time_limited_child.h"

#include <csignal>
#include <cstdlib>
#include <stdexcept>

#include <gtest/gtest.h>

namespace selfcal {
namespace {

using std::chrono::milliseconds;

TEST(TimeLimitedChild, TheChildsBytesComeBackWholeAndItsMemoryStaysItsOwn) {
  int touched = 0;
  // More than a pipe's buffer (64 KiB), so the parent must read while the child writes.
  const ChildOutput out = RunInTimeLimitedChild(
      [&] {
        touched = 1;
        std::string bytes(300000, 'x');
        bytes[123456] = '\0';
        return bytes;
      },
      milliseconds(20000));
  ASSERT_EQ(out.end, ChildEnd::kFinished) << out.detail;
  ASSERT_EQ(out.bytes.size(), 300000u);
  EXPECT_EQ(out.bytes[123456], '\0');
  EXPECT_EQ(out.bytes[0], 'x');
  EXPECT_EQ(touched, 0);  // the child's write went to its own copy
}

TEST(TimeLimitedChild, WorkThatNeverReturnsIsStoppedAtTheLimit) {
  const auto start = std::chrono::steady_clock::now();
  const ChildOutput out = RunInTimeLimitedChild(
      [] {
        volatile bool forever = true;
        while (forever) {
        }
        return std::string("never");
      },
      milliseconds(300));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(out.end, ChildEnd::kTimedOut);
  EXPECT_TRUE(out.bytes.empty());
  EXPECT_GE(seconds, 0.29);
  EXPECT_LT(seconds, 10.0);  // stopped, not waited for (a loaded machine may be slow to kill)
}

TEST(TimeLimitedChild, AChildThatCrashesOrThrowsIsACrashThatSaysHow) {
  const ChildOutput crashed = RunInTimeLimitedChild(
      []() -> std::string {
        std::signal(SIGABRT, SIG_DFL);
        std::abort();
      },
      milliseconds(20000));
  EXPECT_EQ(crashed.end, ChildEnd::kCrashed);
  EXPECT_EQ(crashed.detail, "ended by signal " + std::to_string(SIGABRT));
  const ChildOutput threw = RunInTimeLimitedChild([]() -> std::string { throw std::runtime_error("no"); },
                                                  milliseconds(20000));
  EXPECT_EQ(threw.end, ChildEnd::kCrashed);
  EXPECT_EQ(threw.detail, "the work threw an exception");
}

}  // namespace
}  // namespace selfcal
