#include "liveview/x11_connection.h"

#include <cstdlib>

#include <X11/Xlib.h>

namespace selfcal::liveview::internal {

namespace {

extern "C" int OnXIOError(Display*) noexcept(false) { throw XConnectionLost(); }

extern "C" int OnXError(Display*, XErrorEvent*) { return 0; }

}  // namespace

std::string XDisplayProblem() {
  const char* name = std::getenv("DISPLAY");
  if (name == nullptr || *name == '\0') return "$DISPLAY is not set";
  Display* display = XOpenDisplay(nullptr);
  if (display == nullptr) return std::string("cannot open the X display ") + name;
  XCloseDisplay(display);
  return "";
}

void InstallXHandlers() {
  static const bool installed = [] {
    XSetIOErrorHandler(OnXIOError);
    XSetErrorHandler(OnXError);
    return true;
  }();
  (void)installed;
}

}  // namespace selfcal::liveview::internal
