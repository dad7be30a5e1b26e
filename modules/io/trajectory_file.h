// Trajectory files: the joint configurations of a measurement plan (docs/trajectory-format.md).
//
//   format: selfcal-trajectory
//   version: 1
//   robot: puma560              # optional, informational
//   description: "..."          # optional
//   planner: "..."              # optional, provenance of a planned trajectory
//   num_identification_poses: 15   # optional: the first 15 poses identify, the rest verify
//   planned_for: {...}          # optional: the camera, scene and constraints the plan was made for
//   poses_deg:                  # one row of joint angles per pose (or poses_rad)
//     - [0, -30, 120, 0, 45, 0]
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "kinematics/robot_model.h"
#include "planning/plan_check.h"

namespace selfcal::io {

inline constexpr const char* kTrajectoryFormat = "selfcal-trajectory";
inline constexpr int kTrajectoryVersion = 1;

// The most poses a trajectory file may hold (50 times the largest shipped plan's 105): more is refused naming
// the file, the line of the list, the count and this limit. A plan of 42,000 poses (the mutation campaign's one
// line repeated to 8 MiB) made `plan --check` grow to 22 GB.
inline constexpr int kMaxTrajectoryPoses = 5000;

// A trajectory or measurement plan: a plan is a trajectory with num_identification_poses (the first poses
// identify, the rest verify) and the planner's provenance (docs/trajectory-format.md).
struct TrajectoryFile {
  std::vector<Eigen::VectorXd> poses;  // rad
  std::string robot, description;
  int num_identification_poses = 0;    // 0: not given
  std::string planner;                 // free text: criterion, options, figures
  // The camera, scene and constraints the plan was planned and checked with (`selfcal plan` writes it);
  // `plan --check` and `run` check the plan's geometry against it. Absent: robot-level checks only.
  std::optional<planning::PlannedFor> planned_for;
};

// The plan as the one check takes it (planning::CheckPlanFor).
planning::PlanSubject PlanSubjectOf(const TrajectoryFile& file);

// The whole file, with the same checks as LoadTrajectory; num_identification_poses must not exceed the pose
// count.
Result<TrajectoryFile> LoadTrajectoryFile(const std::string& path, int num_joints);
Result<TrajectoryFile> LoadTrajectoryFile(const std::string& path, const RobotModel& robot);
// The trajectory file at `path` for `robot`, whose config was read from `robot_path` (for the message):
// as LoadTrajectoryFile(path, robot.num_joints()), but a file whose `robot:` names another robot is
// refused before its poses are read, naming both robots and both files (every command that takes a robot
// and a trajectory: a plan made for another arm is a usage error, whatever its joint count).
// ErrorCode::kInvalidInput.
Result<TrajectoryFile> LoadTrajectoryFileForRobot(const std::string& path, const RobotModel& robot,
                                                  const std::string& robot_path);
// The shipped trajectory of a robot: "config/trajectories/initial_<robot_name>.yaml" (relative to the
// source tree's root; docs/robots.md).
std::string InitialTrajectoryPath(const std::string& robot_name);
// Writes atomically (the optional keys only when set).
Status SaveTrajectoryFile(const TrajectoryFile& file, const std::string& path);

// Joint angles in radians, one vector per pose. The whole file is refused (C5) if any pose has a joint
// count other than `num_joints` (every such pose is named by index and line) or a non-finite value or
// one outside [-720, 720] deg. ErrorCode::kInvalidInput.
Result<std::vector<Eigen::VectorXd>> LoadTrajectory(const std::string& path, int num_joints);
// The same, also refusing poses outside the robot's joint limits (C6).
Result<std::vector<Eigen::VectorXd>> LoadTrajectory(const std::string& path, const RobotModel& robot);

// Writes the poses atomically as poses_rad (exact round trip), each with a comment in degrees.
Status SaveTrajectory(const std::vector<Eigen::VectorXd>& poses_rad, const std::string& path,
                      const std::string& robot_name, const std::string& description);

}  // namespace selfcal::io
