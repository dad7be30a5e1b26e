// Device probing for V4l2Camera (V1): the node's checks and identity, formats, fourcc names.
#include "capture/v4l2_device.h"

#include <dirent.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <sstream>
#include <vector>

namespace selfcal::capture {
namespace internal {

std::string ErrnoText(int error) {
  std::ostringstream out;
  const char* name = ::strerrorname_np(error);
  out << "errno " << error;
  if (name != nullptr) out << " " << name;
  out << ": " << std::strerror(error);
  return out.str();
}

int Ioctl(int fd, unsigned long request, void* arg) {
  int rc;
  do {
    rc = ::ioctl(fd, request, arg);
  } while (rc == -1 && errno == EINTR);
  return rc;
}

// "/dev/video0, /dev/video1" or "none": what the user may have meant.
std::string ListVideoNodes() {
  DIR* dir = ::opendir("/dev");
  if (dir == nullptr) return "unknown";
  std::vector<std::string> nodes;
  while (const dirent* d = ::readdir(dir)) {
    if (std::strncmp(d->d_name, "video", 5) == 0) nodes.push_back(std::string("/dev/") + d->d_name);
  }
  ::closedir(dir);
  std::sort(nodes.begin(), nodes.end());
  std::string list;
  for (const std::string& n : nodes) list += (list.empty() ? "" : ", ") + n;
  return list.empty() ? "none" : list;
}

uint32_t Fourcc(V4l2PixelFormat format) {
  switch (format) {
    case V4l2PixelFormat::kGrey:
      return V4L2_PIX_FMT_GREY;
    case V4l2PixelFormat::kYuyv:
      return V4L2_PIX_FMT_YUYV;
    case V4l2PixelFormat::kRgb24:
      return V4L2_PIX_FMT_RGB24;
    case V4l2PixelFormat::kBgr24:
      return V4L2_PIX_FMT_BGR24;
    case V4l2PixelFormat::kRgb32:
      return V4L2_PIX_FMT_RGB32;
    case V4l2PixelFormat::kMjpeg:
      return V4L2_PIX_FMT_MJPEG;
  }
  return 0;
}

uint32_t BytesPerPixel(V4l2PixelFormat format) {
  switch (format) {
    case V4l2PixelFormat::kGrey:
      return 1;
    case V4l2PixelFormat::kYuyv:
      return 2;
    case V4l2PixelFormat::kRgb24:
    case V4l2PixelFormat::kBgr24:
      return 3;
    case V4l2PixelFormat::kRgb32:
      return 4;
    case V4l2PixelFormat::kMjpeg:
      return 0;  // compressed: no fixed row length
  }
  return 0;
}

// stat + open + QUERYCAP with typed errors (V1). Fills the identity fields of `info`.
Result<DeviceFd> OpenNode(const std::string& path, V4l2DeviceInfo* info) {
  const std::string who = "camera " + path + ": ";
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int e = errno;
    if (e == EACCES)
      return CaptureFailure(CaptureError::kPermissionDenied, who + "cannot reach the node (" + ErrnoText(e) + ")");
    return CaptureFailure(CaptureError::kDeviceMissing,
                          who + "does not exist (" + ErrnoText(e) +
                              "); is the camera plugged in? video nodes present: " + ListVideoNodes());
  }
  if (!S_ISCHR(st.st_mode)) {
    const char* kind = S_ISDIR(st.st_mode)   ? "a directory"
                       : S_ISREG(st.st_mode) ? "a regular file"
                                             : "not a character device";
    return CaptureFailure(CaptureError::kNotV4l2,
                          who + "is " + kind + ", not a V4L2 device node; video nodes present: " + ListVideoNodes());
  }
  DeviceFd fd(::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) {
    const int e = errno;
    if (e == EACCES || e == EPERM) {
      return CaptureFailure(CaptureError::kPermissionDenied,
                            who + "permission denied (" + ErrnoText(e) + "); add the user to the `video` group");
    }
    if (e == EBUSY)
      return CaptureFailure(CaptureError::kDeviceBusy, who + "busy (" + ErrnoText(e) + "); another program uses it");
    return CaptureFailure(CaptureError::kDeviceMissing,
                          who + "cannot be opened (" + ErrnoText(e) + "); no driver behind the node?");
  }
  v4l2_capability cap{};
  if (Ioctl(fd.get(), VIDIOC_QUERYCAP, &cap) != 0) {
    const int e = errno;
    if (e == ENODEV)
      return CaptureFailure(CaptureError::kDeviceMissing, who + "the device is gone (" + ErrnoText(e) + ")");
    return CaptureFailure(CaptureError::kNotV4l2, who + "not a V4L2 device (VIDIOC_QUERYCAP failed: " + ErrnoText(e) +
                                                      "); video nodes present: " + ListVideoNodes());
  }
  info->path = path;
  info->driver = reinterpret_cast<const char*>(cap.driver);
  info->card = reinterpret_cast<const char*>(cap.card);
  info->bus_info = reinterpret_cast<const char*>(cap.bus_info);
  info->device_caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  const bool capture = (info->device_caps & V4L2_CAP_VIDEO_CAPTURE) != 0;
  const bool streaming = (info->device_caps & V4L2_CAP_STREAMING) != 0;
  if (!capture || !streaming) {
    std::string what = !capture ? "cannot capture single-planar video" : "has no streaming I/O";
    if (info->device_caps & V4L2_CAP_META_CAPTURE)
      what += " (a metadata node: UVC cameras have one beside the video node)";
    if (info->device_caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE)
      what += " (multi-planar only; vpV4l2Grabber needs single-planar)";
    return CaptureFailure(CaptureError::kNotV4l2, who + "V4L2 device `" + info->card + "` (driver " + info->driver +
                                                      ") " + what + "; video nodes present: " + ListVideoNodes());
  }
  return fd;
}

void ReadFormat(int fd, V4l2DeviceInfo* info) {
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Ioctl(fd, VIDIOC_G_FMT, &fmt) == 0) {
    info->width_px = static_cast<int>(fmt.fmt.pix.width);
    info->height_px = static_cast<int>(fmt.fmt.pix.height);
    info->pixel_format = fmt.fmt.pix.pixelformat;
    info->bytes_per_line = fmt.fmt.pix.bytesperline;
  }
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Ioctl(fd, VIDIOC_G_PARM, &parm) == 0 && parm.parm.capture.timeperframe.denominator != 0) {
    info->frame_period_s =
        static_cast<double>(parm.parm.capture.timeperframe.numerator) / parm.parm.capture.timeperframe.denominator;
  }
}

