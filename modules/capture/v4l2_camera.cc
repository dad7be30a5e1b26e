#include "capture/v4l2_camera.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include <visp3/core/vpException.h>
#include <visp3/sensor/vpV4l2Grabber.h>

#include "capture/mjpeg_decode.h"
#include "capture/v4l2_device.h"
#include "capture/v4l2_modes.h"
#include "capture/v4l2_stream.h"

namespace selfcal::capture {

namespace {

using internal::BytesPerPixel;
using internal::DeviceFd;
using internal::ErrnoText;
using internal::FormatText;
using internal::Fourcc;
using internal::Ioctl;
using internal::OpenNode;
using internal::ReadFormat;

vpV4l2Grabber::vpV4l2PixelFormatType VispFormat(V4l2PixelFormat format) {
  switch (format) {
    case V4l2PixelFormat::kGrey:
      return vpV4l2Grabber::V4L2_GREY_FORMAT;
    case V4l2PixelFormat::kYuyv:
      return vpV4l2Grabber::V4L2_YUYV_FORMAT;
    case V4l2PixelFormat::kRgb24:
      return vpV4l2Grabber::V4L2_RGB24_FORMAT;
    case V4l2PixelFormat::kBgr24:
      return vpV4l2Grabber::V4L2_BGR24_FORMAT;
    case V4l2PixelFormat::kRgb32:
      return vpV4l2Grabber::V4L2_RGB32_FORMAT;
    case V4l2PixelFormat::kMjpeg:
      break;  // not through ViSP: MmapStream + DecodeMjpegFrame
  }
  return vpV4l2Grabber::V4L2_YUYV_FORMAT;
}

}  // namespace

std::string V4l2Options::Validate() const {
  std::ostringstream out;
  if (device.empty()) out << "device must name a node such as /dev/video0\n";
  if (width_px < 1 || width_px > 16384 || height_px < 1 || height_px > 16384) {
    out << "image size " << width_px << "x" << height_px << " must lie in [1, 16384]\n";
  }
  if (num_buffers < 1 || num_buffers > 32) out << "num_buffers = " << num_buffers << " must lie in [1, 32]\n";
  if (!std::isfinite(frame_period_s) || frame_period_s <= 0 || frame_period_s > 10) {
    out << "frame_period_s = " << frame_period_s << " must lie in (0, 10]\n";
  }
  if (!std::isfinite(open_timeout_s) || open_timeout_s <= 0 || open_timeout_s > 600) {
    out << "open_timeout_s = " << open_timeout_s << " must lie in (0, 600]\n";
  }
  if (!std::isfinite(max_timestamp_skew_s) || max_timestamp_skew_s <= 0) {
    out << "max_timestamp_skew_s = " << max_timestamp_skew_s << " must be finite and > 0\n";
  }
  if (check_frames) out << checks.Validate();
  return out.str();
}

// ---- V4l2Camera

struct V4l2Camera::Impl {
  explicit Impl(V4l2Options o) : options(std::move(o)) {}

  V4l2Options options;
  V4l2DeviceInfo info;
  std::vector<V4l2ControlReport> controls;
  DeviceFd control_fd;  // our own descriptor: formats and controls are per device, not per descriptor
  std::unique_ptr<vpV4l2Grabber> grabber;  // uncompressed formats
  internal::MmapStream mjpeg_stream;        // MJPEG, on control_fd
  std::vector<V4l2Mode> modes;              // what the device offers, read at Open
  bool open = false;

  // Shared with the reader thread.
  std::thread reader;
  std::mutex mutex;
  std::condition_variable arrived;
  std::atomic<bool> stop{false};
  std::optional<Status> failure;  // sticky until Close
  Frame latest;                   // sequence -1: none yet
  std::optional<Status> latest_bad;  // why `latest` cannot be used (an MJPEG frame that did not decode)
  int64_t received = 0;

  // Grab's bookkeeping.
  int64_t last_returned = -1;
  int64_t last_examined = -1;
  int64_t stale = 0;

