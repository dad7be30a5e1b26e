#include "rosbag/ros_messages.h"

#include <cstring>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <visp3/core/vpImageConvert.h>

namespace selfcal::rosbag {

namespace {

constexpr std::size_t kEncapsulation = 4;

// A bounds-checked CDR little-endian reader; the first failure is kept with the field it was reading.
class Cdr {
 public:
  Cdr(const std::string& bytes, std::string where) : bytes_(bytes), where_(std::move(where)) {}

  Status Header() {
    if (bytes_.size() < kEncapsulation) return Fail("header", "fewer than the 4 bytes of the CDR header");
    if (bytes_[0] != 0 || bytes_[1] != 1) {
      char kind[16];
      std::snprintf(kind, sizeof(kind), "%02x %02x", static_cast<unsigned char>(bytes_[0]),
                    static_cast<unsigned char>(bytes_[1]));
      return Fail("header", std::string("encapsulation ") + kind + ", not 00 01 (CDR little-endian, what ROS 2 writes)");
    }
    pos_ = kEncapsulation;
    return Status::Ok();
  }
  template <typename T>
  bool Get(T* value, const char* field) {
    const std::size_t align = sizeof(T) < 8 ? sizeof(T) : 8;
    const std::size_t rel = pos_ - kEncapsulation;
    const std::size_t padded = pos_ + (align - rel % align) % align;
    if (padded > bytes_.size() || bytes_.size() - padded < sizeof(T)) return Short(field);
    std::memcpy(value, bytes_.data() + padded, sizeof(T));  // little-endian host (x86-64, arm64)
    pos_ = padded + sizeof(T);
    return true;
  }
  bool String(std::string* out, const char* field) {
    std::uint32_t n = 0;
    if (!Get(&n, field)) return false;
    if (n == 0) {  // some writers give an empty string no NUL
      out->clear();
      return true;
    }
    if (bytes_.size() - pos_ < n) return Short(field);
    if (bytes_[pos_ + n - 1] != '\0') {
      status_ = Fail(field, "a string without its terminating NUL");
      return false;
    }
    out->assign(bytes_.data() + pos_, n - 1);
    pos_ += n;
    return true;
  }
  // A sequence's count, checked against the bytes left at `element_size` bytes (at least) each.
  bool Count(std::uint32_t* n, std::size_t element_size, const char* field) {
    if (!Get(n, field)) return false;
    if (static_cast<std::uint64_t>(*n) * element_size > bytes_.size() - pos_) return Short(field);
    return true;
  }
  bool Doubles(std::vector<double>* out, const char* field) {
    std::uint32_t n = 0;
    if (!Count(&n, 8, field)) return false;
    out->resize(n);
    for (std::uint32_t k = 0; k < n; ++k) {
      if (!Get(&(*out)[k], field)) return false;
    }
    return true;
  }
  bool Octets(std::string* out, const char* field) {
    std::uint32_t n = 0;
    if (!Count(&n, 1, field)) return false;
    out->assign(bytes_.data() + pos_, n);
    pos_ += n;
    return true;
  }
  bool Stamp(RosStamp* stamp, std::string* frame_id) {
    return Get(&stamp->sec, "header.stamp.sec") && Get(&stamp->nanosec, "header.stamp.nanosec") &&
           String(frame_id, "header.frame_id");
  }
  const Status& status() const { return status_; }

 private:
  Status Fail(const char* field, const std::string& what) const {
    return Status::Error(ErrorCode::kInvalidInput, where_ + ": message field `" + field + "`: " + what);
  }
  bool Short(const char* field) {
    status_ = Fail(field, "the message ends at byte " + std::to_string(bytes_.size()) + " inside it (truncated or not this type)");
    return false;
  }

