// A RobotModel (typically the calibrated one) written as a URDF (docs/urdf.md): base_link, one revolute
// joint per model joint whose origin is that joint's calibrated RotX(alpha) TransX(a) RotY(beta)
// RotZ(theta) TransZ(d) (axis z, the model's limits), fixed joints for base_from_link0, link_n_from_flange
// (to `tip_link`) and flange_from_cam (to `camera_link`, the camera's optical frame; in eye-to-hand base_from_cam from
// `base_link`, the camera fixed); effort 0 and velocity
// kDefaultJointVelocityRadPerS in every <limit>. Rotations whose
// roll-pitch-yaw would be near gimbal lock are written through an intermediate link, so that every
// origin is exact to rounding. The text is checked with urdfdom + KDL before it is returned.
#pragma once

#include <string>
#include <vector>

#include "base/status.h"
#include "kinematics/robot_model.h"
#include "urdf/urdf_robot.h"

namespace selfcal::urdf {

// The <limit velocity> (rad/s) of every joint of a written URDF: selfcal does not know the arm's rated
// speeds, and MoveIt's time parameterization refuses a joint whose velocity limit is 0. A conservative
// placeholder (57 deg/s) for MoveIt's joint_limits.yaml to override (docs/urdf.md).
inline constexpr double kDefaultJointVelocityRadPerS = 1.0;

struct UrdfNames {
  std::string robot;                // empty: the model's name
  std::vector<std::string> joints;  // empty: joint1 .. jointN
  std::vector<std::string> links;   // the child link of each joint; empty: link1 .. linkN (the model's frames)
  std::vector<double> velocities_rad_s;  // each joint's <limit velocity>; empty: kDefaultJointVelocityRadPerS
  std::string base_link = "base_link";
  std::string tip_link = "tool0";
  std::string camera_link = "camera_optical_frame";
};

// `<origin xyz="x y z" rpy="roll pitch yaw"/>` of `parent_from_child` (URDF's rpy: R = Rz(yaw) Ry(pitch)
// Rx(roll)), every number to 17 significant digits.
std::string OriginElement(const Rigid3& parent_from_child);

// The URDF text, refused (kInternal) if KDL's forward kinematics of it differs from the model's by more
// than the check's tolerances at its random joints.
Result<std::string> UrdfOfModel(const RobotModel& model, const UrdfNames& names, const FkCheckOptions& check = {});

// UrdfOfModel written atomically to `path`.
Status WriteUrdf(const RobotModel& model, const UrdfNames& names, const std::string& path);

// KDL's forward kinematics of the URDF `text` (chains spec.base_link -> tip_link, and -> camera_link when
// named) against the model's base_from_flange and base_from_cam at seeded random joints within the limits;
// refused (kInvalidInput) naming the worst pose beyond the tolerances.
Result<FkCheck> CompareWithKdl(const std::string& text, const std::string& name, const UrdfChainSpec& spec,
                               const RobotModel& model, const FkCheckOptions& options);

}  // namespace selfcal::urdf
