#include "capture/v4l2_stream.h"

#include <linux/videodev2.h>
#include <sys/mman.h>
#include <sys/select.h>

#include <cerrno>
#include <cmath>

#include "capture/frame_source.h"
#include "capture/v4l2_device.h"

namespace selfcal::capture::internal {

namespace {

Status StreamFailure(const std::string& device, const char* call, int error) {
  const std::string what = "camera " + device + ": " + call + " failed (" + ErrnoText(error) + ")";
  if (error == ENODEV) return CaptureFailure(CaptureError::kDisconnected, what + ": disconnected");
  if (error == EBUSY) return CaptureFailure(CaptureError::kDeviceBusy, what + ": another program streams from it");
  return CaptureFailure(CaptureError::kFormatMismatch, what);
}

}  // namespace

Status MmapStream::Start(int fd, int num_buffers, const std::string& device) {
  Stop();
  fd_ = fd;
  device_ = device;
  v4l2_requestbuffers request{};
  request.count = static_cast<uint32_t>(num_buffers);
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  if (Ioctl(fd_, VIDIOC_REQBUFS, &request) != 0) return StreamFailure(device_, "VIDIOC_REQBUFS", errno);
  if (request.count < 1) return StreamFailure(device_, "VIDIOC_REQBUFS (no buffer granted)", ENOMEM);
  for (uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    buffer.index = i;
    if (Ioctl(fd_, VIDIOC_QUERYBUF, &buffer) != 0) return StreamFailure(device_, "VIDIOC_QUERYBUF", errno);
    void* start = ::mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, buffer.m.offset);
    if (start == MAP_FAILED) return StreamFailure(device_, "mmap", errno);
    buffers_.push_back({start, buffer.length});
    if (Ioctl(fd_, VIDIOC_QBUF, &buffer) != 0) return StreamFailure(device_, "VIDIOC_QBUF", errno);
  }
  v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Ioctl(fd_, VIDIOC_STREAMON, &type) != 0) return StreamFailure(device_, "VIDIOC_STREAMON", errno);
  streaming_ = true;
  return Status::Ok();
}

Result<DequeuedBuffer> MmapStream::Dequeue(double timeout_s, bool* timed_out) {
  *timed_out = false;
  fd_set readable;
  FD_ZERO(&readable);
  FD_SET(fd_, &readable);
  timeval wait{};
  wait.tv_sec = static_cast<time_t>(timeout_s);
  wait.tv_usec = static_cast<suseconds_t>(1e6 * (timeout_s - std::floor(timeout_s)));
  const int ready = ::select(fd_ + 1, &readable, nullptr, nullptr, &wait);
  if (ready < 0 && errno != EINTR) return StreamFailure(device_, "select", errno);
  v4l2_buffer buffer{};
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  if (ready <= 0 || Ioctl(fd_, VIDIOC_DQBUF, &buffer) != 0) {
    if (ready <= 0 || errno == EAGAIN) {
      *timed_out = true;
      return CaptureFailure(CaptureError::kTimeout, "camera " + device_ + ": no frame within the timeout");
    }
    const int error = errno;
    return CaptureFailure(CaptureError::kDisconnected,
                          "camera " + device_ + ": VIDIOC_DQBUF failed (" + ErrnoText(error) + ")" +
                              (error == ENODEV ? ": disconnected" : ""));
  }
  DequeuedBuffer out;
  out.index = static_cast<int>(buffer.index);
  out.data = static_cast<const uint8_t*>(buffers_.at(buffer.index).start);
  out.bytes_used = std::min<size_t>(buffer.bytesused, buffers_.at(buffer.index).length);
  out.timestamp_s = static_cast<double>(buffer.timestamp.tv_sec) + 1e-6 * static_cast<double>(buffer.timestamp.tv_usec);
  out.driver_error = (buffer.flags & V4L2_BUF_FLAG_ERROR) != 0;
  return out;
}

void MmapStream::Requeue(int index) {
  v4l2_buffer buffer{};
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  buffer.index = static_cast<uint32_t>(index);
  Ioctl(fd_, VIDIOC_QBUF, &buffer);  // a failure shows as the next Dequeue's error
}

void MmapStream::Stop() {
  if (streaming_) {
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    Ioctl(fd_, VIDIOC_STREAMOFF, &type);
    streaming_ = false;
  }
  for (const Mapping& m : buffers_) ::munmap(m.start, m.length);
  if (!buffers_.empty() && fd_ >= 0) {
    v4l2_requestbuffers release{};
    release.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    release.memory = V4L2_MEMORY_MMAP;
    Ioctl(fd_, VIDIOC_REQBUFS, &release);
  }
  buffers_.clear();
  fd_ = -1;
}

}  // namespace selfcal::capture::internal
