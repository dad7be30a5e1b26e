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

}  // namespace selfcal::io
