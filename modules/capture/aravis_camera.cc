// AravisCamera: Aravis 0.8's C API (GObject) behind the FrameSource interface. GLib stays in this file.
#include "capture/aravis_camera.h"

#include <arv.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>
#include <thread>

namespace selfcal::capture {

namespace {

// The message of an Aravis error, which is cleared; empty when there was none.
std::string Take(GError** error) {
  if (*error == nullptr) return "";
  std::string message = (*error)->message;
  g_clear_error(error);
  return message;
}

double RealtimeNowS() {
  timespec t{};
  ::clock_gettime(CLOCK_REALTIME, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Aravis stamps a buffer's arrival on the host with g_get_real_time (CLOCK_REALTIME, ns): on the
// monotonic clock of settle times.
double ArrivalMonotonicS(ArvBuffer* buffer) {
  const double arrival_realtime_s = 1e-9 * static_cast<double>(arv_buffer_get_system_timestamp(buffer));
  return arrival_realtime_s - (RealtimeNowS() - MonotonicNowS());
}

std::string CamerasFound() {
  arv_update_device_list();
  std::string list;
  for (unsigned i = 0; i < arv_get_n_devices(); ++i) {
    const char* id = arv_get_device_id(i);
    list += (list.empty() ? "" : ", ") + std::string(id != nullptr ? id : "?");
  }
  return list.empty() ? "none" : list;
}

void SleepS(double seconds) {
  if (seconds > 0) std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
}

}  // namespace

std::string AravisOptions::Validate() const {
  std::ostringstream out;
  if (width_px < 0 || width_px > 16384 || height_px < 0 || height_px > 16384 || ((width_px == 0) != (height_px == 0))) {
    out << "image size " << width_px << "x" << height_px << " must be both 0 (the camera's) or both in [1, 16384]\n";
  }
  if (!std::isfinite(exposure_s) || exposure_s > 10) out << "exposure_s = " << exposure_s << " must be at most 10 s\n";
  if (!std::isfinite(gain_db) || gain_db > 100) out << "gain_db = " << gain_db << " must be at most 100 dB\n";
  if (!std::isfinite(frame_rate_hz) || frame_rate_hz < 0 || frame_rate_hz > 10000) {
    out << "frame_rate_hz = " << frame_rate_hz << " must lie in [0, 10000]\n";
  }
  if (num_buffers < 2 || num_buffers > 64) out << "num_buffers = " << num_buffers << " must lie in [2, 64]\n";
  if (!std::isfinite(open_timeout_s) || open_timeout_s <= 0 || open_timeout_s > 600) {
    out << "open_timeout_s = " << open_timeout_s << " must lie in (0, 600]\n";
  }
  if (check_frames) out << checks.Validate();
  return out.str();
}

struct AravisCamera::Impl {
  explicit Impl(AravisOptions o) : options(std::move(o)) {}

  AravisOptions options;
  ArvCamera* camera = nullptr;
  ArvStream* stream = nullptr;
  gulong control_lost_handler = 0;
  std::atomic<bool> control_lost{false};  // set by Aravis' heartbeat thread
  std::optional<Status> failure;          // sticky until Close
  bool open = false;
  bool triggered = false;
  double exposure_s = 0;
  double frame_period_s = 0.1;
  int width_px = 0, height_px = 0;
  int64_t sequence = 0;
  int64_t stale = 0;
  std::vector<AravisControlReport> controls;
  std::string identity;

  std::string Who() const {
    return "Aravis camera " + (options.camera_id.empty() ? std::string("(first found)") : options.camera_id);
  }
  Status Connect();
  Status SetRegionAndFormat();
  void Lock(const char* name, bool auto_available, bool is_gain, double wanted);
  void LockControls();
  Status StartStream();
  Status Disconnected(const std::string& why);
  Status TimedOut(double not_before_s, double timeout_s);
  Result<Frame> TakeFrame(ArvBuffer* buffer, double exposure_time_s);
  void Shutdown();
};

Status AravisCamera::Impl::Connect() {
  if (options.fake_interface) arv_enable_interface("Fake");
  GError* error = nullptr;
  camera = arv_camera_new(options.camera_id.empty() ? nullptr : options.camera_id.c_str(), &error);
  if (camera == nullptr) {
    return CaptureFailure(CaptureError::kDeviceMissing, Who() + " not found (Aravis: " + Take(&error) +
                                                            "); cameras found: " + CamerasFound() +
                                                            " (arv-tool-0.8 lists them, with their ids)");
  }
  const char* vendor = arv_camera_get_vendor_name(camera, &error);
  const char* model = arv_camera_get_model_name(camera, &error);
  const char* serial = arv_camera_get_device_serial_number(camera, &error);
  Take(&error);
  identity = std::string(vendor ? vendor : "?") + " " + (model ? model : "?") + " " + (serial ? serial : "?");
  ArvDevice* device = arv_camera_get_device(camera);
  control_lost_handler = g_signal_connect_swapped(
      device, "control-lost", G_CALLBACK(+[](gpointer self) { static_cast<Impl*>(self)->control_lost = true; }), this);
  return Status::Ok();
}

Status AravisCamera::Impl::SetRegionAndFormat() {
  GError* error = nullptr;
  int min_w = 0, max_w = 0, min_h = 0, max_h = 0;
  arv_camera_get_width_bounds(camera, &min_w, &max_w, &error);
  arv_camera_get_height_bounds(camera, &min_h, &max_h, &error);
  const int step_w = std::max(1, arv_camera_get_width_increment(camera, &error));
  const int step_h = std::max(1, arv_camera_get_height_increment(camera, &error));
  Take(&error);
  const auto offered = [&](int w, int h) {
    return w >= min_w && w <= max_w && h >= min_h && h <= max_h && (w - min_w) % step_w == 0 &&
           (h - min_h) % step_h == 0;
  };
  if (options.width_px > 0 && offered(options.width_px, options.height_px)) {
    arv_camera_set_region(camera, 0, 0, options.width_px, options.height_px, &error);
    Take(&error);
  }
  int x = 0, y = 0;
  arv_camera_get_region(camera, &x, &y, &width_px, &height_px, &error);
  if (const std::string e = Take(&error); !e.empty()) return Disconnected("reading its region failed (" + e + ")");
  if (options.width_px > 0 && (width_px != options.width_px || height_px != options.height_px)) {
    std::ostringstream why;
    why << Who() << " (" << identity << "): asked for " << options.width_px << "x" << options.height_px
        << ", the camera has " << width_px << "x" << height_px << "; it offers " << min_w << "x" << min_h << " to "
        << max_w << "x" << max_h << " in steps of " << step_w << "x" << step_h;
    return CaptureFailure(CaptureError::kFormatMismatch, why.str());
  }
  arv_camera_set_pixel_format(camera, ARV_PIXEL_FORMAT_MONO_8, &error);
  Take(&error);
  const ArvPixelFormat format = arv_camera_get_pixel_format(camera, &error);
  Take(&error);
  if (format != ARV_PIXEL_FORMAT_MONO_8) {
    const char* name = arv_camera_get_pixel_format_as_string(camera, &error);
    Take(&error);
    return CaptureFailure(CaptureError::kFormatMismatch,
                          Who() + " (" + identity + "): delivers " + (name ? name : "?") +
                              " and refuses Mono8, the only pixel format read (8-bit grey)");
  }
  if (options.frame_rate_hz > 0) {
    arv_camera_set_frame_rate(camera, options.frame_rate_hz, &error);
    Take(&error);
  }
  const double rate = arv_camera_get_frame_rate(camera, &error);
  if (Take(&error).empty() && rate > 0) frame_period_s = 1.0 / rate;
  return Status::Ok();
}

// ExposureAuto / GainAuto Off, then the value asked for (wanted >= 0), each read back (V7).
void AravisCamera::Impl::Lock(const char* name, bool auto_available, bool is_gain, double wanted) {
  GError* error = nullptr;
  AravisControlReport automatic{std::string(name) + "_auto", auto_available, !auto_available, 0, ""};
  if (!auto_available) {
    automatic.note = "the camera has no automatic mode: fixed";
  } else {
    is_gain ? arv_camera_set_gain_auto(camera, ARV_AUTO_OFF, &error)
            : arv_camera_set_exposure_time_auto(camera, ARV_AUTO_OFF, &error);
    automatic.note = Take(&error);
    const ArvAuto now =
        is_gain ? arv_camera_get_gain_auto(camera, &error) : arv_camera_get_exposure_time_auto(camera, &error);
    automatic.as_requested = Take(&error).empty() && now == ARV_AUTO_OFF;
    if (!automatic.as_requested && automatic.note.empty()) automatic.note = "reads back as not Off";
  }
  controls.push_back(automatic);
  AravisControlReport value{std::string(name) + (is_gain ? "_db" : "_s"), true, true, 0, ""};
  if (wanted >= 0) {
    is_gain ? arv_camera_set_gain(camera, wanted, &error) : arv_camera_set_exposure_time(camera, 1e6 * wanted, &error);
    value.note = Take(&error);
  }
  const double now = is_gain ? arv_camera_get_gain(camera, &error) : 1e-6 * arv_camera_get_exposure_time(camera, &error);
  if (const std::string e = Take(&error); !e.empty()) {
    value.supported = value.as_requested = false;
    value.note = "cannot be read: " + e;
  } else {
    value.value = now;
    value.as_requested = wanted < 0 || std::abs(now - wanted) <= 0.01 * std::max(std::abs(wanted), 1e-6);
    if (!value.as_requested && value.note.empty()) value.note = "reads back " + std::to_string(now);
  }
  if (!is_gain && value.supported) exposure_s = now;
  controls.push_back(value);
}

void AravisCamera::Impl::LockControls() {
  controls.clear();
  GError* error = nullptr;
  const bool exposure_auto = arv_camera_is_exposure_auto_available(camera, &error);
  const bool gain_auto = arv_camera_is_gain_auto_available(camera, &error);
  Take(&error);
  Lock("exposure", exposure_auto, false, options.exposure_s);
  Lock("gain", gain_auto, true, options.gain_db);
}

Status AravisCamera::Impl::StartStream() {
  GError* error = nullptr;
  triggered = false;
  const bool has_trigger = options.software_trigger && arv_camera_is_software_trigger_supported(camera, &error);
  Take(&error);
  if (has_trigger) {
    arv_camera_set_trigger(camera, "Software", &error);
    triggered = Take(&error).empty();
  }
  if (!triggered) {
    arv_camera_clear_triggers(camera, &error);
    Take(&error);
  }
  arv_camera_set_acquisition_mode(camera, ARV_ACQUISITION_MODE_CONTINUOUS, &error);
  Take(&error);
  stream = arv_camera_create_stream(camera, nullptr, nullptr, &error);
  if (stream == nullptr) return Disconnected("no stream could be opened (" + Take(&error) + ")");
  const guint payload = arv_camera_get_payload(camera, &error);
  if (const std::string e = Take(&error); !e.empty()) return Disconnected("reading its payload size failed (" + e + ")");
  for (int i = 0; i < options.num_buffers; ++i) arv_stream_push_buffer(stream, arv_buffer_new_allocate(payload));
  arv_camera_start_acquisition(camera, &error);
  if (const std::string e = Take(&error); !e.empty()) return Disconnected("acquisition did not start (" + e + ")");
  if (triggered) {
    // A camera that lists a software trigger but runs free anyway (Aravis' in-process fake does) would hand
    // out frames exposed before the trigger: watch for frames nobody triggered, and treat it as free-running.
    ArvBuffer* untriggered = arv_stream_timeout_pop_buffer(
        stream, static_cast<guint64>(1e6 * std::max(0.25, 2 * frame_period_s + exposure_s)));
    if (untriggered != nullptr) {
      arv_stream_push_buffer(stream, untriggered);
      triggered = false;
    }
  }
  return Status::Ok();
}

Status AravisCamera::Impl::Disconnected(const std::string& why) {
  failure = CaptureFailure(CaptureError::kDisconnected,
                           Who() + (identity.empty() ? "" : " (" + identity + ")") + ": " + why +
                               "; samples already captured stay valid; reconnect with Close() then Open()");
  return *failure;
}

// No frame in time: a camera that vanished (control lost, or no register readable any more) or a timeout.
Status AravisCamera::Impl::TimedOut(double not_before_s, double timeout_s) {
  GError* error = nullptr;
  if (control_lost) return Disconnected("the camera stopped answering (control lost)");
  arv_camera_get_payload(camera, &error);
  if (const std::string e = Take(&error); !e.empty()) return Disconnected("the camera stopped answering (" + e + ")");
  std::ostringstream why;
  why.precision(6);
  why << std::fixed << Who() << ": no frame " << ExposedAtOrAfterWords(not_before_s) << "arrived within " << timeout_s
      << " s (" << (triggered ? "software trigger" : "free-running") << ", " << sequence << " frames returned since Open)";
  return CaptureFailure(CaptureError::kTimeout, why.str());
}

Result<Frame> AravisCamera::Impl::TakeFrame(ArvBuffer* buffer, double exposure_time_s) {
  size_t size = 0;
  const auto* data = static_cast<const unsigned char*>(arv_buffer_get_image_data(buffer, &size));
  const int w = arv_buffer_get_image_width(buffer), h = arv_buffer_get_image_height(buffer);
  const ArvPixelFormat format = arv_buffer_get_image_pixel_format(buffer);
  if (data == nullptr || w != width_px || h != height_px || format != ARV_PIXEL_FORMAT_MONO_8 ||
      size < static_cast<size_t>(w) * static_cast<size_t>(h)) {
    std::ostringstream why;
    why << Who() << ": a buffer of " << size << " bytes, " << w << "x" << h << " pixel format 0x" << std::hex << format
        << ", not the " << std::dec << width_px << "x" << height_px << " Mono8 set at Open";
    arv_stream_push_buffer(stream, buffer);
    return CaptureFailure(CaptureError::kBadFrame, why.str());
  }
  Frame frame;
  frame.image.resize(static_cast<unsigned>(h), static_cast<unsigned>(w));
  std::memcpy(frame.image.bitmap, data, static_cast<size_t>(w) * static_cast<size_t>(h));
  arv_stream_push_buffer(stream, buffer);
  frame.exposure_time_s = exposure_time_s;
  frame.sequence = sequence++;
  frame.source = options.camera_id.empty() ? identity : options.camera_id;
  if (options.check_frames) {
    if (Status s = CheckFrame(frame.image, options.checks, frame.source); !s.ok()) return s;
  }
  return frame;
}

void AravisCamera::Impl::Shutdown() {
  if (camera != nullptr) {
    GError* error = nullptr;
    if (!failure || CaptureErrorOf(*failure) != CaptureError::kDisconnected) {
      arv_camera_stop_acquisition(camera, &error);  // a vanished camera would only make this wait
      Take(&error);
    }
    if (control_lost_handler != 0) g_signal_handler_disconnect(arv_camera_get_device(camera), control_lost_handler);
  }
  if (stream != nullptr) g_object_unref(stream);
  if (camera != nullptr) g_object_unref(camera);
  stream = nullptr;
  camera = nullptr;
  control_lost_handler = 0;
  control_lost = false;
  failure.reset();
  open = triggered = false;
  sequence = stale = 0;
}

AravisCamera::AravisCamera(AravisOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
AravisCamera::~AravisCamera() { impl_->Shutdown(); }

std::string AravisCamera::Describe() const {
  const Impl& m = *impl_;
  std::ostringstream out;
  out << "Aravis " << (m.options.camera_id.empty() ? "(first camera)" : m.options.camera_id);
  if (!m.open) return out.str() + " (not open)";
  out << " (" << m.identity << "): " << m.width_px << "x" << m.height_px << " Mono8, "
      << (m.triggered ? "software trigger" : "free-running") << ", " << 1000 * m.frame_period_s << " ms/frame";
  for (const AravisControlReport& c : m.controls) {
    out << "; " << c.name << ": " << (c.as_requested ? "locked" : "NOT locked");
    if (c.supported && c.name.find("_auto") == std::string::npos) out << " (value " << c.value << ")";
    if (!c.note.empty()) out << " (" << c.note << ")";
  }
  return out.str();
}

Status AravisCamera::Open() {
  Impl& m = *impl_;
  m.Shutdown();
  if (const std::string problems = m.options.Validate(); !problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "invalid Aravis camera options for " + m.Who() + ":\n" + problems);
  }
  auto fail = [&](Status s) {
    m.Shutdown();
    return s;
  };
  if (Status s = m.Connect(); !s.ok()) return fail(s);
  if (Status s = m.SetRegionAndFormat(); !s.ok()) return fail(s);
  m.LockControls();
  if (Status s = m.StartStream(); !s.ok()) return fail(s);
  m.open = true;
  Result<Frame> test = Grab(kAnyFrame, m.options.open_timeout_s);  // pre-flight test frame (V1, V3)
  if (!test.ok() && CaptureErrorOf(test.status()) != CaptureError::kBadFrame) return fail(test.status());
  return Status::Ok();
}

Result<Frame> AravisCamera::Grab(double not_before_s, double timeout_s) {
  Impl& m = *impl_;
  if (!m.open) return Status::Error(ErrorCode::kInvalidInput, "Grab on " + m.Who() + " before Open");
  if (!(timeout_s >= 0) || !std::isfinite(timeout_s)) {
    return Status::Error(ErrorCode::kInvalidInput, "Grab on " + m.Who() + ": timeout_s must be finite and >= 0");
  }
  if (m.failure) return *m.failure;
  const double deadline = MonotonicNowS() + timeout_s;
  while (ArvBuffer* waiting = arv_stream_try_pop_buffer(m.stream)) {  // never a buffer from before this grab
    arv_stream_push_buffer(m.stream, waiting);
    ++m.stale;
  }
  if (not_before_s > deadline) {
    SleepS(deadline - MonotonicNowS());
    return m.TimedOut(not_before_s, timeout_s);
  }
  SleepS(not_before_s - MonotonicNowS());
  const double triggered_at = MonotonicNowS();
  if (m.triggered) {
    GError* error = nullptr;
    arv_camera_software_trigger(m.camera, &error);
    if (const std::string e = Take(&error); !e.empty()) return m.Disconnected("the software trigger failed (" + e + ")");
  }
  for (;;) {
    const double left = deadline - MonotonicNowS();
    ArvBuffer* buffer = left > 0 ? arv_stream_timeout_pop_buffer(m.stream, static_cast<guint64>(1e6 * left)) : nullptr;
    if (buffer == nullptr) return m.TimedOut(not_before_s, timeout_s);
    const double arrived = ArrivalMonotonicS(buffer);
    const ArvBufferStatus status = arv_buffer_get_status(buffer);
    if (status != ARV_BUFFER_STATUS_SUCCESS) {
      arv_stream_push_buffer(m.stream, buffer);
      return CaptureFailure(CaptureError::kBadFrame,
                            m.Who() + ": an incomplete frame (Aravis buffer status " + std::to_string(status) + ")");
    }
    // Triggered: the camera exposed after the trigger. Free-running: the earliest the exposure can have begun.
    const double exposed = m.triggered ? triggered_at : arrived - m.exposure_s - m.frame_period_s;
    if ((m.triggered && arrived < triggered_at) || (!m.triggered && exposed < not_before_s)) {
      arv_stream_push_buffer(m.stream, buffer);
      ++m.stale;
      continue;
    }
    return m.TakeFrame(buffer, exposed);
  }
}

void AravisCamera::Close() { impl_->Shutdown(); }

const std::vector<AravisControlReport>& AravisCamera::controls() const { return impl_->controls; }
bool AravisCamera::triggered() const { return impl_->triggered; }
int64_t AravisCamera::stale_frames_discarded() const { return impl_->stale; }
std::string AravisCamera::identity() const { return impl_->identity; }

}  // namespace selfcal::capture
