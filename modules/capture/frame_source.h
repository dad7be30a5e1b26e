// Module capture (ARCHITECTURE.md): FrameSource (this header: Open / Grab(not_before, timeout) / Close,
// typed CaptureError); frame_checks.h (per-frame checks, V6, V9); recorded_sequence.h (index.yaml + PNG,
// atomic writer, validating reader: V8); v4l2_camera.h (V4l2Camera over vpV4l2Grabber with device, format,
// clock and control checks, V1-V5, V7), v4l2_modes.h (any size, format and frame interval the device lists:
// ENUM_FMT / FRAMESIZES / FRAMEINTERVALS, refusals with the list), v4l2_stream.h (MJPEG through its own mmap
// stream) and mjpeg_decode.h (libjpeg-turbo; damaged frames refused, tested on test/data/mjpeg);
// aravis_camera.h (GigE Vision / USB3 Vision through Aravis 0.8: exposure and gain locked, a software trigger
// after the settle, vanished cameras kDisconnected; tested against Aravis' fake camera). Uses base, yaml
// (private), ViSP; libjpeg, Aravis and OpenCV private.
//
// Frame sources: the one interface through which a session gets images, whether from a V4L2 camera
// (v4l2_camera.h), a recorded sequence folder (recorded_sequence.h) or the simulator
// (sim/simulated_camera.h). The session code cannot tell them apart (../shared/DESIGN.md section 2, ../shared/STYLE.md
// "take from ViSP the frame-grabber interface that simulators and recorded sources also implement").
//
// Images are 8-bit grey vpImage<unsigned char>, row-major, pixel (u, v) = image[v][u]; the pixel
// convention is camera/camera.h's (origin at the centre of the top-left pixel, u right, v down).
//
// Time: every timestamp is in seconds on one clock per source. Live sources use CLOCK_MONOTONIC
// (MonotonicNowS() below; the clock V4L2 drivers stamp buffers with); recorded sources replay the
// recorded timestamps; the simulated camera uses its own simulated clock. `not_before_s` passed to
// Grab must be on the same clock as the source's exposure timestamps.
//
// Errors: every failure is a Status whose detail (Status::detail_domain() == kCaptureErrorDomain)
// carries a CaptureError; CaptureErrorOf() reads it back. Messages name the device or the file.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include <visp3/core/vpImage.h>

#include "base/status.h"

namespace selfcal::capture {

// What went wrong, for callers that react differently (retry, skip the pose, stop the session).
// ../shared/RELIABILITY.md rows in brackets.
enum class CaptureError {
  kNone = 0,
  kDeviceMissing,     // no such device node, or no driver behind it [V1]
  kDeviceBusy,        // another process streams from the device [V1]
  kPermissionDenied,  // no read/write access to the node [V1]
  kNotV4l2,           // a regular file, a directory, another kind of device, or a V4L2 node that cannot capture [V1]
  kFormatMismatch,    // the driver delivers another resolution / pixel format / layout than requested [V2]
  kTimeout,           // no acceptable frame within the timeout [V3]
  kDisconnected,      // the device went away or the stream broke mid-session (ENODEV) [V4]
  kBadFrame,          // a frame failed the sanity checks: black, saturated, flat, truncated, blurred [V6, V9]
  kSequenceEnd,       // a recorded sequence has no further frame at or after not_before_s [V8]
  kSequenceCorrupt,   // a recorded sequence's index or one of its images is broken [V8]
  kClockMismatch,     // frame timestamps are not on the documented clock, so freshness cannot be checked [V5]
};

inline constexpr const char* kCaptureErrorDomain = "capture";

// "device_missing", "timeout", ...: stable names for journals and reports.
const char* CaptureErrorName(CaptureError error);

// The ErrorCode a capture error maps to: kHardware for device and frame faults, kInvalidInput for a corrupt
// recorded sequence (a malformed input file, like io's files), kDegenerateData for the end of a sequence
// (ran out of data).
ErrorCode ErrorCodeFor(CaptureError error);

// A Status carrying `error` (kNone is not allowed) and `message`.
Status CaptureFailure(CaptureError error, const std::string& message);

// The CaptureError of a Status: kNone for OK, and for errors made elsewhere (no capture detail).
CaptureError CaptureErrorOf(const Status& status);

// Seconds on CLOCK_MONOTONIC: the clock of live exposure timestamps and of robot settle times.
double MonotonicNowS();

struct Frame {
  vpImage<unsigned char> image;  // grey, 8 bit
  double exposure_time_s = 0;    // when the frame was exposed, on the source's clock (see above)
  int64_t sequence = -1;         // advances by one per frame the source delivered (gaps: dropped frames)
  std::string source;            // device path, or recorded image file, or "sim"
  std::string pose_id;           // recorded sequences: the pose the frame belongs to; otherwise empty
};

// Not thread-safe: one caller drives a source. Open and Close may be called repeatedly (a reconnect is
// Close + Open).
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // Device or folder, resolution and pixel format as actually in effect (after Open), for logs and the
  // session journal.
  virtual std::string Describe() const = 0;

  virtual Status Open() = 0;

  // The first frame exposed at or after `not_before_s` (typically the robot's settle time: never a
  // stale buffered frame, ../shared/RELIABILITY.md V5), waiting at most `timeout_s` of wall time; kTimeout after
  // that. A frame that fails the source's sanity checks gives kBadFrame (the caller decides whether to
  // retry). Requires Open().
  virtual Result<Frame> Grab(double not_before_s, double timeout_s) = 0;

  virtual void Close() = 0;
};

// `not_before_s` for any frame at all (a camera's pre-flight test frame at Open).
constexpr double kAnyFrame = -1e300;

// A Grab's time condition in a message: "exposed at or after T s ", or nothing for kAnyFrame.
inline std::string ExposedAtOrAfterWords(double not_before_s) {
  if (not_before_s <= kAnyFrame) return "";
  char text[64];
  std::snprintf(text, sizeof(text), "exposed at or after %.6f s ", not_before_s);
  return text;
}

}  // namespace selfcal::capture
