// A fault-injecting frame source (../shared/RELIABILITY.md "test infrastructure"): wraps any FrameSource and makes
// chosen Grab calls fail the way cameras do, so that sessions can be tested against V3-V6 without
// hardware. Calls are counted from 0 over the wrapper's life ("grab #k").
#pragma once

#include <memory>
#include <set>
#include <string>

#include "capture/frame_source.h"

namespace selfcal::capture {

struct FrameFaults {
  std::set<int> timeouts;        // V3: grab #k returns kTimeout (no frame came)
  std::set<int> disconnects;     // V4: grab #k and every later one return kDisconnected (unplugged)
  std::set<int> bad_frames;      // V6: grab #k returns kBadFrame (black / truncated frame)
  std::set<int> stale_frames;    // V5: grab #k returns a frame exposed 0.5 s before not_before_s
};

class FaultyFrameSource : public FrameSource {
 public:
  FaultyFrameSource(FrameSource* inner, FrameFaults faults) : inner_(inner), faults_(std::move(faults)) {}

  std::string Describe() const override { return inner_->Describe() + " (fault injection)"; }
  Status Open() override { return unplugged_ ? Unplugged() : inner_->Open(); }
  void Close() override { inner_->Close(); }
  Result<Frame> Grab(double not_before_s, double timeout_s) override;

  int grabs() const { return grabs_; }

 private:
  Status Unplugged() const;
  FrameSource* inner_;
  FrameFaults faults_;
  int grabs_ = 0;
  bool unplugged_ = false;
};

}  // namespace selfcal::capture
