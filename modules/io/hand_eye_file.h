// The result of a hand-eye calibration on recorded flange poses (a flange-pose observations set,
// docs/observations-format.md): the camera in the flange frame (eye-in-hand) or in the robot base frame
// (eye-to-hand), f_x, and their standard deviations.
//
//   format: selfcal-hand-eye
//   version: 1
//   flange_from_cam: {xyz_mm: [...], rpy_deg: [...]}            # for people (rpy as in transform_yaml.h)
//   flange_from_cam_exact: {xyz_m: [...], rotation: [[...], [...], [...]]}   # loads back bit-identical
//   flange_from_cam_quat_xyzw: [x, y, z, w]                       # the same rotation as ROS writes it
//   flange_from_cam_stddev: {xyz_mm: [...], rotvec_deg: [...]}    # of the correction in the camera frame
//   fx_px: 607.2
//   fx_stddev_px: 0.4
//   camera: {width_px: 640, height_px: 480, fx_px: 607.2, mu: 1, cx_px: ..., cy_px: ..., k1: ...}
//   intrinsics_stddev: {fx_px: 0.4, k1: 0.002}                   # of the estimated intrinsics
//
// Eye-to-hand (version 1.1): `configuration: eye_to_hand`, and base_from_cam, base_from_cam_exact,
// base_from_cam_quat_xyzw, base_from_cam_stddev instead of the flange_from_cam keys.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "camera/camera.h"
#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"

namespace selfcal::io {

inline constexpr const char* kHandEyeFormat = "selfcal-hand-eye";

struct HandEyeResult {
  CameraMount mount = CameraMount::kEyeInHand;
  Rigid3 flange_from_cam;  // eye-in-hand: the camera on the flange
  Rigid3 base_from_cam;    // eye-to-hand: the fixed camera in the robot base frame
  // Of the camera transform (flange_from_cam or base_from_cam) * Exp(correction): translation (m) and
  // rotation vector (rad), camera frame; NaN where unavailable.
  Eigen::Matrix<double, 6, 1> stddev = Eigen::Matrix<double, 6, 1>::Constant(NAN);
  double fx_px = 0;
  double fx_stddev_px = NAN;
  // The calibrated camera (every intrinsic) and the standard deviations of the estimated intrinsics (NaN:
  // held or unknown); optional.
  std::optional<CameraIntrinsics> camera;
  IntrinsicsVector intrinsics_stddev = {NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN};
  std::string source;
  std::vector<std::pair<std::string, std::string>> provenance;
};

// Writes the result atomically; refuses non-finite values.
Status SaveHandEye(const HandEyeResult& result, const std::string& path);

// Reads a file written by SaveHandEye (the exact transform; the rounded one must agree to 1e-6).
Result<HandEyeResult> LoadHandEye(const std::string& path);

}  // namespace selfcal::io
