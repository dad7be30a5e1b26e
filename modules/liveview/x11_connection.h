// Internal to liveview: the parts of Xlib the live view uses directly, kept out of every other source
// (Xlib.h defines macros such as Status and Bool that clash with ours).
#pragma once

#include <string>

namespace selfcal::liveview::internal {

// Empty when XOpenDisplay($DISPLAY) succeeds (the connection is closed again), else why not.
std::string XDisplayProblem();

// Thrown out of an Xlib call when the X connection is lost (see InstallXHandlers).
struct XConnectionLost {};

// Once per process: Xlib's default handlers end the process (exit(1)) when the X connection is lost
// (the server stopped, the window manager killed the client when its window was closed) or on a protocol
// error; a robot session must never end that way, mid-move and without its stop. The connection's loss
// throws XConnectionLost, which unwinds out of the Xlib call (Xlib is C, built with unwind tables on
// Debian) to the drawing code, which must then never touch that connection again; a protocol error is
// ignored (the drawing goes on or fails visibly).
void InstallXHandlers();

}  // namespace selfcal::liveview::internal
