// The calibrated camera as a ROS camera_info YAML (docs/camera-files.md): the format of ROS's
// camera_calibration_parsers (readCalibration / writeCalibration, camera_info_manager's `file://` URLs,
// the `camera_info_url` of ROS camera drivers), which fills a sensor_msgs/CameraInfo:
//
//   image_width: 640
//   image_height: 480
//   camera_name: camera
//   camera_matrix: {rows: 3, cols: 3, data: [fx, 0, cx, 0, fy, cy, 0, 0, 1]}            # K
//   distortion_model: plumb_bob
//   distortion_coefficients: {rows: 1, cols: 5, data: [k1, k2, p1, p2, k3]}             # D
//   rectification_matrix: {rows: 3, cols: 3, data: [1, 0, 0, 0, 1, 0, 0, 0, 1]}        # R (monocular)
//   projection_matrix: {rows: 3, cols: 4, data: [fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0]}  # P = [K | 0]
//
// plumb_bob is OpenCV's radial-tangential model, selfcal's; ROS's pixel convention is OpenCV's (the
// centre of the top-left pixel is (0, 0)), so the numbers are copied unchanged. P = [K | 0]: the
// rectified image of a monocular camera taken with the same intrinsics (image_proc then only removes the
// lens distortion). The OpenCV FileStorage file (camera_file.h) is not this format: it has no
// rectification or projection matrix and its matrices are tagged !!opencv-matrix, and
// camera_calibration_parsers refuses it ("invalid node; first invalid key: rows").
#pragma once

#include <string>

#include "base/status.h"
#include "camera/camera.h"

namespace selfcal::io {

// The YAML text above; `camera_name` quoted.
std::string CameraInfoYaml(const CameraIntrinsics& camera, const std::string& camera_name);

// CameraInfoYaml written atomically to `path`.
Status SaveCameraInfo(const CameraIntrinsics& camera, const std::string& camera_name, const std::string& path);

}  // namespace selfcal::io
