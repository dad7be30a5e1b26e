#include "report/terminal_progress.h"

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <sstream>

namespace selfcal::report {
namespace {

TEST(TerminalProgress, EstimatesTheTimeLeftAtTheRateSoFar) {
  EXPECT_DOUBLE_EQ(*EstimateRemainingSeconds(10, 40, 5.0), 15.0);   // 0.5 s a unit, 30 units left
  EXPECT_DOUBLE_EQ(*EstimateRemainingSeconds(3, 4, 90.0), 30.0);
  EXPECT_DOUBLE_EQ(*EstimateRemainingSeconds(40, 40, 12.0), 0.0);
  EXPECT_FALSE(EstimateRemainingSeconds(0, 40, 5.0).has_value());   // no rate yet
  EXPECT_FALSE(EstimateRemainingSeconds(5, 0, 5.0).has_value());    // no total
}

TEST(TerminalProgress, FormatsDurations) {
  EXPECT_EQ(FormatDuration(0), "0:00");
  EXPECT_EQ(FormatDuration(7.9), "0:07");
  EXPECT_EQ(FormatDuration(723), "12:03");
  EXPECT_EQ(FormatDuration(3723), "1:02:03");
  EXPECT_EQ(FormatDuration(-1), "-:--");
}

TEST(TerminalProgress, TextShowsBarCountsElapsedAndLeft) {
  EXPECT_EQ(ProgressText(10, 40, 5.0, 8), "[##......] 10/40 0:05 elapsed, 0:15 left");
  EXPECT_EQ(ProgressText(0, 40, 0.2, 4), "[....] 0/40 0:00 elapsed, -:-- left");
  EXPECT_EQ(ProgressText(7, 0, 3.0, 4), "7 done, 0:03 elapsed");
}

// A clock the test moves.
struct FakeClock {
  double t = 100;
  std::function<double()> Fn() {
    return [this] { return t; };
  }
};

// Drawn on the clock, with a bar of 4 characters.
TerminalProgressOptions Drawn(FakeClock& clock, int width = 100) {
  TerminalProgressOptions options;
  options.enabled = true;
  options.bar_width = 4;
  options.width = width;
  options.now_s = clock.Fn();
  return options;
}

TEST(TerminalProgress, RedrawsOneLineInPlaceWithTheEstimate) {
  FakeClock clock;
  std::ostringstream out;
  {
    TerminalProgress progress(out, Drawn(clock));
    progress.Start(4, "study runs");
    clock.t += 30;
    progress.Advance(1);  // 30 s a run: 90 s left
    EXPECT_NE(out.str().find("\rstudy runs [#...] 1/4 0:30 elapsed, 1:30 left\x1b[K"), std::string::npos) << out.str();
    clock.t += 0.01;
    const size_t before = out.str().size();
    progress.Advance(1);  // too soon after the last draw: not redrawn
    EXPECT_EQ(out.str().size(), before);
    clock.t += 60;
    progress.Advance(2);  // the last unit is always drawn
    EXPECT_NE(out.str().find("study runs [####] 4/4 1:30 elapsed, 0:00 left"), std::string::npos) << out.str();
    progress.Finish();
    EXPECT_EQ(out.str().back(), '\n');  // the final state stays on its own line
  }
  EXPECT_EQ(out.str().find('\n'), out.str().size() - 1);
}

TEST(TerminalProgress, NestedStepsShareTheLine) {
  FakeClock clock;
  std::ostringstream out;
  TerminalProgress progress(out, Drawn(clock));
  progress.Start(3, "calibrate");
  progress.Advance(1);
  progress.Start(10, "two-view pairs");
  clock.t += 2;
  progress.Advance(5);
  EXPECT_NE(out.str().find("calibrate 1/3 > two-view pairs [##..] 5/10 0:02 elapsed, 0:02 left"), std::string::npos)
      << out.str();
  progress.Finish();
  EXPECT_EQ(out.str().find('\n'), std::string::npos);  // an inner step leaves no line behind
  progress.Clear();
  EXPECT_EQ(out.str().substr(out.str().size() - 4), "\r\x1b[K");
}

TEST(TerminalProgress, NarrowTerminalKeepsTheFigures) {
  FakeClock clock;
  std::ostringstream out;
  TerminalProgress progress(out, Drawn(clock, 40));
  progress.Start(4, "a very long label that does not fit on the line");
  EXPECT_NE(out.str().find("[....] 0/4 0:00 elapsed, -:-- left\x1b[K"), std::string::npos) << out.str();
  EXPECT_EQ(out.str().size(), 1 + 40 + 3u);  // "\r", the 40 columns, "\x1b[K"
}

TEST(TerminalProgress, QuietWhenDisabledWritesNothing) {
  std::ostringstream out;
  {
    TerminalProgress progress(out, TerminalProgressOptions{});  // enabled = false: not a terminal, --quiet, --json
    ProgressScope scope(&progress, 3, "poses");
    scope.Advance();
    progress.Clear();
  }
  EXPECT_EQ(out.str(), "");
}

TEST(TerminalProgress, IsTerminalTellsAPipeFromATerminal) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  EXPECT_FALSE(IsTerminal(fds[0]));
  EXPECT_FALSE(IsTerminal(fds[1]));
  close(fds[0]);
  close(fds[1]);
  const int master = posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) GTEST_SKIP() << "no pseudo-terminal here";
  const int slave = open(ptsname(master), O_RDWR | O_NOCTTY);
  ASSERT_GE(slave, 0);
  EXPECT_TRUE(IsTerminal(slave));
  close(slave);
  close(master);
}

}  // namespace
}  // namespace selfcal::report
