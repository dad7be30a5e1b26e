#include "liveview/live_view.h"

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <sstream>

#if defined(SELFCAL_HAVE_VISP_DISPLAY_X)
#include <visp3/core/vpDisplay.h>
#include <visp3/core/vpException.h>
#include <visp3/gui/vpDisplayX.h>

#include "liveview/x11_connection.h"
#endif

namespace selfcal::liveview {

namespace {

double SteadyNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

Result<LiveViewMode> ParseLiveViewMode(const std::string& text) {
  if (text == "auto") return LiveViewMode::kAuto;
  if (text == "on") return LiveViewMode::kOn;
  if (text == "off") return LiveViewMode::kOff;
  return Status::Error(ErrorCode::kInvalidInput, "--live-view must be auto, on or off, not \"" + text + "\"");
}

std::string DisplayUnavailableReason() {
#if defined(SELFCAL_HAVE_VISP_DISPLAY_X)
  return internal::XDisplayProblem();
#else
  return "this build has no X11 display (ViSP without X11)";
#endif
}

#if defined(SELFCAL_HAVE_VISP_DISPLAY_X)
// The window and the image it is attached to (vpDisplay draws on the image's display).
struct LiveView::Window {
  vpImage<unsigned char> image;
  vpDisplayX display;
};
#else
struct LiveView::Window {};
#endif

LiveView::LiveView(LiveViewOptions options) : options_(std::move(options)) {}
LiveView::~LiveView() = default;

void LiveView::Fail(const std::string& why) {
  failed_ = true;
  window_.reset();
  if (options_.log) options_.log("live view off: " + why + " (the session goes on)");
}

void LiveView::Show(const acquisition::FrameView& view) {
  if (failed_ || view.frame == nullptr) return;
  const double now = SteadyNow();
  if (view.phase == acquisition::FramePhase::kMoving && options_.max_moving_redraws_per_s > 0 &&
      now - last_draw_s_ < 1.0 / options_.max_moving_redraws_per_s) {
    ++throttled_;
    return;
  }
  last_draw_s_ = now;
  Draw(view);
}

#if defined(SELFCAL_HAVE_VISP_DISPLAY_X)

namespace {

using internal::InstallXHandlers;
using internal::XConnectionLost;

vpColor ColorOf(acquisition::ViewDotState state) {
  switch (state) {
    case acquisition::ViewDotState::kTracked: return vpColor::green;
    case acquisition::ViewDotState::kNamed: return vpColor::cyan;
    case acquisition::ViewDotState::kLost: return vpColor::red;
    case acquisition::ViewDotState::kCandidate: return vpColor::yellow;
  }
  return vpColor::white;
}

// "pose 4/20 p03: settled, 41 dots (2 lost)" or "pose 4/20 p03: SKIPPED (too_few_dots), 3 dots".
std::string Headline(const acquisition::FrameView& view) {
  int lost = 0, shown = 0;
  for (const acquisition::ViewDot& d : view.dots) {
    lost += d.state == acquisition::ViewDotState::kLost ? 1 : 0;
    shown += d.state == acquisition::ViewDotState::kLost || d.state == acquisition::ViewDotState::kCandidate ? 0 : 1;
  }
  std::ostringstream text;
  text << "pose " << view.pose + 1 << "/" << view.num_poses << " " << view.pose_id << ": ";
  if (view.phase == acquisition::FramePhase::kSkipped) {
    text << "SKIPPED (" << view.detail << ")";
  } else {
    text << acquisition::FramePhaseName(view.phase);
  }
  text << ", " << shown << " dots";
  if (lost > 0) text << " (" << lost << " lost)";
  return text.str();
}

}  // namespace

void LiveView::Draw(const acquisition::FrameView& view) {
  const vpImage<unsigned char>& frame = view.frame->image;
  InstallXHandlers();
  try {
    if (window_ != nullptr &&
        (window_->image.getWidth() != frame.getWidth() || window_->image.getHeight() != frame.getHeight())) {
      window_.reset();  // another image size: a new window
    }
    if (window_ == nullptr) {
      window_ = std::make_unique<Window>();
      window_->image.resize(frame.getHeight(), frame.getWidth());
      window_->display.init(window_->image, -1, -1, options_.title);
    }
    vpImage<unsigned char>& shown = window_->image;
    // The bitmap only: assigning the vpImage would also take the frame's (absent) display.
    std::memcpy(shown.bitmap, frame.bitmap, static_cast<std::size_t>(frame.getSize()));
    vpDisplay::display(shown);
    for (const acquisition::ViewDot& d : view.dots) {
      const vpColor color = ColorOf(d.state);
      const vpImagePoint at(d.centroid_px.y(), d.centroid_px.x());
      vpDisplay::displayCross(shown, at, 15, color, 2);
      vpDisplay::displayText(shown, vpImagePoint(at.get_i() - 6, at.get_j() + 7), std::to_string(d.id), color);
    }
    const vpColor headline = view.phase == acquisition::FramePhase::kSkipped ? vpColor::red : vpColor::yellow;
    vpDisplay::displayText(shown, 16, 10, Headline(view), headline);
    vpDisplay::displayText(shown, static_cast<int>(shown.getHeight()) - 10, 10,
                           "green tracked, cyan named here, red lost here, yellow candidate", vpColor::white);
    vpDisplay::flush(shown);
    ++drawn_;
  } catch (const vpException& e) {
    Fail(e.getStringMessage());
  } catch (const XConnectionLost&) {
    (void)window_.release();  // its connection is dead: closing it would only fail again
    Fail("the connection to the X display was lost");
  }
}

Result<vpImage<vpRGBa>> LiveView::Snapshot() {
  if (window_ == nullptr || drawn_ == 0) {
    return Status::Error(ErrorCode::kInvalidInput, "the live view has drawn no frame");
  }
  vpImage<vpRGBa> content;
  try {
    vpDisplay::getImage(window_->image, content);
  } catch (const vpException& e) {
    return Status::Error(ErrorCode::kHardware, "reading the live view's window back: " + e.getStringMessage());
  } catch (const XConnectionLost&) {
    (void)window_.release();
    Fail("the connection to the X display was lost");
    return Status::Error(ErrorCode::kHardware, "reading the live view's window back: the X connection was lost");
  }
  return content;
}

#else

void LiveView::Draw(const acquisition::FrameView&) { Fail(DisplayUnavailableReason()); }

Result<vpImage<vpRGBa>> LiveView::Snapshot() {
  return Status::Error(ErrorCode::kInvalidInput, DisplayUnavailableReason());
}

#endif

Result<std::unique_ptr<LiveView>> OpenLiveView(LiveViewMode mode, const LiveViewOptions& options, std::string* note) {
  if (note != nullptr) note->clear();
  if (mode == LiveViewMode::kOff) return std::unique_ptr<LiveView>();
  const std::string why = DisplayUnavailableReason();
  if (!why.empty()) {
    if (mode == LiveViewMode::kOn) {
      return Status::Error(ErrorCode::kInvalidInput, "--live-view on: " + why +
                                                         "; start the run where an X display is available (or "
                                                         "under Xvfb), or give --live-view off");
    }
    if (note != nullptr) *note = "live view off: " + why;
    return std::unique_ptr<LiveView>();
  }
  if (note != nullptr) *note = std::string("live view on display ") + std::getenv("DISPLAY");
  return std::make_unique<LiveView>(options);
}

}  // namespace selfcal::liveview