std::string FormatText(int width, int height, uint32_t fourcc, uint32_t bytes_per_line) {
  std::ostringstream out;
  out << width << "x" << height << " " << FourccToString(fourcc);
  if (bytes_per_line != 0) out << " (" << bytes_per_line << " bytes/row)";
  return out.str();
}

}  // namespace internal

const char* V4l2PixelFormatName(V4l2PixelFormat format) {
  switch (format) {
    case V4l2PixelFormat::kGrey:
      return "GREY";
    case V4l2PixelFormat::kYuyv:
      return "YUYV";
    case V4l2PixelFormat::kRgb24:
      return "RGB3";
    case V4l2PixelFormat::kBgr24:
      return "BGR3";
    case V4l2PixelFormat::kRgb32:
      return "RGB4";
    case V4l2PixelFormat::kMjpeg:
      return "MJPG";
  }
  return "?";
}

bool V4l2PixelFormatFromName(const std::string& name, V4l2PixelFormat* format) {
  for (V4l2PixelFormat f : {V4l2PixelFormat::kGrey, V4l2PixelFormat::kYuyv, V4l2PixelFormat::kRgb24,
                            V4l2PixelFormat::kBgr24, V4l2PixelFormat::kRgb32, V4l2PixelFormat::kMjpeg}) {
    if (name == V4l2PixelFormatName(f)) {
      *format = f;
      return true;
    }
  }
  return false;
}

std::string FourccToString(uint32_t fourcc) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xFF);
    s.push_back(c >= 0x20 && c < 0x7F ? c : '?');
  }
  return s;
}

Result<V4l2DeviceInfo> ProbeV4l2Device(const std::string& path) {
  V4l2DeviceInfo info;
  Result<internal::DeviceFd> fd = internal::OpenNode(path, &info);
  if (!fd.ok()) return fd.status();
  internal::ReadFormat(fd->get(), &info);
  return info;
}

}  // namespace selfcal::capture
