#include "robot/clock.h"

#include <time.h>

#include <cerrno>
#include <algorithm>
#include <cmath>

namespace selfcal::robot {

double MonotonicClock::Now() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

void MonotonicClock::SleepUntil(double time_s) {
  if (!std::isfinite(time_s) || time_s <= Now()) return;
  const double whole_s = std::floor(time_s);
  timespec until{};
  until.tv_sec = static_cast<time_t>(whole_s);
  until.tv_nsec = static_cast<long>(std::min(999999999.0, std::round((time_s - whole_s) * 1e9)));
  // Absolute deadline: a signal that interrupts the sleep does not stretch it when it is resumed.
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR) {
  }
}

}  // namespace selfcal::robot
