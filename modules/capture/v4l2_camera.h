// A V4L2 camera (USB/UVC webcams, industrial cameras with a V4L2 driver) as a FrameSource, through
// ViSP's vpV4l2Grabber (mmap streaming, conversion to 8-bit grey) for the uncompressed formats and
// capture's own mmap stream and MJPEG decoder for MJPEG, with the checks ViSP leaves out (../shared/RELIABILITY.md
// section 3). Any size, pixel format and frame interval the device lists (v4l2_modes.h).
//
// The MJPEG path (v4l2_stream.h, mjpeg_decode.h) is UNTESTED on a device: no V4L2 device (nor
// v4l2loopback) exists where the tests run; its decoding is tested on recorded frames.
//
// Clock (V5). Exposure timestamps are the driver's buffer timestamps, read as CLOCK_MONOTONIC seconds
// (MonotonicNowS()). That is the V4L2 default for current drivers (uvcvideo stamps the start of exposure
// on CLOCK_MONOTONIC since Linux 3.x); vpV4l2Grabber does not pass on the buffer's clock flags, so Open
// checks the test frame's timestamp against the monotonic clock instead and refuses a camera whose
// timestamps are more than max_timestamp_skew_s away (kClockMismatch: e.g. a driver stamping with
// CLOCK_REALTIME). The robot's settle time passed as not_before_s must be MonotonicNowS() taken after
// the arm settled.
//
// Streaming model. Open starts a background thread that acquires continuously (so the driver's ring of
// num_buffers never fills with old frames) and keeps only the newest frame. Grab(not_before_s,
// timeout_s) waits, at most timeout_s, for a frame whose driver timestamp is >= not_before_s and that
// it has not returned before; older frames are discarded and counted (stale_frames_discarded()).
// `sequence` counts the frames the thread dequeued; a gap means frames superseded before anyone asked.
//
// ../shared/RELIABILITY.md rows, and what covers them:
//   V1 (missing / busy / permission / not V4L2) - code: ProbeV4l2Device (stat, open(O_RDWR|O_NONBLOCK),
//      VIDIOC_QUERYCAP, capture + streaming capabilities) before ViSP touches the device; busy also from
//      VIDIOC_S_FMT returning EBUSY; messages name the node, errno and its name. TESTED without hardware:
//      missing node, regular file, directory, a character device that is not V4L2 (/dev/null).
//      UNTESTED (needs hardware or an unprivileged user): busy, permission denied, metadata-only node.
//   V2 (format) - code: the device's modes enumerated (VIDIOC_ENUM_FMT / ENUM_FRAMESIZES /
//      ENUM_FRAMEINTERVALS, v4l2_modes.h) and the requested format, size and frame period refused with the
//      list when it is not among them (TESTED on the check, without hardware); VIDIOC_S_FMT then VIDIOC_G_FMT on our own descriptor before ViSP opens, and
//      VIDIOC_G_FMT again after (ViSP silently falls back to other pixel formats); any difference in
//      width, height, pixel format or a padded row (ViSP copies rows without stride) is kFormatMismatch.
//      UNTESTED without hardware.
//   V3 (no frame) - code: Grab never waits longer than timeout_s (kTimeout); Open waits open_timeout_s
//      for a test frame. ViSP's internal select() timeout (30 s) only delays Close() of a camera that
//      delivers nothing. UNTESTED without hardware.
//   V4 (unplugged, ENODEV) - code: a failed acquisition ends the stream; the node is probed again:
//      gone or ENODEV gives kDisconnected ("reconnect: Close() then Open()"); other driver errors also
//      kDisconnected with ViSP's message. The error is sticky until Close. UNTESTED without hardware.
//   V5 (stale frames) - code: driver timestamps compared with not_before_s as above, clock checked at
//      Open. UNTESTED without hardware (the same rule is tested on the recorded and simulated sources).
//   V6 (bad frames) - code: CheckFrame on every returned frame (kBadFrame); duplicates cannot occur (each
//      frame is returned once). Truncated buffers (bytesused) are not visible through vpV4l2Grabber: NOT
//      COVERED for the uncompressed formats; an MJPEG frame that is truncated, corrupt or flagged
//      V4L2_BUF_FLAG_ERROR is kBadFrame (the decoding TESTED on recorded frames, the stream UNTESTED). The checks themselves are tested in frame_checks.
//   V7 (exposure / focus) - code: V4L2_CID_EXPOSURE_AUTO = manual, V4L2_CID_EXPOSURE_AUTO_PRIORITY = 0,
//      V4L2_CID_AUTOGAIN = 0, V4L2_CID_FOCUS_AUTO = 0 (optionally absolute values), each read back with
//      VIDIOC_G_CTRL and reported in controls() and Describe(); an absent or refused control is reported,
//      not fatal. UNTESTED without hardware.
//   V9 (blur) - optional Laplacian threshold in FrameCheckOptions.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "base/status.h"
#include "capture/frame_checks.h"
#include "capture/frame_source.h"

