#include "capture/frame_source.h"

#include <time.h>

#include <cstring>

namespace selfcal::capture {

const char* CaptureErrorName(CaptureError error) {
  switch (error) {
    case CaptureError::kNone:
      return "none";
    case CaptureError::kDeviceMissing:
      return "device_missing";
    case CaptureError::kDeviceBusy:
      return "device_busy";
    case CaptureError::kPermissionDenied:
      return "permission_denied";
    case CaptureError::kNotV4l2:
      return "not_v4l2";
    case CaptureError::kFormatMismatch:
      return "format_mismatch";
    case CaptureError::kTimeout:
      return "timeout";
    case CaptureError::kDisconnected:
      return "disconnected";
    case CaptureError::kBadFrame:
      return "bad_frame";
    case CaptureError::kSequenceEnd:
      return "sequence_end";
    case CaptureError::kSequenceCorrupt:
      return "sequence_corrupt";
    case CaptureError::kClockMismatch:
      return "clock_mismatch";
  }
  return "unknown";
}

ErrorCode ErrorCodeFor(CaptureError error) {
  switch (error) {
    case CaptureError::kNone:
      return ErrorCode::kOk;
    case CaptureError::kSequenceCorrupt:
      return ErrorCode::kInvalidInput;
    case CaptureError::kSequenceEnd:
      return ErrorCode::kDegenerateData;
    default:
      return ErrorCode::kHardware;
  }
}

Status CaptureFailure(CaptureError error, const std::string& message) {
  if (error == CaptureError::kNone) throw InvalidArgument("CaptureFailure needs an error, not kNone: " + message);
  return Status::Error(ErrorCodeFor(error), message).WithDetail(kCaptureErrorDomain, static_cast<int>(error));
}

CaptureError CaptureErrorOf(const Status& status) {
  if (status.ok() || std::strcmp(status.detail_domain(), kCaptureErrorDomain) != 0) return CaptureError::kNone;
  return static_cast<CaptureError>(status.detail());
}

double MonotonicNowS() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

}  // namespace selfcal::capture
