// The OpenCV and ViSP code of camera files (io/camera_formats.h): compiled into selfcal_io_camera_formats
// (linked) and into libselfcal_camera_formats.so (loaded by dlopen). Uses nothing of selfcal but the
// header's plain types, so that the shared object needs no selfcal library.
#include <iostream>

#include <opencv2/core.hpp>
#include <visp3/core/vpXmlParserCamera.h>

#include "io/camera_formats.h"

namespace selfcal::io::internal {
namespace {

FileStorageScalar ScalarOf(const cv::FileNode& node) {
  FileStorageScalar s;
  s.present = !node.empty() && !node.isNone();
  s.is_int = s.present && node.isInt();
  if (s.is_int) s.value = static_cast<int>(node);
  return s;
}

FileStorageMatrix MatrixOf(const cv::FileNode& node) {
  FileStorageMatrix m;
  m.present = !node.empty() && !node.isNone();
  if (!m.present) return m;
  // rows, cols and data checked before cv::FileStorage allocates rows x cols: a mistyped `cols` (or a
  // repeated key) can make it ask for tens of gigabytes. The intrinsics' matrices have at most 16 entries.
  const auto small_int = [](const cv::FileNode& n) { return n.isInt() && int(n) >= 1 && int(n) <= 16; };
  m.header_ok = node.isMap() && small_int(node["rows"]) && small_int(node["cols"]) && node["data"].isSeq() &&
                node["data"].size() == static_cast<size_t>(int(node["rows"]) * int(node["cols"]));
  if (!m.header_ok) return m;
  cv::Mat read;
  try {
    node >> read;
  } catch (const std::exception&) {  // cv::Exception, or a std::exception of FileStorage
    read = cv::Mat();
  }
  m.read_ok = !read.empty() && read.channels() == 1;
  if (!m.read_ok) return m;
  cv::Mat values;
  read.convertTo(values, CV_64F);
  m.rows = values.rows;
  m.cols = values.cols;
  for (int r = 0; r < values.rows; ++r) {
    for (int c = 0; c < values.cols; ++c) m.data.push_back(values.at<double>(r, c));
  }
  return m;
}

FileStorageCamera ReadOpenCv(const std::string& contents) {
  FileStorageCamera out;
  cv::FileStorage fs;
  try {
    if (!fs.open(contents, cv::FileStorage::READ | cv::FileStorage::MEMORY)) return out;
  } catch (const std::exception& e) {  // cv::Exception, or e.g. std::length_error from FileStorage::open
    out.open = FileStorageCamera::Open::kThrew;
    out.what = e.what();
    return out;
  }
  out.open = FileStorageCamera::Open::kOpened;
  const cv::FileNode root = fs.root();
  out.root_is_map = root.isMap();
  if (!out.root_is_map) return out;
  out.keys = root.keys();
  out.image_width = ScalarOf(root["image_width"]);
  out.image_height = ScalarOf(root["image_height"]);
  out.fisheye_model = ScalarOf(root["fisheye_model"]);
  out.camera_matrix = MatrixOf(root["camera_matrix"]);
  out.distortion_coefficients = MatrixOf(root["distortion_coefficients"]);
  return out;
}

bool FormatOpenCv(const OpenCvCameraValues& values, std::string* text, std::string* error) {
  try {
    cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    fs.writeComment(values.comment);
    fs << "image_width" << values.width_px << "image_height" << values.height_px;
    const cv::Mat k = cv::Mat(3, 3, CV_64F, const_cast<double*>(values.camera_matrix)).clone();
    const cv::Mat d = cv::Mat(5, 1, CV_64F, const_cast<double*>(values.distortion_coefficients)).clone();
    fs << "camera_matrix" << k << "distortion_coefficients" << d;
    *text = fs.releaseAndGetString();
  } catch (const std::exception& e) {
    *error = e.what();
    return false;
  }
  return true;
}

// Silences std::cout while ViSP's parser talks ("Found camera with name ...").
class QuietCout {
 public:
  QuietCout() : saved_(std::cout.rdbuf(nullptr)) {}
  ~QuietCout() { std::cout.rdbuf(saved_); }

 private:
  std::streambuf* saved_;
};

bool SaveVisp(const VispCameraValues& values, const std::string& path) {
  vpCameraParameters cam;
  if (values.with_distortion) {
    cam.initPersProjWithDistortion(values.px, values.py, values.u0, values.v0, values.kud, values.kdu);
  } else {
    cam.initPersProjWithoutDistortion(values.px, values.py, values.u0, values.v0);
  }
  try {
    QuietCout quiet;
    vpXmlParserCamera parser;
    return parser.save(cam, path, values.name, values.width_px, values.height_px) == vpXmlParserCamera::SEQUENCE_OK;
  } catch (const std::exception&) {
    return false;
  }
}

constexpr CameraFormatBackend kBackend = {kCameraFormatBackendVersion, ReadOpenCv, FormatOpenCv, SaveVisp};

}  // namespace
}  // namespace selfcal::io::internal

extern "C" const selfcal::io::internal::CameraFormatBackend* selfcal_camera_format_backend() {
  return &selfcal::io::internal::kBackend;
}
