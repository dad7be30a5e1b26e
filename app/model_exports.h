// The calibrated model's exports beside calibrated_model.yaml (calibrate, simulate, identify-tracker):
// calibrated.urdf (docs/urdf.md), the DH table in the convention the robot was entered in
// (calibrated_robot.yaml, docs/calibrated-model-format.md) and the camera's static transform (flange-to-camera,
// or base-to-camera in eye-to-hand)
// (camera_static_transform.yaml and camera_static_transform.launch.py, docs/ros-static-transform.md). Each said on stdout and named in --json.
#pragma once

#include <string>

#include "base/status.h"
#include "io/robot_origin.h"
#include "kinematics/robot_model.h"

namespace selfcal::app {

// The robot's origin for the exports: of `robot_config` when given, else of the input (a session's recorded
// robot.yaml or an observations file's robot). Unknown (generic names, no DH table) when unreadable.
io::RobotOrigin OriginOfInput(const std::string& robot_config, const std::string& input, bool is_session);

// calibrated.urdf (the URDF's names when `origin` is a URDF) and calibrated_robot.yaml (the DH table in
// origin's convention) of `calibrated` (a joint-angle robot) in `out_dir`, then the static transform below;
// a model the entered DH convention cannot hold gets no calibrated_robot.yaml and the reasons on stdout and
// in --json's `dh_table`. `source` goes into calibrated_robot.yaml.
Status WriteModelExports(const RobotModel& calibrated, const io::RobotOrigin& origin, const std::string& source,
                         const std::string& out_dir);

// camera_static_transform.yaml in `out_dir`: the camera link (child) in its parent, `parent_from_cam`: eye-in-hand
// flange_from_cam from the tip link, eye-to-hand base_from_cam from the base link; the links named from the
// URDF the robot came from, else tool0 (base_link) and camera_optical_frame; and the same transform as the
// ROS 2 launch file camera_static_transform.launch.py.
Status WriteCameraStaticTransform(CameraMount mount, const Rigid3& parent_from_cam, const io::RobotOrigin& origin,
                                  const std::string& out_dir);

}  // namespace selfcal::app
