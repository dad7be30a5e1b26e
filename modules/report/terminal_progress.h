// The terminal's progress line of a long step (base/progress.h): one line on stderr redrawn in place
// with "\r" (label, bar, done/total, elapsed, estimated time left), quiet when the stream is not a
// terminal or the user asked for quiet or machine-readable output. Nested steps share the line:
// "calibrate 2/4 > two-view pairs [#####...] 12/40 0:03 elapsed, 0:07 left".
//
// The time left is the constant-rate estimate elapsed * (total - done) / done of the innermost step,
// measured on a monotonic clock (std::chrono::steady_clock unless a clock is handed in, for tests).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "base/progress.h"

namespace selfcal::report {

// Seconds left at the rate so far: elapsed_s * (total - done) / done; nullopt before the first unit,
// without a total (0) or with negative input. 0 once done >= total.
std::optional<double> EstimateRemainingSeconds(int64_t done, int64_t total, double elapsed_s);

// "0:07", "12:03", "1:02:03" (rounded down to whole seconds; negative or non-finite: "-:--").
std::string FormatDuration(double seconds);

// One step's text without the label: "[#####...] 12/40 0:03 elapsed, 0:07 left" (bar of bar_width
// characters); without a total: "12 done, 0:03 elapsed".
std::string ProgressText(int64_t done, int64_t total, double elapsed_s, int bar_width);

// Whether the file descriptor is a terminal (isatty).
bool IsTerminal(int fd);

struct TerminalProgressOptions {
  bool enabled = false;      // draw at all: the stream is a terminal and neither --quiet nor --json
  int width = 100;           // columns of the line (longer lines are cut)
  int bar_width = 24;
  double min_redraw_s = 0.1;  // at most this often (and always at Start, Finish and the last unit)
  std::function<double()> now_s;  // monotonic seconds; default std::chrono::steady_clock
};

class TerminalProgress : public ProgressSink {
 public:
  TerminalProgress(std::ostream& out, TerminalProgressOptions options);
  ~TerminalProgress() override;

  void Start(int64_t total, const std::string& label) override;
  void Advance(int64_t units) override;
  void Finish() override;

  // Erases the drawn line, so that other text can be written to the terminal; the next redraw draws it
  // again. Nothing when nothing is drawn.
  void Clear();

 private:
  struct Step {
    std::string label;
    int64_t total = 0, done = 0;
    double start_s = 0;
  };
  double Now() const;
  void Draw();

  std::ostream& out_;
  TerminalProgressOptions options_;
  std::vector<Step> steps_;
  double last_draw_s_ = -1e300;
  bool drawn_ = false;
};

}  // namespace selfcal::report