  Status Configure();
  void LockControls();
  void SetControl(const char* name, uint32_t id, int64_t wanted, bool required_by_user);
  Status VerifyFormat(const char* when);
  void ReadLoop();
  bool AcquireMjpeg(vpImage<unsigned char>* image, timeval* stamp, std::optional<Status>* bad);
  Status StartStreaming();
  void Shutdown();
};

Status V4l2Camera::Impl::Configure() {
  const std::string who = "camera " + options.device + ": ";
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Ioctl(control_fd.get(), VIDIOC_G_FMT, &fmt) != 0) {
    return CaptureFailure(CaptureError::kNotV4l2, who + "VIDIOC_G_FMT failed (" + ErrnoText(errno) + ")");
  }
  modes = EnumerateV4l2Modes(control_fd.get());
  if (Status s = CheckV4l2ModeOffered(modes, options.device, Fourcc(options.pixel_format), options.width_px,
                                      options.height_px, options.exact_frame_period ? options.frame_period_s : 0);
      !s.ok()) {
    return s;
  }
  fmt.fmt.pix.width = static_cast<uint32_t>(options.width_px);
  fmt.fmt.pix.height = static_cast<uint32_t>(options.height_px);
  fmt.fmt.pix.pixelformat = Fourcc(options.pixel_format);
  fmt.fmt.pix.field = V4L2_FIELD_ANY;
  fmt.fmt.pix.bytesperline = 0;
  if (Ioctl(control_fd.get(), VIDIOC_S_FMT, &fmt) != 0) {
    const int e = errno;
    if (e == EBUSY) {
      return CaptureFailure(CaptureError::kDeviceBusy,
                            who + "busy: another program is streaming from it (VIDIOC_S_FMT: " + ErrnoText(e) + ")");
    }
    if (e == ENODEV) return CaptureFailure(CaptureError::kDisconnected, who + "disconnected (" + ErrnoText(e) + ")");
    return CaptureFailure(CaptureError::kFormatMismatch,
                          who + "refuses format " +
                              FormatText(options.width_px, options.height_px, Fourcc(options.pixel_format), 0) +
                              " (VIDIOC_S_FMT: " + ErrnoText(e) + ")");
  }
  if (Status s = VerifyFormat("after VIDIOC_S_FMT"); !s.ok()) return s;
  // Frame period: only where the driver supports it; the period in effect is read back either way.
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  bool period_settable = false;
  if (Ioctl(control_fd.get(), VIDIOC_G_PARM, &parm) == 0 && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
    parm.parm.capture.timeperframe.numerator = 1000;
    parm.parm.capture.timeperframe.denominator = static_cast<uint32_t>(std::lround(1000.0 / options.frame_period_s));
    period_settable = Ioctl(control_fd.get(), VIDIOC_S_PARM, &parm) == 0;
  }
  ReadFormat(control_fd.get(), &info);
  if (options.exact_frame_period && period_settable &&
      std::abs(info.frame_period_s - options.frame_period_s) > 0.01 * options.frame_period_s) {
    std::ostringstream why;
    why << who << "asked for " << 1.0 / options.frame_period_s << " fps, the driver set " << 1.0 / info.frame_period_s
        << " fps; it offers:\n"
        << V4l2ModesText(modes);
    return CaptureFailure(CaptureError::kFormatMismatch, why.str());
  }
  return Status::Ok();
}

Status V4l2Camera::Impl::VerifyFormat(const char* when) {
  V4l2DeviceInfo now = info;
  now.width_px = now.height_px = 0;
  ReadFormat(control_fd.get(), &now);
  const uint32_t want_fourcc = Fourcc(options.pixel_format);
  const uint32_t want_bpl = static_cast<uint32_t>(options.width_px) * BytesPerPixel(options.pixel_format);
  const bool compressed = options.pixel_format == V4l2PixelFormat::kMjpeg;  // no fixed row length
  if (now.width_px != options.width_px || now.height_px != options.height_px || now.pixel_format != want_fourcc ||
      (!compressed && now.bytes_per_line != want_bpl)) {
    return CaptureFailure(
        CaptureError::kFormatMismatch,
        "camera " + options.device + ": requested " +
            FormatText(options.width_px, options.height_px, want_fourcc, want_bpl) + " but the driver has " +
            FormatText(now.width_px, now.height_px, now.pixel_format, now.bytes_per_line) + " " + when +
            "; choose a mode the camera lists (v4l2-ctl --list-formats-ext) and intrinsics of that "
            "resolution");
  }
  return Status::Ok();
}

