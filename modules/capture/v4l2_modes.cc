// VIDIOC_ENUM_FMT / ENUM_FRAMESIZES / ENUM_FRAMEINTERVALS and the check of a requested mode against them.
#include "capture/v4l2_modes.h"

#include <linux/videodev2.h>

#include <cmath>
#include <sstream>

#include "capture/frame_source.h"
#include "capture/v4l2_camera.h"
#include "capture/v4l2_device.h"

namespace selfcal::capture {

namespace {

using internal::Ioctl;

double PeriodOf(const v4l2_fract& f) {
  return f.denominator == 0 ? 0.0 : static_cast<double>(f.numerator) / f.denominator;
}

bool InSteps(int value, int min, int max, int step) {
  if (value < min || value > max) return false;
  return step <= 1 || (value - min) % step == 0;
}

void ReadPeriods(int fd, V4l2Mode* mode) {
  v4l2_frmivalenum ival{};
  ival.pixel_format = mode->fourcc;
  ival.width = static_cast<uint32_t>(mode->min_width_px);
  ival.height = static_cast<uint32_t>(mode->min_height_px);
  for (ival.index = 0; Ioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &ival) == 0 && ival.index < 64; ++ival.index) {
    if (ival.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
      mode->periods_s.push_back(PeriodOf(ival.discrete));
    } else {
      mode->min_period_s = PeriodOf(ival.stepwise.min);
      mode->max_period_s = PeriodOf(ival.stepwise.max);
      return;
    }
  }
}

std::string FpsText(double period_s) {
  std::ostringstream out;
  out.precision(4);
  out << 1.0 / period_s;
  return out.str();
}

}  // namespace

bool V4l2Mode::HasSize(int width_px, int height_px) const {
  return InSteps(width_px, min_width_px, max_width_px, step_width_px) &&
         InSteps(height_px, min_height_px, max_height_px, step_height_px);
}

bool V4l2Mode::HasPeriod(double period_s) const {
  if (period_s <= 0 || (periods_s.empty() && min_period_s <= 0)) return true;  // any, or the driver lists none
  for (double p : periods_s) {
    if (std::abs(p - period_s) <= 0.01 * p) return true;
  }
  return min_period_s > 0 && period_s >= 0.99 * min_period_s && period_s <= 1.01 * max_period_s;
}

std::vector<V4l2Mode> EnumerateV4l2Modes(int fd) {
  std::vector<V4l2Mode> modes;
  v4l2_fmtdesc desc{};
  desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  for (desc.index = 0; Ioctl(fd, VIDIOC_ENUM_FMT, &desc) == 0 && desc.index < 64; ++desc.index) {
    V4l2Mode format;
    format.fourcc = desc.pixelformat;
    format.description = reinterpret_cast<const char*>(desc.description);
    format.compressed = (desc.flags & V4L2_FMT_FLAG_COMPRESSED) != 0;
    v4l2_frmsizeenum size{};
    size.pixel_format = desc.pixelformat;
    for (size.index = 0; Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &size) == 0 && size.index < 256; ++size.index) {
      V4l2Mode mode = format;
      if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        mode.min_width_px = mode.max_width_px = static_cast<int>(size.discrete.width);
        mode.min_height_px = mode.max_height_px = static_cast<int>(size.discrete.height);
      } else {
        mode.min_width_px = static_cast<int>(size.stepwise.min_width);
        mode.max_width_px = static_cast<int>(size.stepwise.max_width);
        mode.step_width_px = static_cast<int>(size.stepwise.step_width);
        mode.min_height_px = static_cast<int>(size.stepwise.min_height);
        mode.max_height_px = static_cast<int>(size.stepwise.max_height);
        mode.step_height_px = static_cast<int>(size.stepwise.step_height);
      }
      ReadPeriods(fd, &mode);
      modes.push_back(mode);
      if (size.type != V4L2_FRMSIZE_TYPE_DISCRETE) break;
    }
  }
  return modes;
}

std::string V4l2ModesText(const std::vector<V4l2Mode>& modes) {
  std::ostringstream out;
  for (const V4l2Mode& m : modes) {
    out << "  " << FourccToString(m.fourcc) << " ";
    if (m.min_width_px == m.max_width_px && m.min_height_px == m.max_height_px) {
      out << m.min_width_px << "x" << m.min_height_px;
    } else {
      out << m.min_width_px << "x" << m.min_height_px << " to " << m.max_width_px << "x" << m.max_height_px
          << " in steps of " << m.step_width_px << "x" << m.step_height_px;
    }
    if (!m.periods_s.empty()) {
      out << " @";
      for (size_t i = 0; i < m.periods_s.size(); ++i) out << (i == 0 ? " " : ", ") << FpsText(m.periods_s[i]);
      out << " fps";
    } else if (m.min_period_s > 0) {
      out << " @ " << FpsText(m.max_period_s) << " to " << FpsText(m.min_period_s) << " fps";
    }
    out << "\n";
  }
  return out.str();
}

Status CheckV4l2ModeOffered(const std::vector<V4l2Mode>& modes, const std::string& device, uint32_t fourcc,
                            int width_px, int height_px, double period_s) {
  if (modes.empty()) return Status::Ok();
  bool format_listed = false, size_listed = false;
  for (const V4l2Mode& m : modes) {
    if (m.fourcc != fourcc) continue;
    format_listed = true;
    if (!m.HasSize(width_px, height_px)) continue;
    size_listed = true;
    if (m.HasPeriod(period_s)) return Status::Ok();
  }
  std::ostringstream why;
  why << "camera " << device << " does not offer " << FourccToString(fourcc) << " " << width_px << "x"
      << height_px;
  if (period_s > 0) why << " at " << FpsText(period_s) << " fps";
  why << " ("
      << (!format_listed ? "no such pixel format" : !size_listed ? "not at that size" : "not at that frame rate")
      << "); it offers:\n"
      << V4l2ModesText(modes) << "choose one of these with --camera-format, --camera-width-px, --camera-height-px "
      << "and --camera-fps (and intrinsics of that resolution)";
  return CaptureFailure(CaptureError::kFormatMismatch, why.str());
}

}  // namespace selfcal::capture
