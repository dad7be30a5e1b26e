// The user's own URDF with the calibrated kinematics (docs/urdf.md, "URDF out"): every element, attribute,
// comment and byte of the input kept (link names, visuals, meshes, collisions, inertias, limits,
// velocities, transmissions, ros2_control, gazebo tags), and only the <origin> of these joints changed:
//
//   - each movable joint of the chain base_link -> tip_link, so that its child link sits where the
//     calibrated model puts it: with C_i the joint's child link frame and M_i the model's frame of link i
//     (both attached to link i; X_i = C_i^-1 M_i, constant, from the nominal conversion of the same URDF),
//     base_from_C_i'(q) = base_from_M_i'(q) * X_i^-1. Joint i still turns about its own <axis> through
//     C_i's origin, which X_i maps onto M_i's z axis, so the new origin is
//     origin_i' = base_from_parent_i'(0)^-1 * base_from_M_i'(0) * X_i^-1,
//     the calibrated base correction folded into the first one and the tilts of (nearly) parallel axes
//     (Hayati's beta) into theirs: nothing else is needed;
//   - the fixed joint whose child is camera_link (when named), so that tip_link -> camera_link is the
//     calibrated flange_from_cam.
//
// Fixed joints between them and every link off the chain keep their origins (they move with their
// parents). The result is checked as the generic writer's is: KDL's forward kinematics of the new text
// (base_link -> tip_link, -> camera_link) against the calibrated model at random joints, 1e-9 m / 1e-9 rad.
#pragma once

#include <map>
#include <string>

#include "base/status.h"
#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"
#include "urdf/urdf_robot.h"

namespace selfcal::urdf {

// `text` (the URDF the nominal robot was read from; `name` stands for it in messages, `spec` as in its robot
// config) with the origins above set from `calibrated`, a calibration of that robot. Errors: kInvalidInput
// when the URDF does not convert to a model of calibrated's joints, or the check fails (a URDF changed since,
// an origin near gimbal lock whose roll-pitch-yaw loses the 1e-9).
Result<std::string> CalibratedUserUrdf(const std::string& text, const std::string& name, const UrdfChainSpec& spec,
                                       const RobotModel& calibrated, const FkCheckOptions& check = {});

// CalibratedUserUrdf of the URDF file at `path` (read capped at urdf_parse.h's kMaxUrdfBytes).
Result<std::string> CalibratedUserUrdfFile(const std::string& path, const UrdfChainSpec& spec,
                                           const RobotModel& calibrated);

// `text` with the <origin> of each named <joint> (an element with a `type` attribute, outside comments)
// replaced by `origins` (parent_from_child), or inserted when it has none; nothing else changed. Errors:
// kInvalidInput naming a joint not found.
Result<std::string> ReplaceJointOrigins(const std::string& text, const std::string& name,
                                        const std::map<std::string, Rigid3>& origins);

}  // namespace selfcal::urdf
