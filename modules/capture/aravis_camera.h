// GigE Vision and USB3 Vision cameras (what most calibration cells use) as a FrameSource, through Aravis
// 0.8 (Debian's libaravis-dev). Aravis' own simulated camera serves the tests and rehearsals: the in-process
// "Fake" interface (camera id "Fake_1", free-running) and arv-fake-gv-camera-0.8, a GigE Vision camera on a
// loopback address (id = that address; software trigger honoured; killing it is a camera that vanishes).
//
// Open: the camera found by id (empty: the first one Aravis lists), its region set when asked, exposure
// and gain locked (ExposureAuto and GainAuto Off, then the values asked for, each read back and reported:
// the V4L2 camera's rule, ../shared/RELIABILITY.md V7), pixel format Mono8, a software trigger when the camera has
// one, streaming started, a test frame within open_timeout_s.
//
// Grab at the pose (V5): buffers already waiting are discarded, the grab waits until not_before_s (the
// settle time, MonotonicNowS()), then
//   - with a software trigger, triggers and returns the one frame that answers it: exposure_time_s is the
//     trigger's time (the camera exposes after the trigger);
//   - free-running, returns the first frame whose exposure began, at the earliest, at not_before_s:
//     exposure_time_s is a lower bound, the host's arrival time (Aravis' system timestamp) less the
//     exposure time and one frame period.
// Timeout (V3): no such frame within timeout_s is kTimeout. Vanished camera (V4): a failed trigger, the
// device's control-lost signal, or after a timeout a register that cannot be read any more gives
// kDisconnected, sticky until Close; frames already returned stay valid. Detecting a vanished GigE camera
// takes Aravis' GVCP retries (2.5-3.5 s with arv-fake-gv-camera), and Close of it about 10 s more (Aravis
// gives up on the device when it is released; 0.8 has no setting for it). UNTESTED on real cameras: USB3
// Vision, packet loss (Aravis' incomplete buffers are kBadFrame), cameras without Mono8 (refused).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "base/status.h"
#include "capture/frame_checks.h"
#include "capture/frame_source.h"

namespace selfcal::capture {

struct AravisOptions {
  std::string camera_id;               // Aravis' id ("Vendor-Model-Serial", an IP address); empty: the first
  bool fake_interface = false;         // enable Aravis' in-process "Fake" interface (camera "Fake_1")
  int width_px = 0, height_px = 0;     // the region; 0: the camera's current one
  double exposure_s = -1;              // with exposure locked; < 0 keeps the camera's value
  double gain_db = -1;                 // with gain locked; < 0 keeps the camera's value
  double frame_rate_hz = 0;            // 0 keeps the camera's rate
  bool software_trigger = true;        // use it when the camera has one
  int num_buffers = 4;
  double open_timeout_s = 3.0;
  bool check_frames = true;
  FrameCheckOptions checks;
  std::string Validate() const;  // empty when valid; otherwise every problem, one per line
};

// A lock of V7 after Open: what the camera reports now.
struct AravisControlReport {
  std::string name;  // "exposure_auto", "gain_auto", "exposure_s", "gain_db"
  bool supported = false;
  bool as_requested = false;
  double value = 0;
  std::string note;
};

class AravisCamera : public FrameSource {
 public:
  explicit AravisCamera(AravisOptions options);
  ~AravisCamera() override;
  AravisCamera(const AravisCamera&) = delete;
  AravisCamera& operator=(const AravisCamera&) = delete;

  std::string Describe() const override;
  Status Open() override;
  Result<Frame> Grab(double not_before_s, double timeout_s) override;
  void Close() override;

  const std::vector<AravisControlReport>& controls() const;
  bool triggered() const;                  // the software trigger is in use
  int64_t stale_frames_discarded() const;  // waiting buffers dropped by Grab, or exposed too early
  std::string identity() const;            // "vendor model serial", after Open

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace selfcal::capture
