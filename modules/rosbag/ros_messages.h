// The ROS 2 messages `selfcal detect --bag` reads, deserialized from their CDR encoding (the
// "cdr" message encoding of rosbag2: a 4-byte encapsulation header 00 01 00 00, CDR little-endian, then
// the fields in order, each primitive aligned to its own size (at most 8) counted from the end of the
// header; strings as a uint32 length including the terminating NUL, then the bytes and the NUL; sequences
// as a uint32 count, then the elements). Every count and length is checked against the bytes left before
// it is used; a message that is too short, has another encapsulation (big-endian, XCDR2) or a string
// without its NUL is refused with `where` (the file and byte offset of the message record).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <visp3/core/vpImage.h>

#include "base/status.h"

namespace selfcal::rosbag {

struct RosStamp {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  double seconds() const { return sec + 1e-9 * nanosec; }
  bool zero() const { return sec == 0 && nanosec == 0; }
};

// sensor_msgs/msg/JointState.
struct JointStateMessage {
  RosStamp stamp;
  std::string frame_id;
  std::vector<std::string> name;
  std::vector<double> position, velocity, effort;
};
Result<JointStateMessage> DecodeJointState(const std::string& cdr, const std::string& where);

// sensor_msgs/msg/Image, or sensor_msgs/msg/CompressedImage (`format` set, `encoding` empty).
struct ImageMessage {
  RosStamp stamp;
  std::string frame_id;
  std::uint32_t height = 0, width = 0, step = 0;
  std::string encoding;   // Image: mono8, rgb8, bgr8, ...
  std::uint8_t is_bigendian = 0;
  std::string format;     // CompressedImage: "png", "jpeg", "rgb8; jpeg compressed bgr8", ...
  std::string data;
};
Result<ImageMessage> DecodeImage(const std::string& cdr, const std::string& where);
Result<ImageMessage> DecodeCompressedImage(const std::string& cdr, const std::string& where);

// The image as 8-bit grey: mono8 as it is; rgb8, bgr8 (and rgba8, bgra8) through ViSP's colour to grey
// conversion, the one its image reader applies to colour files; a compressed image decoded by OpenCV
// (cv::imdecode) and converted the same way. Other encodings (16-bit depth, Bayer, YUV) are refused by
// name. `max_pixels` bounds width x height.
Result<vpImage<unsigned char>> GreyImage(const ImageMessage& image, const std::string& where,
                                         std::size_t max_pixels = 100'000'000);

}  // namespace selfcal::rosbag
