// Trajectory files: the joint configurations of a measurement plan (docs/trajectory-format.md).
//
//   format: selfcal-trajectory
//   version: 1
//   robot: puma560              # optional, informational
//   description: "..."          # optional
//   poses_deg:                  # one row of joint angles per pose (or poses_rad)
//     - [0, -30, 120, 0, 45, 0]
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "kinematics/robot_model.h"

namespace selfcal::io {

inline constexpr const char* kTrajectoryFormat = "selfcal-trajectory";
inline constexpr int kTrajectoryVersion = 1;

// Joint angles in radians, one vector per pose. The whole file is refused (C5) if any pose has a joint
// count other than `num_joints` (every such pose is named by index and line) or a non-finite value or
// one outside [-720, 720] deg. ExitCode::kUsage.
Result<std::vector<Eigen::VectorXd>> LoadTrajectory(const std::string& path, int num_joints);
// The same, also refusing poses outside the robot's joint limits (C6).
Result<std::vector<Eigen::VectorXd>> LoadTrajectory(const std::string& path, const RobotModel& robot);

// Writes the poses atomically as poses_rad (exact round trip), each with a comment in degrees.
Status SaveTrajectory(const std::vector<Eigen::VectorXd>& poses_rad, const std::string& path,
                      const std::string& robot_name, const std::string& description);

}  // namespace selfcal::io
