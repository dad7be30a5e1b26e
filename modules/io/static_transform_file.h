// The flange-to-camera transform as a ROS static transform file (docs/ros-static-transform.md): the YAML
// of a geometry_msgs/TransformStamped, the layout `ros2 topic echo /tf_static` prints and easy_handeye2
// stores its result in, which ROS tools load into a message (rosidl_runtime_py's set_message_fields on
// yaml.safe_load) or read key by key:
//
//   header:
//     frame_id: tool0                       # parent: the flange
//   child_frame_id: camera_optical_frame    # child: the camera's optical frame (z forward, x right, y down)
//   transform:
//     translation: {x: 0.04, y: 0.0, z: 0.06}           # m, the child's origin in the parent frame
//     rotation: {x: 0.0, y: 0.0, z: 0.7071, w: 0.7071}  # unit quaternion, parent_from_child, w >= 0
//
// with the equivalent `ros2 run tf2_ros static_transform_publisher` command line as a comment. Numbers
// are shortest round-trip decimals, so the transform reads back to rounding.
//
// The same transform as a ROS 2 launch file (camera_static_transform.launch.py): one launch_ros `Node` of
// tf2_ros' static_transform_publisher with the named arguments (--x --y --z --qx --qy --qz --qw --frame-id
// --child-frame-id) of ROS 2 Humble and later; the same numbers, as strings, in the same convention.
#pragma once

#include <string>

#include "base/status.h"
#include "geometry/rigid3.h"

namespace selfcal::io {

struct StaticTransform {
  std::string parent_frame;
  std::string child_frame;
  Rigid3 parent_from_child;
};

std::string StaticTransformYaml(const StaticTransform& transform);

// StaticTransformYaml written atomically to `path`.
Status SaveStaticTransform(const StaticTransform& transform, const std::string& path);

// The ROS 2 launch file (Python) that publishes `transform` with static_transform_publisher.
std::string StaticTransformLaunchPy(const StaticTransform& transform);

// StaticTransformLaunchPy written atomically to `path`.
Status SaveStaticTransformLaunch(const StaticTransform& transform, const std::string& path);

}  // namespace selfcal::io
