#include "io/static_transform_file.h"

#include <cstdio>
#include <sstream>

#include <Eigen/Geometry>

#include "io/atomic_file.h"
#include "io/yaml_writer.h"

namespace selfcal::io {
namespace {

// The seven numbers of both files, shortest round-trip decimals: translation (m), then the unit quaternion
// (x, y, z, w) of parent_from_child with w >= 0.
struct TransformNumbers {
  std::string x, y, z, qx, qy, qz, qw;
};

TransformNumbers NumbersOf(const Rigid3& parent_from_child) {
  Eigen::Quaterniond q(parent_from_child.rotation);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // the same rotation; w >= 0 by convention
  const Eigen::Vector3d& t = parent_from_child.translation;
  return {YamlNumber(t.x() + 0.0),  YamlNumber(t.y() + 0.0),  YamlNumber(t.z() + 0.0), YamlNumber(q.x() + 0.0),
          YamlNumber(q.y() + 0.0), YamlNumber(q.z() + 0.0), YamlNumber(q.w() + 0.0)};
}

// `text` as a single-quoted Python string literal: quotes, backslashes and control bytes escaped.
std::string PythonQuoted(const std::string& text) {
  std::string out = "'";
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\'' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u == 0x7f) {
      char buffer[8];
      std::snprintf(buffer, sizeof(buffer), "\\x%02x", u);
      out += buffer;
    } else {
      out += c;
    }
  }
  return out + "'";
}

}  // namespace

std::string StaticTransformYaml(const StaticTransform& transform) {
  const TransformNumbers n = NumbersOf(transform.parent_from_child);
  std::ostringstream out;
  out << "# The calibrated camera transform (parent: the flange, or the base for a fixed camera) as a geometry_msgs/TransformStamped (selfcal,\n"
      << "# docs/ros-static-transform.md): translation in m, rotation a unit quaternion (x, y, z, w) of\n"
      << "# parent_from_child. The same transform on the command line:\n"
      << "#   ros2 run tf2_ros static_transform_publisher --x " << n.x << " --y " << n.y << " --z " << n.z << " --qx "
      << n.qx << " --qy " << n.qy << " --qz " << n.qz << " --qw " << n.qw << " --frame-id " << transform.parent_frame
      << " --child-frame-id " << transform.child_frame << "\n"
      << "header:\n"
      << "  frame_id: " << YamlQuoted(transform.parent_frame) << "\n"
      << "child_frame_id: " << YamlQuoted(transform.child_frame) << "\n"
      << "transform:\n"
      << "  translation: {x: " << n.x << ", y: " << n.y << ", z: " << n.z << "}\n"
      << "  rotation: {x: " << n.qx << ", y: " << n.qy << ", z: " << n.qz << ", w: " << n.qw << "}\n";
  return out.str();
}

Status SaveStaticTransform(const StaticTransform& transform, const std::string& path) {
  return WriteFileAtomically(path, StaticTransformYaml(transform));
}

std::string StaticTransformLaunchPy(const StaticTransform& transform) {
  const TransformNumbers n = NumbersOf(transform.parent_from_child);
  std::ostringstream out;
  out << "# The calibrated camera transform (parent: the flange, or the base for a fixed camera) published by tf2_ros' static_transform_publisher\n"
      << "# (selfcal, docs/ros-static-transform.md): the transform of camera_static_transform.yaml, translation\n"
      << "# in m, rotation the unit quaternion (x, y, z, w) of parent_from_child. Named arguments: ROS 2 Humble\n"
      << "# and later. Start it with `ros2 launch ./camera_static_transform.launch.py`.\n"
      << "from launch import LaunchDescription\n"
      << "from launch_ros.actions import Node\n"
      << "\n"
      << "\n"
      << "def generate_launch_description():\n"
      << "    return LaunchDescription([\n"
      << "        Node(\n"
      << "            package='tf2_ros',\n"
      << "            executable='static_transform_publisher',\n"
      << "            name='selfcal_camera_static_transform',\n"
      << "            arguments=[\n"
      << "                '--x', '" << n.x << "', '--y', '" << n.y << "', '--z', '" << n.z << "',\n"
      << "                '--qx', '" << n.qx << "', '--qy', '" << n.qy << "', '--qz', '" << n.qz << "', '--qw', '" << n.qw
      << "',\n"
      << "                '--frame-id', " << PythonQuoted(transform.parent_frame) << ",\n"
      << "                '--child-frame-id', " << PythonQuoted(transform.child_frame) << ",\n"
      << "            ],\n"
      << "        ),\n"
      << "    ])\n";
  return out.str();
}

Status SaveStaticTransformLaunch(const StaticTransform& transform, const std::string& path) {
  return WriteFileAtomically(path, StaticTransformLaunchPy(transform));
}

}  // namespace selfcal::io
