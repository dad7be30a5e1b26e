// Progress of a long step (a study's runs, a plan's iterations, a session's poses, a calibration's
// stages, a folder's images), reported to whoever watches: an abstract sink, so that the numerical core
// never touches a terminal. The terminal's renderer is report/terminal_progress.h; the default is none.
//
// Steps nest: a Start inside a started step begins a sub-step, ended by its Finish. A library function
// that reports progress takes an optional `ProgressSink*` (null: nothing reported) and opens a
// ProgressScope, which finishes the step on every exit path.
#pragma once

#include <cstdint>
#include <string>

namespace selfcal {

class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  // Begins a step of `total` units (>= 0; 0: unknown) named `label` (a few words, e.g. "study runs").
  virtual void Start(int64_t total, const std::string& label) = 0;
  // `units` more of the current step are done.
  virtual void Advance(int64_t units) = 0;
  // The current step ended (completed or not).
  virtual void Finish() = 0;
};

// A step reported to `sink` (null: to nobody): started here, finished when the scope ends.
class ProgressScope {
 public:
  ProgressScope(ProgressSink* sink, int64_t total, const std::string& label) : sink_(sink) {
    if (sink_ != nullptr) sink_->Start(total, label);
  }
  ~ProgressScope() {
    if (sink_ != nullptr) sink_->Finish();
  }
  ProgressScope(const ProgressScope&) = delete;
  ProgressScope& operator=(const ProgressScope&) = delete;

  void Advance(int64_t units = 1) {
    if (sink_ != nullptr) sink_->Advance(units);
  }
  // The sink, for a callee that reports a sub-step.
  ProgressSink* sink() const { return sink_; }

 private:
  ProgressSink* sink_;
};

}  // namespace selfcal