void V4l2Camera::Impl::SetControl(const char* name, uint32_t id, int64_t wanted, bool required_by_user) {
  V4l2ControlReport report;
  report.name = name;
  v4l2_queryctrl query{};
  query.id = id;
  if (Ioctl(control_fd.get(), VIDIOC_QUERYCTRL, &query) != 0 || (query.flags & V4L2_CTRL_FLAG_DISABLED)) {
    report.note = required_by_user ? "not supported by this camera: cannot be locked" : "not supported by this camera";
    controls.push_back(report);
    return;
  }
  report.supported = true;
  v4l2_control control{};
  control.id = id;
  control.value = static_cast<int32_t>(std::clamp<int64_t>(wanted, query.minimum, query.maximum));
  if (Ioctl(control_fd.get(), VIDIOC_S_CTRL, &control) != 0) report.note = "setting it failed: " + ErrnoText(errno);
  v4l2_control read_back{};
  read_back.id = id;
  if (Ioctl(control_fd.get(), VIDIOC_G_CTRL, &read_back) == 0) {
    report.value = read_back.value;
    report.as_requested = read_back.value == wanted;
    if (!report.as_requested && report.note.empty()) {
      report.note = "reads back " + std::to_string(read_back.value) + ", not " + std::to_string(wanted);
    }
  } else {
    report.note = "cannot be read back: " + ErrnoText(errno);
  }
  controls.push_back(report);
}

void V4l2Camera::Impl::LockControls() {
  controls.clear();
  if (options.lock_exposure) {
    SetControl("exposure_auto", V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL, true);
    SetControl("exposure_auto_priority", V4L2_CID_EXPOSURE_AUTO_PRIORITY, 0, false);
    SetControl("autogain", V4L2_CID_AUTOGAIN, 0, false);
    if (options.exposure_absolute_100us >= 0) {
      SetControl("exposure_absolute_100us", V4L2_CID_EXPOSURE_ABSOLUTE, options.exposure_absolute_100us, true);
    }
  }
  if (options.lock_focus) {
    SetControl("focus_auto", V4L2_CID_FOCUS_AUTO, 0, true);
    if (options.focus_absolute >= 0)
      SetControl("focus_absolute", V4L2_CID_FOCUS_ABSOLUTE, options.focus_absolute, true);
  }
}

// One MJPEG frame from the stream, decoded (`bad` set when it cannot be used). False: nothing within the
// poll period (the caller loops), or the stream failed (`failure` set).
bool V4l2Camera::Impl::AcquireMjpeg(vpImage<unsigned char>* image, timeval* stamp, std::optional<Status>* bad) {
  bool timed_out = false;
  Result<internal::DequeuedBuffer> buffer = mjpeg_stream.Dequeue(0.2, &timed_out);
  if (!buffer.ok()) {
    if (timed_out) return false;
    std::lock_guard<std::mutex> lock(mutex);
    failure = CaptureFailure(CaptureError::kDisconnected,
                             buffer.status().message() +
                                 "; samples already captured stay valid; reconnect with Close() then Open()");
    arrived.notify_all();
    return false;
  }
  const std::string source = options.device + " frame " + std::to_string(received);
  if (buffer->driver_error) {
    *bad = CaptureFailure(CaptureError::kBadFrame, source + ": the driver flagged the MJPEG frame as damaged");
  } else {
    Result<vpImage<unsigned char>> decoded =
        DecodeMjpegFrame(buffer->data, buffer->bytes_used, source, options.width_px, options.height_px);
    if (decoded.ok()) {
      *image = std::move(decoded).value();
    } else {
      *bad = decoded.status();
    }
  }
  stamp->tv_sec = static_cast<time_t>(buffer->timestamp_s);
  stamp->tv_usec = static_cast<suseconds_t>(std::lround(1e6 * (buffer->timestamp_s - std::floor(buffer->timestamp_s))));
  mjpeg_stream.Requeue(buffer->index);
  return true;
}

