// The OpenCV and ViSP side of camera files (io/camera_file.h), behind a table of plain functions on
// standard types, so that a program can load OpenCV and ViSP only when it meets such a file.
//
// camera_file.cc holds every check and every message; the backend only runs the other tools' code:
// cv::FileStorage reads a text into the nodes the checks look at, cv::FileStorage writes the OpenCV text,
// vpXmlParserCamera writes the ViSP XML. `CameraFormats()` gives the backend, one of two ways, chosen by
// the program that links selfcal::io (modules/io/CMakeLists.txt):
// - linked (every program by default): the backend compiled in, OpenCV core and ViSP core linked;
// - loaded (`selfcal`, whose commands must start fast): `libselfcal_camera_formats.so` from the
//   program's private library directory (base/install_layout.h: <prefix>/lib/selfcal installed, beside
//   the executable in a build tree), opened with dlopen on the first camera file that needs it (about 20 ms of CPU and 20
//   shared libraries that a calibration without such a file never loads).
#pragma once

#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal::io::internal {

// A scalar entry of a FileStorage document: `present` unless the key is missing or null.
struct FileStorageScalar {
  bool present = false;
  bool is_int = false;
  int value = 0;
};

// An opencv-matrix entry, read only when its rows, cols and data are small and consistent (`header_ok`:
// FileStorage allocates rows x cols before it reads data); `read_ok` when it read a non-empty
// single-channel matrix, then `data` holds its rows x cols entries row by row, as double.
struct FileStorageMatrix {
  bool present = false;
  bool header_ok = false;
  bool read_ok = false;
  int rows = 0, cols = 0;
  std::vector<double> data;
};

// What cv::FileStorage read of a camera file's text.
struct FileStorageCamera {
  enum class Open { kOpened, kRefused, kThrew };
  Open open = Open::kRefused;  // kRefused: open() returned false; kThrew: it threw `what`
  std::string what;
  bool root_is_map = false;
  std::vector<std::string> keys;  // the top-level keys, in the document's order
  FileStorageScalar image_width, image_height, fisheye_model;
  FileStorageMatrix camera_matrix, distortion_coefficients;
};

// The intrinsics in the two tools' own terms.
struct OpenCvCameraValues {
  int width_px = 0, height_px = 0;
  double camera_matrix[9] = {};           // row by row
  double distortion_coefficients[5] = {};  // k1, k2, p1, p2, k3
  std::string comment;
};
struct VispCameraValues {
  std::string name;
  unsigned width_px = 0, height_px = 0;
  double px = 0, py = 0, u0 = 0, v0 = 0;
  bool with_distortion = false;
  double kud = 0, kdu = 0;
};

// The backend's table. Every function catches what the other tool throws and says so in its result.
struct CameraFormatBackend {
  int version;  // kCameraFormatBackendVersion
  FileStorageCamera (*read_opencv)(const std::string& contents);
  // The YAML text, or false with `error` set.
  bool (*format_opencv)(const OpenCvCameraValues& values, std::string* text, std::string* error);
  // Writes a fresh XML file at `path` (vpXmlParserCamera adds to an existing one: `path` must not exist).
  bool (*save_visp)(const VispCameraValues& values, const std::string& path);
};
inline constexpr int kCameraFormatBackendVersion = 1;

// The backend, or an error naming what could not be loaded (ErrorCode::kInternal).
Result<const CameraFormatBackend*> CameraFormats();

}  // namespace selfcal::io::internal

// The backend's one exported symbol, in the linked library and in libselfcal_camera_formats.so.
extern "C" const selfcal::io::internal::CameraFormatBackend* selfcal_camera_format_backend();
