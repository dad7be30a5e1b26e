// The session clock shared by the robot, the camera and the session loop. Live sessions use the
// monotonic clock (CLOCK_MONOTONIC, the clock V4L2 stamps frames with); simulated sessions use a
// virtual clock that only advances when someone waits on it, so that a simulated session is
// deterministic and runs as fast as the computer allows.
#pragma once

namespace selfcal::robot {

class Clock {
 public:
  virtual ~Clock() = default;
  virtual double Now() = 0;
  // Waits until Now() >= time_s (returns at once if it already is).
  virtual void SleepUntil(double time_s) = 0;
  void SleepFor(double seconds) { SleepUntil(Now() + seconds); }
};

// CLOCK_MONOTONIC in seconds; SleepUntil sleeps.
class MonotonicClock : public Clock {
 public:
  double Now() override;
  void SleepUntil(double time_s) override;
};

// Virtual time: SleepUntil jumps. Never goes backwards.
class SimulatedClock : public Clock {
 public:
  explicit SimulatedClock(double start_s = 0) : now_s_(start_s) {}
  double Now() override { return now_s_; }
  void SleepUntil(double time_s) override {
    if (time_s > now_s_) now_s_ = time_s;
  }

 private:
  double now_s_;
};

}  // namespace selfcal::robot
