// Per-image robot poses in JSON files whose keys the user names (`selfcal detect --pose-joints-key ...`,
// docs/detect.md): what recorders write beside each image, e.g. the kvasios Franka recorder's
//
//   {"joint_pose": [-0.22, -0.19, ...],           # 7 joint angles, rad
//    "O_T_EE": [r00, r01, r02, tx, r10, ..., 0, 0, 0, 1], ...}   # libfranka's TCP pose, 16 numbers, m
//
// The pose is one of: joint angles (`joints`), a 4x4 homogeneous transform (`matrix`: 16 numbers, row- or
// column-major as named, or 4 rows of 4), or a position and a unit quaternion (`position`, `quaternion`).
// A transform's rotation is taken as controllers write it (io/transform_yaml.h, kRecordedRotationTolerance:
// made a rotation, the correction kept). Every problem names the file, the line and the key.
#pragma once

#include <string>

#include "base/status.h"
#include "kinematics/robot_model.h"

namespace selfcal::io {

struct ImagePose;  // io/pose_files.h

struct JsonPoseKeys {
  std::string joints;           // joint angles, one per joint of the robot
  bool joints_deg = false;      // in degrees (default radians)
  std::string matrix;           // a 4x4 homogeneous transform, metres
  bool column_major = false;    // 16 numbers column by column (Eigen, libfranka's std::array in C++)
  std::string position;         // 3 numbers, metres
  std::string quaternion;       // 4 numbers, norm 1 to 1e-3 (then normalised)
  bool quaternion_wxyz = false;  // w first (default x, y, z, w as ROS and Eigen's coeffs())

  bool empty() const { return joints.empty() && matrix.empty() && position.empty() && quaternion.empty(); }
  // Exactly one pose: `joints`, `matrix`, or `position` with `quaternion`; ErrorCode::kInvalidInput naming
  // the command line's options otherwise.
  Status Validate() const;
};

// The pose of one JSON file: joints (checked against `robot`, which they need) or the recorded transform as
// base_from_flange (the caller turns a tool's pose into the flange's), with its rotation correction.
// *out's key and source are the file's (ImageKey, the path).
Status LoadJsonPoseFile(const std::string& path, const JsonPoseKeys& keys, const RobotModel* robot, ImagePose* out);

}  // namespace selfcal::io
