// Internal to capture: V4L2 memory-mapped streaming on a descriptor of our own, for the compressed formats
// vpV4l2Grabber cannot read (MJPEG). VIDIOC_REQBUFS / QUERYBUF + mmap / QBUF / STREAMON, then select +
// VIDIOC_DQBUF per frame, the buffer handed back with VIDIOC_QBUF once its bytes are decoded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal::capture::internal {

struct DequeuedBuffer {
  int index = -1;
  const uint8_t* data = nullptr;
  size_t bytes_used = 0;       // what the driver filled
  double timestamp_s = 0;      // the driver's (CLOCK_MONOTONIC for current drivers)
  bool driver_error = false;   // V4L2_BUF_FLAG_ERROR: the driver says the frame is damaged
};

class MmapStream {
 public:
  MmapStream() = default;
  ~MmapStream() { Stop(); }
  MmapStream(const MmapStream&) = delete;
  MmapStream& operator=(const MmapStream&) = delete;

  // Errors are kDisconnected (ENODEV), kDeviceBusy (EBUSY) or kFormatMismatch, naming `device`.
  Status Start(int fd, int num_buffers, const std::string& device);
  // A frame within timeout_s, or kTimeout (`timed_out` set) or kDisconnected.
  Result<DequeuedBuffer> Dequeue(double timeout_s, bool* timed_out);
  void Requeue(int index);
  void Stop();  // STREAMOFF, unmap, release the buffers; safe to call repeatedly

 private:
  struct Mapping {
    void* start = nullptr;
    size_t length = 0;
  };
  int fd_ = -1;
  std::string device_;
  std::vector<Mapping> buffers_;
  bool streaming_ = false;
};

}  // namespace selfcal::capture::internal
