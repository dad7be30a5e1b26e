#include "capture/faulty_frame_source.h"

namespace selfcal::capture {

Status FaultyFrameSource::Unplugged() const {
  return CaptureFailure(CaptureError::kDisconnected, Describe() + ": device unplugged (injected, ENODEV)");
}

Result<Frame> FaultyFrameSource::Grab(double not_before_s, double timeout_s) {
  const int k = grabs_++;
  if (unplugged_ || faults_.disconnects.count(k) > 0) {
    unplugged_ = true;
    return Unplugged();
  }
  if (faults_.timeouts.count(k) > 0) {
    return CaptureFailure(CaptureError::kTimeout, Describe() + ": no frame within " + std::to_string(timeout_s) +
                                                      " s (injected)");
  }
  if (faults_.stale_frames.count(k) > 0) {
    Result<Frame> frame = inner_->Grab(not_before_s, timeout_s);
    if (frame.ok()) frame.value().exposure_time_s = not_before_s - 0.5;  // an old buffer (V5)
    return frame;
  }
  Result<Frame> frame = inner_->Grab(not_before_s, timeout_s);
  if (frame.ok() && faults_.bad_frames.count(k) > 0) {
    return CaptureFailure(CaptureError::kBadFrame, Describe() + ": frame " + std::to_string(frame->sequence) +
                                                       " is black (injected)");
  }
  return frame;
}

}  // namespace selfcal::capture
