// Target poses for `selfcal compensate` (docs/compensation.md):
//
//   format: selfcal-targets
//   version: 1
//   robot: puma560          # optional; checked against the model when given
//   frame: camera           # camera | flange: which frame the poses place
//   targets:                # poses in the robot's base frame; seed optional (joint angles to start from)
//     - {pose: {xyz_mm: [600, -150, 300], rpy_deg: [180, 0, 90]}, seed_deg: [0, 30, -60, 0, 45, 0]}
//
// `pose` takes every transform form of io/transform_yaml.h (rpy, rotation matrix, quat_xyzw, rotvec).
// Every problem is reported together, naming the line.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "geometry/rigid3.h"

namespace selfcal::io {

inline constexpr const char* kTargetsFormat = "selfcal-targets";
inline constexpr int kTargetsVersion = 1;

struct PoseTarget {
  Rigid3 base_from_target;
  std::optional<Eigen::VectorXd> seed;  // rad
};

struct TargetsFile {
  std::string robot;
  int robot_line = 0;  // of `robot` in the file read (0: not read from a file)
  bool camera_frame = true;  // false: flange
  std::vector<PoseTarget> targets;
};

// `num_joints`: the seeds' length. ErrorCode::kInvalidInput naming file, line and key.
Result<TargetsFile> LoadTargetsFile(const std::string& path, int num_joints);

// Written exactly (SI, rotation matrices, seeds in rad): LoadTargetsFile gives back the same bits.
Status SaveTargetsFile(const TargetsFile& file, const std::string& path);

}  // namespace selfcal::io
