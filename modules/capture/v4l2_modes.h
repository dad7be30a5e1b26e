// What a V4L2 device offers (VIDIOC_ENUM_FMT, VIDIOC_ENUM_FRAMESIZES, VIDIOC_ENUM_FRAMEINTERVALS) and the
// check of a requested size, pixel format and frame period against it, kept apart from the device so that
// the check and its refusal are tested without a camera.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal::capture {

// One frame size of one pixel format, with its frame periods. Stepwise/continuous ranges are kept as such.
struct V4l2Mode {
  uint32_t fourcc = 0;
  std::string description;  // the driver's, e.g. "Motion-JPEG"
  bool compressed = false;
  // Discrete size: min == max. Stepwise or continuous: a range with steps.
  int min_width_px = 0, max_width_px = 0, step_width_px = 1;
  int min_height_px = 0, max_height_px = 0, step_height_px = 1;
  // Discrete frame periods, seconds; empty with a range, or when the driver lists none (then any period is
  // accepted and the one in effect is read back).
  std::vector<double> periods_s;
  double min_period_s = 0, max_period_s = 0;  // a stepwise/continuous range; 0 when none

  bool HasSize(int width_px, int height_px) const;
  bool HasPeriod(double period_s) const;  // within 1 % (drivers list 1/30 as 333333/10000000, ...)
};

// The device's list, read from an open descriptor (empty when the driver enumerates nothing).
std::vector<V4l2Mode> EnumerateV4l2Modes(int fd);

// "MJPG 1280x720 @ 30, 15 fps; YUYV 640x480 @ 30 fps; ...", one mode per line for messages.
std::string V4l2ModesText(const std::vector<V4l2Mode>& modes);

// OK when `modes` offers the format at that size and period (or lists no periods for it; period_s <= 0:
// any period). Otherwise a
// kFormatMismatch naming `device` and listing what it offers. An empty list (a driver that enumerates
// nothing) is accepted: the format read back after VIDIOC_S_FMT is checked anyway.
Status CheckV4l2ModeOffered(const std::vector<V4l2Mode>& modes, const std::string& device, uint32_t fourcc,
                            int width_px, int height_px, double period_s);

}  // namespace selfcal::capture
