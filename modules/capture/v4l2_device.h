// Internal to capture: V4L2 device probing shared by ProbeV4l2Device and V4l2Camera (V1 checks, the
// current format, fourcc codes), kept apart from the camera's streaming.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <string>

#include "capture/v4l2_camera.h"

namespace selfcal::capture::internal {

// "errno 16 EBUSY: Device or resource busy".
std::string ErrnoText(int error);
// ioctl, retried on EINTR.
int Ioctl(int fd, unsigned long request, void* arg);
// "/dev/video0, /dev/video1" or "none": what the user may have meant.
std::string ListVideoNodes();
uint32_t Fourcc(V4l2PixelFormat format);
uint32_t BytesPerPixel(V4l2PixelFormat format);

// A descriptor on a device node that passed the V1 checks, closed on destruction.
class DeviceFd {
 public:
  DeviceFd() = default;
  explicit DeviceFd(int fd) : fd_(fd) {}
  DeviceFd(DeviceFd&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  DeviceFd& operator=(DeviceFd&& other) noexcept {
    if (this != &other) {
      Reset();
      fd_ = other.fd_;
      other.fd_ = -1;
    }
    return *this;
  }
  ~DeviceFd() { Reset(); }
  void Reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  int get() const { return fd_; }

 private:
  int fd_ = -1;
};


// stat + open + QUERYCAP with typed errors (V1). Fills the identity fields of `info`.
Result<DeviceFd> OpenNode(const std::string& path, V4l2DeviceInfo* info);
// VIDIOC_G_FMT and VIDIOC_G_PARM into `info` (fields left as they are when a call fails).
void ReadFormat(int fd, V4l2DeviceInfo* info);
// "640x480 YUYV (1280 bytes/row)".
std::string FormatText(int width, int height, uint32_t fourcc, uint32_t bytes_per_line);

}  // namespace selfcal::capture::internal