  const std::string& bytes_;
  std::string where_;
  std::size_t pos_ = 0;
  Status status_ = Status::Ok();
};

}  // namespace

Result<JointStateMessage> DecodeJointState(const std::string& cdr, const std::string& where) {
  Cdr in(cdr, where + " (sensor_msgs/msg/JointState)");
  if (Status s = in.Header(); !s.ok()) return s;
  JointStateMessage m;
  std::uint32_t names = 0;
  bool ok = in.Stamp(&m.stamp, &m.frame_id) && in.Count(&names, 4, "name");
  for (std::uint32_t k = 0; ok && k < names; ++k) {
    m.name.emplace_back();
    ok = in.String(&m.name.back(), "name");
  }
  ok = ok && in.Doubles(&m.position, "position") && in.Doubles(&m.velocity, "velocity") && in.Doubles(&m.effort, "effort");
  if (!ok) return in.status();
  return m;
}

Result<ImageMessage> DecodeImage(const std::string& cdr, const std::string& where) {
  Cdr in(cdr, where + " (sensor_msgs/msg/Image)");
  if (Status s = in.Header(); !s.ok()) return s;
  ImageMessage m;
  const bool ok = in.Stamp(&m.stamp, &m.frame_id) && in.Get(&m.height, "height") && in.Get(&m.width, "width") &&
                  in.String(&m.encoding, "encoding") && in.Get(&m.is_bigendian, "is_bigendian") &&
                  in.Get(&m.step, "step") && in.Octets(&m.data, "data");
  if (!ok) return in.status();
  return m;
}

Result<ImageMessage> DecodeCompressedImage(const std::string& cdr, const std::string& where) {
  Cdr in(cdr, where + " (sensor_msgs/msg/CompressedImage)");
  if (Status s = in.Header(); !s.ok()) return s;
  ImageMessage m;
  if (!(in.Stamp(&m.stamp, &m.frame_id) && in.String(&m.format, "format") && in.Octets(&m.data, "data"))) {
    return in.status();
  }
  return m;
}

namespace {

Status BadImage(const std::string& where, const std::string& what) {
  return Status::Error(ErrorCode::kInvalidInput, where + ": " + what);
}

// Rows of `channels` bytes per pixel (mono8 1, rgb8/bgr8 3, rgba8/bgra8 4) to grey.
Result<vpImage<unsigned char>> RawToGrey(const unsigned char* data, std::size_t step, unsigned width, unsigned height,
                                         const std::string& encoding, const std::string& where) {
  const unsigned channels = encoding == "mono8" ? 1 : (encoding == "rgb8" || encoding == "bgr8") ? 3 : 4;
  std::vector<unsigned char> packed(static_cast<std::size_t>(width) * height * channels);
  for (unsigned r = 0; r < height; ++r) {
    std::memcpy(packed.data() + static_cast<std::size_t>(r) * width * channels, data + r * step,
                static_cast<std::size_t>(width) * channels);
  }
  vpImage<unsigned char> grey(height, width);
  unsigned char* out = grey.bitmap;
  if (encoding == "mono8") {
    std::memcpy(out, packed.data(), packed.size());
  } else if (encoding == "rgb8") {
    vpImageConvert::RGBToGrey(packed.data(), out, width * height);
  } else if (encoding == "bgr8") {
    vpImageConvert::BGRToGrey(packed.data(), out, width, height);
  } else if (encoding == "rgba8") {
    vpImageConvert::RGBaToGrey(packed.data(), out, width * height);
  } else if (encoding == "bgra8") {
    vpImageConvert::BGRaToGrey(packed.data(), out, width, height);
  } else {
    return BadImage(where, "image encoding `" + encoding + "`");
  }
  return grey;
}

}  // namespace

Result<vpImage<unsigned char>> GreyImage(const ImageMessage& image, const std::string& where, std::size_t max_pixels) {
  if (!image.format.empty() || image.encoding.empty()) {
    const cv::Mat bytes(1, static_cast<int>(image.data.size()), CV_8UC1, const_cast<char*>(image.data.data()));
    cv::Mat decoded;
    if (!image.data.empty()) decoded = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
    if (decoded.empty()) return BadImage(where, "compressed image (format `" + image.format + "`) does not decode");
    if (decoded.depth() != CV_8U) {
      return BadImage(where, "compressed image (format `" + image.format + "`) is not 8 bits a channel; selfcal detect reads 8-bit images");
    }
    if (static_cast<std::size_t>(decoded.cols) * decoded.rows > max_pixels) return BadImage(where, "image of too many pixels");
    const int c = decoded.channels();
    const char* encoding = c == 1 ? "mono8" : c == 3 ? "bgr8" : "bgra8";  // OpenCV decodes colour as BGR
    if (c != 1 && c != 3 && c != 4) return BadImage(where, "compressed image of " + std::to_string(c) + " channels");
    if (!decoded.isContinuous()) decoded = decoded.clone();
    return RawToGrey(decoded.data, decoded.step[0], static_cast<unsigned>(decoded.cols),
                     static_cast<unsigned>(decoded.rows), encoding, where);
  }
  const std::string& e = image.encoding;
  if (e != "mono8" && e != "rgb8" && e != "bgr8" && e != "rgba8" && e != "bgra8") {
    return BadImage(where, "image encoding `" + e + "`: selfcal detect reads mono8, rgb8, bgr8, rgba8 and bgra8 (and "
                           "compressed images); record the camera's 8-bit colour or grey stream");
  }
  if (image.width == 0 || image.height == 0 || static_cast<std::size_t>(image.width) * image.height > max_pixels) {
    return BadImage(where, "image of " + std::to_string(image.width) + "x" + std::to_string(image.height) + " pixels");
  }
  const std::size_t channels = e == "mono8" ? 1 : (e == "rgb8" || e == "bgr8") ? 3 : 4;
  if (image.step < image.width * channels || static_cast<std::uint64_t>(image.step) * image.height > image.data.size()) {
    return BadImage(where, "image " + std::to_string(image.width) + "x" + std::to_string(image.height) + " " + e +
                               " with step " + std::to_string(image.step) + " needs more than its " +
                               std::to_string(image.data.size()) + " bytes of data");
  }
  return RawToGrey(reinterpret_cast<const unsigned char*>(image.data.data()), image.step, image.width, image.height, e,
                   where);
}

}  // namespace selfcal::rosbag
