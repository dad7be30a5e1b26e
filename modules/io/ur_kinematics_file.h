// A calibrated Universal Robots arm as the kinematics parameters file of Universal Robots' ROS 2
// description (ur_description's config/<ur_type>/default_kinematics.yaml, given to its launch files as
// `kinematics_params_file`; docs/calibrated-model-format.md):
//
//   kinematics:
//     shoulder:  {x: ..., y: ..., z: ..., roll: ..., pitch: ..., yaw: ...}   # m, rad
//     upper_arm: {...}
//     forearm:   {...}
//     wrist_1:   {...}
//     wrist_2:   {...}
//     wrist_3:   {...}
//     hash: calib_<number>
//
// ur_description's xacro makes each entry the <origin xyz="x y z" rpy="roll pitch yaw"/> of one revolute
// joint about its child's z axis (shoulder_pan_joint ... wrist_3_joint), URDF's rpy (R = Rz(yaw) Ry(pitch)
// Rx(roll)), the chain starting at base_link_inertia (the controller's Base frame, which is the model's
// base for config/robots/ur5e.yaml) and ending at wrist_3_link, the tool flange (tool0 has the same pose):
//
//   base_from_wrist_3(q) = prod_i Origin_i * RotZ(q_i)
//
// The model's links RotX(alpha) TransX(a) RotY(beta) RotZ(q + theta) TransZ(d) are that form exactly, as
// RotZ(q) commutes with TransZ(d): Origin_i = RotX(alpha_i) TransX(a_i) RotY(beta_i) RotZ(theta_i)
// TransZ(d_i) (ur_calibration's grouping of a DH table: a and alpha of the row before, theta and d of the
// joint's own), base_from_link0 folded into Origin_1, and link_n_from_flange, which must turn about and
// slide along z only (it then commutes with RotZ(q_6)), folded into Origin_6. So the file holds the calibrated model, tilts of parallel axes included, to
// rounding; a model whose flange is off the last axis cannot be held, and is refused with the reason.
//
// `hash`: Universal Robots' driver writes "calib_" and std::hash of the controller's DH values (its
// calibration checksum) and, at start-up, compares it with the hash the controller reports. This file is
// selfcal's calibration, not the controller's: it carries "calib_" and std::hash of its own values as
// written, so the driver's check says the kinematics do not match the controller's (which is true).
#pragma once

#include <string>

#include "base/status.h"
#include "kinematics/robot_model.h"

namespace selfcal::io {

// True for a model named like a Universal Robots arm (ur3, ur5e, ur10e, ur16e, ur20, ur30, ...; case
// ignored) with 6 joints.
bool IsUniversalRobotsArm(const RobotModel& model);

// The file's text, or kInvalidInput with why the model cannot be held (not 6 joints; the flange off the
// last joint's axis).
Result<std::string> UrKinematicsYaml(const RobotModel& model);

// UrKinematicsYaml written atomically to `path`.
Status SaveUrKinematics(const RobotModel& model, const std::string& path);

}  // namespace selfcal::io
