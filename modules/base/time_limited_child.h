// Work that may never return, run in a child process with a wall-clock limit.
//
// For third-party parsers that can loop forever on hostile text (OpenCV 4.6's YAML reader does on some
// camera files, found by fuzzing): the child (fork) runs `work`, writes its bytes to a pipe and exits;
// the parent reads them until the child ends, or kills it (SIGKILL) when `limit` passes. Nothing but those
// bytes comes back: the child's memory, files and exit handlers stay its own (it ends with _exit).
//
// Call it before the process starts threads of its own (a child of a threaded process holds copies of
// locks other threads may have held; a deadlocked child ends as a timeout, never as a wrong result).
#pragma once

#include <chrono>
#include <functional>
#include <string>

#include "base/status.h"

namespace selfcal {

enum class ChildEnd {
  kFinished,   // the child wrote its bytes and exited 0
  kTimedOut,   // killed after `limit`
  kCrashed,    // the work crashed the child (ended by a signal other than the limit's kill) or threw
  kFailed,     // fork, pipe or waitpid failed, or the child exited non-zero for another reason
};

struct ChildOutput {
  ChildEnd end = ChildEnd::kFailed;
  std::string bytes;   // what `work` returned (kFinished only)
  std::string detail;  // kCrashed, kFailed: why, e.g. "ended by signal 11" or "fork: Resource temporarily unavailable"
};

// Runs `work` in a forked child and returns its bytes, within `limit` of wall-clock time.
ChildOutput RunInTimeLimitedChild(const std::function<std::string()>& work, std::chrono::milliseconds limit);

}  // namespace selfcal