void V4l2Camera::Impl::ReadLoop() {
  while (!stop.load()) {
    vpImage<unsigned char> image;
    timeval stamp{};
    std::optional<Status> bad;
    if (!grabber) {
      if (!AcquireMjpeg(&image, &stamp, &bad)) {
        std::lock_guard<std::mutex> lock(mutex);
        if (failure) return;
        continue;
      }
    } else try {
      grabber->acquire(image, stamp);
    } catch (const vpException& e) {
      const int error = errno;
      if (stop.load()) break;
      const std::string what = e.getStringMessage();
      if (what.find("timeout") != std::string::npos) continue;  // ViSP's own select() timeout: keep waiting
      // Why did the stream break? Probe the node afresh (V4).
      V4l2DeviceInfo ignored;
      Result<DeviceFd> probe = OpenNode(options.device, &ignored);
      std::string message = "camera " + options.device + ": ";
      if (!probe.ok() || error == ENODEV) {
        message += "disconnected (" + (probe.ok() ? ErrnoText(error) : probe.status().message()) + ")";
      } else {
        message += "the stream failed (" + what + ")";
      }
      message += "; samples already captured stay valid; reconnect with Close() then Open()";
      std::lock_guard<std::mutex> lock(mutex);
      failure = CaptureFailure(CaptureError::kDisconnected, message);
      arrived.notify_all();
      return;
    }
    std::lock_guard<std::mutex> lock(mutex);
    latest.image = std::move(image);
    latest.exposure_time_s = static_cast<double>(stamp.tv_sec) + 1e-6 * static_cast<double>(stamp.tv_usec);
    latest.sequence = received++;
    latest.source = options.device;
    latest_bad = std::move(bad);
    arrived.notify_all();
  }
}

void V4l2Camera::Impl::Shutdown() {
  stop.store(true);
  if (reader.joinable()) reader.join();
  mjpeg_stream.Stop();
  if (grabber) {
    try {
      grabber->close();
    } catch (const vpException&) {
      // Closing a device that is already gone: nothing left to release.
    }
    grabber.reset();
  }
  control_fd.Reset();
  open = false;
  failure.reset();
  latest = Frame();
  latest_bad.reset();
  received = 0;
  last_returned = -1;
  last_examined = -1;
  stale = 0;
  stop.store(false);
}

// The stream: MJPEG on our own descriptor, the other formats through ViSP's grabber.
Status V4l2Camera::Impl::StartStreaming() {
  if (options.pixel_format == V4l2PixelFormat::kMjpeg) {
    return mjpeg_stream.Start(control_fd.get(), std::max(options.num_buffers, 2), options.device);
  }
  grabber = std::make_unique<vpV4l2Grabber>();
  grabber->setDevice(options.device);
  grabber->setInput(0);  // webcams have one input, 0; ViSP's default (2) is for TV cards
  grabber->setWidth(static_cast<unsigned>(options.width_px));
  grabber->setHeight(static_cast<unsigned>(options.height_px));
  grabber->setPixelFormat(VispFormat(options.pixel_format));
  grabber->setNBuffers(static_cast<unsigned>(options.num_buffers));
  grabber->setFramerate(vpV4l2Grabber::framerate_25fps);  // only selects full frames (not fields) in ViSP
  try {
    vpImage<unsigned char> first;
    grabber->open(first);
  } catch (const vpException& e) {
    const int error = errno;
    const std::string who =
        "camera " + options.device + ": ViSP could not start streaming (" + e.getStringMessage() + ")";
    if (error == EBUSY)
      return CaptureFailure(CaptureError::kDeviceBusy, who + ": busy (" + ErrnoText(error) + ")");
    if (error == ENODEV) return CaptureFailure(CaptureError::kDisconnected, who + ": " + ErrnoText(error));
    return CaptureFailure(CaptureError::kFormatMismatch, who);
  }
  // ViSP falls back to other pixel formats without saying so (V2).
  return VerifyFormat("after vpV4l2Grabber::open");
}

V4l2Camera::V4l2Camera(V4l2Options options) : impl_(std::make_unique<Impl>(std::move(options))) {}

V4l2Camera::~V4l2Camera() { impl_->Shutdown(); }

std::string V4l2Camera::Describe() const {
  const Impl& m = *impl_;
  std::ostringstream out;
  out << "V4L2 " << m.options.device;
  if (!m.open) {
    out << " (not open; requested " << m.options.width_px << "x" << m.options.height_px << " "
        << V4l2PixelFormatName(m.options.pixel_format) << ")";
    return out.str();
  }
  out << " (" << m.info.driver << ", `" << m.info.card << "`, " << m.info.bus_info
      << "): " << FormatText(m.info.width_px, m.info.height_px, m.info.pixel_format, m.info.bytes_per_line)
      << " -> GREY8";
  if (m.info.frame_period_s > 0) out << ", " << 1000.0 * m.info.frame_period_s << " ms/frame";
  out << ", " << m.options.num_buffers << " buffer(s)";
  for (const V4l2ControlReport& c : m.controls) {
    out << "; " << c.name << ": " << (c.as_requested ? "locked" : "NOT locked")
        << (c.supported ? " (value " + std::to_string(c.value) + ")" : "");
    if (!c.note.empty()) out << " (" << c.note << ")";
  }
  return out.str();
}

