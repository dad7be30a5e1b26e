#include "io/camera_info_file.h"

#include <sstream>
#include <vector>

#include "io/atomic_file.h"
#include "io/yaml_writer.h"

namespace selfcal::io {
namespace {

// `key:` with rows, cols and data in the block layout camera_calibration_parsers writes itself.
void Matrix(std::ostringstream& out, const char* key, int rows, int cols, const std::vector<double>& data) {
  out << key << ":\n  rows: " << rows << "\n  cols: " << cols << "\n  data: " << YamlNumberList(data) << "\n";
}

}  // namespace

std::string CameraInfoYaml(const CameraIntrinsics& camera, const std::string& camera_name) {
  const double fx = camera.fx_px, fy = camera.fy_px(), cx = camera.cx_px, cy = camera.cy_px;
  std::ostringstream out;
  out << "# The calibrated camera as a ROS camera_info file (camera_calibration_parsers' YAML; selfcal,\n"
      << "# docs/camera-files.md). Pixels: the centre of the top-left pixel is (0, 0), as in ROS and OpenCV.\n"
      << "image_width: " << camera.width_px << "\n"
      << "image_height: " << camera.height_px << "\n"
      << "camera_name: " << YamlQuoted(camera_name) << "\n";
  Matrix(out, "camera_matrix", 3, 3, {fx, 0, cx, 0, fy, cy, 0, 0, 1});
  out << "distortion_model: plumb_bob\n";
  Matrix(out, "distortion_coefficients", 1, 5, {camera.k1, camera.k2, camera.p1, camera.p2, camera.k3});
  Matrix(out, "rectification_matrix", 3, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1});
  Matrix(out, "projection_matrix", 3, 4, {fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0});
  return out.str();
}

Status SaveCameraInfo(const CameraIntrinsics& camera, const std::string& camera_name, const std::string& path) {
  return WriteFileAtomically(path, CameraInfoYaml(camera, camera_name));
}

}  // namespace selfcal::io
