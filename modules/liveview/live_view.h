// Module liveview (ARCHITECTURE.md): this header and x11_connection.h. Uses acquisition, capture, base,
// ViSP (visp_gui) and X11.
//
// The live view of a session (`selfcal run` / `simulate --live-view`): every frame the session loop
// looks at (acquisition::FrameView, through RunContext::observe) drawn in an X11 window through ViSP's
// vpDisplayX: the grey image, a cross and the id per dot coloured by its state (green tracked, cyan
// named at this pose, red lost at this pose, yellow candidate), and the pose number, id and phase as text
// (docs/session-format.md, "Live view"). Only this module links ViSP's gui module and X11; the session
// loop knows nothing of displays.
//
// Drawing is throttled so that the loop is not slowed: frames of a move are drawn at most
// LiveViewOptions::max_moving_redraws_per_s times a second (wall clock), every settled, accepted and
// skipped frame is drawn. A display that fails while drawing turns the view off (said once through
// LiveViewOptions::log); the session goes on.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include <visp3/core/vpImage.h>
#include <visp3/core/vpRGBa.h>

#include "acquisition/session_runner.h"
#include "base/status.h"

namespace selfcal::liveview {

enum class LiveViewMode {
  kAuto,  // on when an X display ($DISPLAY) can be opened, else off without an error
  kOn,    // refused (kInvalidInput) when no X display can be opened
  kOff,
};
// "auto", "on", "off"; kInvalidInput naming the option otherwise.
Result<LiveViewMode> ParseLiveViewMode(const std::string& text);

struct LiveViewOptions {
  double max_moving_redraws_per_s = 15;  // frames of a move; settled / accepted / skipped ones always
  std::string title = "selfcal run";
  std::function<void(const std::string& line)> log;  // the view turned itself off, and why (optional)
};

// Empty when an X display can be opened (XOpenDisplay of $DISPLAY) by this build, else why not in a
// sentence ("$DISPLAY is not set", "cannot open the X display :3", "this build has no X11 display").
std::string DisplayUnavailableReason();

class LiveView {
 public:
  explicit LiveView(LiveViewOptions options);
  ~LiveView();
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  // Draws `view` (throttled, see above); the window opens at the first frame, at that frame's size.
  void Show(const acquisition::FrameView& view);

  int frames_drawn() const { return drawn_; }
  int frames_throttled() const { return throttled_; }
  bool failed() const { return failed_; }

  // The window's content as drawn last, read back from the X server (vpDisplay::getImage): the image
  // with its overlay. kInvalidInput before the first frame was drawn or when the display failed.
  Result<vpImage<vpRGBa>> Snapshot();

 private:
  struct Window;
  void Draw(const acquisition::FrameView& view);
  void Fail(const std::string& why);

  LiveViewOptions options_;
  std::unique_ptr<Window> window_;
  double last_draw_s_ = -1e300;  // steady clock
  int drawn_ = 0, throttled_ = 0;
  bool failed_ = false;
};

// The live view `mode` asks for: null for kOff, and for kAuto when no display can be opened (then *note,
// if given, says why in a line for the operator; with a view it says "live view on ..."). kInvalidInput
// for kOn without a display, naming the reason and `--live-view off`.
Result<std::unique_ptr<LiveView>> OpenLiveView(LiveViewMode mode, const LiveViewOptions& options,
                                               std::string* note = nullptr);

}  // namespace selfcal::liveview