Status V4l2Camera::Open() {
  Impl& m = *impl_;
  m.Shutdown();
  if (const std::string problems = m.options.Validate(); !problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "invalid V4L2 camera options for " + m.options.device + ":\n" + problems);
  }
  m.info = V4l2DeviceInfo();
  Result<DeviceFd> fd = OpenNode(m.options.device, &m.info);
  if (!fd.ok()) return fd.status();
  m.control_fd = std::move(fd).value();
  auto fail = [&](const Status& s) {
    m.Shutdown();
    return s;
  };
  if (Status s = m.Configure(); !s.ok()) return fail(s);
  m.LockControls();

  if (Status s = m.StartStreaming(); !s.ok()) return fail(s);
  ReadFormat(m.control_fd.get(), &m.info);

  m.open = true;
  m.reader = std::thread([&m] { m.ReadLoop(); });
  // Pre-flight test frame (V1, V3) and its clock (V5).
  const double asked_at = MonotonicNowS();
  Result<Frame> test = Grab(kAnyFrame, m.options.open_timeout_s);
  // A dark or flat first frame (kBadFrame) is common while the sensor settles; format and clock are
  // what the pre-flight checks.
  if (!test.ok() && CaptureErrorOf(test.status()) != CaptureError::kBadFrame) return fail(test.status());
  double stamp = 0;
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    stamp = m.latest.exposure_time_s;
  }
  const double skew = stamp - asked_at;
  if (std::abs(skew) > m.options.max_timestamp_skew_s + m.options.open_timeout_s) {
    std::ostringstream why;
    why.precision(6);
    why << "camera " << m.options.device << ": the test frame's driver timestamp is " << skew
        << " s away from CLOCK_MONOTONIC: the driver stamps buffers with another clock, so stale frames "
           "cannot be told from fresh ones";
    return fail(CaptureFailure(CaptureError::kClockMismatch, why.str()));
  }
  return Status::Ok();
}

Result<Frame> V4l2Camera::Grab(double not_before_s, double timeout_s) {
  Impl& m = *impl_;
  if (!m.open) return Status::Error(ErrorCode::kInvalidInput, "Grab on camera " + m.options.device + " before Open");
  if (!(timeout_s >= 0) || !std::isfinite(timeout_s)) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "Grab on camera " + m.options.device + ": timeout_s must be finite and >= 0");
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  Frame frame;
  {
    std::unique_lock<std::mutex> lock(m.mutex);
    for (;;) {
      if (m.failure) return *m.failure;
      if (m.latest.sequence > m.last_examined) {
        m.last_examined = m.latest.sequence;
        if (m.latest.exposure_time_s >= not_before_s) {
          if (m.latest_bad) return *m.latest_bad;  // a fresh frame that did not decode: the caller retries
          frame = m.latest;
          break;
        }
        ++m.stale;  // exposed before the settle time: never handed out (V5)
      }
      if (m.arrived.wait_until(lock, deadline) == std::cv_status::timeout && m.latest.sequence <= m.last_examined &&
          !m.failure) {
        std::ostringstream why;
        why.precision(6);
        why << std::fixed << "camera " << m.options.device << ": no frame " << ExposedAtOrAfterWords(not_before_s)
            << "arrived within " << timeout_s << " s (" << m.received << " frames received since Open";
        if (m.latest.sequence >= 0) why << ", the newest exposed at " << m.latest.exposure_time_s << " s";
        why << ")";
        return CaptureFailure(CaptureError::kTimeout, why.str());
      }
    }
  }
  m.last_returned = frame.sequence;
  if (m.options.check_frames) {
    if (Status s = CheckFrame(frame.image, m.options.checks, m.options.device); !s.ok()) return s;
  }
  return frame;
}

void V4l2Camera::Close() { impl_->Shutdown(); }

const V4l2DeviceInfo& V4l2Camera::info() const { return impl_->info; }
const std::vector<V4l2ControlReport>& V4l2Camera::controls() const { return impl_->controls; }

int64_t V4l2Camera::frames_received() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->received;
}

int64_t V4l2Camera::stale_frames_discarded() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->stale;
}

}  // namespace selfcal::capture