namespace selfcal::capture {

// The pixel formats read: the uncompressed ones through vpV4l2Grabber, which converts them to grey; MJPEG
// (most USB cameras at 1280x720 and above) through capture's own memory-mapped stream (v4l2_stream.h) and
// libjpeg-turbo (mjpeg_decode.h), the luminance plane alone.
enum class V4l2PixelFormat { kGrey, kYuyv, kRgb24, kBgr24, kRgb32, kMjpeg };
// "GREY", "YUYV", "RGB3", "BGR3", "RGB4", "MJPG" (fourcc)
const char* V4l2PixelFormatName(V4l2PixelFormat format);
// The format of a fourcc name (case-sensitive, as above); false when none.
bool V4l2PixelFormatFromName(const std::string& name, V4l2PixelFormat* format);

struct V4l2Options {
  std::string device = "/dev/video0";
  int width_px = 640;
  int height_px = 480;
  V4l2PixelFormat pixel_format = V4l2PixelFormat::kYuyv;  // what UVC webcams deliver natively
  int num_buffers = 1;                // ViSP's advice for non-real-time use; the reader thread drains anyway
  double frame_period_s = 1.0 / 30;   // requested with VIDIOC_S_PARM when supported; read back
  // Refuse a frame period the device does not list, or that the driver does not set (a rate the user
  // chose); otherwise whatever period the driver sets is taken.
  bool exact_frame_period = false;
  double open_timeout_s = 3.0;        // the test frame of Open must arrive within this
  bool lock_exposure = true;          // manual exposure, no auto gain, no frame-rate priority (V7)
  int exposure_absolute_100us = -1;   // with lock_exposure: V4L2_CID_EXPOSURE_ABSOLUTE; -1 keeps the current value
  bool lock_focus = true;             // V4L2_CID_FOCUS_AUTO = 0 (V7)
  int focus_absolute = -1;            // with lock_focus: V4L2_CID_FOCUS_ABSOLUTE; -1 keeps the current value
  double max_timestamp_skew_s = 5.0;  // clock plausibility of the test frame (V5)
  bool check_frames = true;
  FrameCheckOptions checks;
  // Empty when valid; otherwise every problem, one per line.
  std::string Validate() const;
};

// What the device reports, read without changing anything.
struct V4l2DeviceInfo {
  std::string path;
  std::string driver, card, bus_info;
  uint32_t device_caps = 0;  // V4L2_CAP_* of this node
  int width_px = 0;
  int height_px = 0;
  uint32_t pixel_format = 0;  // fourcc
  uint32_t bytes_per_line = 0;
  double frame_period_s = 0;  // 0 when the driver does not say
};

std::string FourccToString(uint32_t fourcc);

// Pre-flight check of a device node (V1): stat, open(O_RDWR | O_NONBLOCK), VIDIOC_QUERYCAP (a
// single-planar video capture node with streaming I/O), VIDIOC_G_FMT, VIDIOC_G_PARM. Errors
// (kDeviceMissing, kPermissionDenied, kDeviceBusy, kNotV4l2) name the path, errno and its name.
Result<V4l2DeviceInfo> ProbeV4l2Device(const std::string& path);

// A camera control of V7 after Open: what was asked and what the driver reports now.
struct V4l2ControlReport {
  std::string name;  // "exposure_auto", "focus_auto", ...
  bool supported = false;
  bool as_requested = false;
  int64_t value = 0;  // read back with VIDIOC_G_CTRL
  std::string note;   // why not, in words
};

class V4l2Camera : public FrameSource {
 public:
  explicit V4l2Camera(V4l2Options options);
  ~V4l2Camera() override;
  V4l2Camera(const V4l2Camera&) = delete;
  V4l2Camera& operator=(const V4l2Camera&) = delete;

  std::string Describe() const override;
  // Probe, set format and frame period, lock controls, open ViSP's grabber, re-read the format, start
  // the reader thread, wait for a test frame and check its clock. Any failure leaves the camera closed.
  Status Open() override;
  Result<Frame> Grab(double not_before_s, double timeout_s) override;
  // Stops the reader thread (may wait for ViSP's internal select() timeout if frames stopped) and
  // releases the device. Safe to call repeatedly.
  void Close() override;

  const V4l2DeviceInfo& info() const;  // as in effect after Open
  const std::vector<V4l2ControlReport>& controls() const;
  int64_t frames_received() const;         // dequeued by the reader thread since Open
  int64_t stale_frames_discarded() const;  // older than a Grab's not_before_s

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace selfcal::capture
