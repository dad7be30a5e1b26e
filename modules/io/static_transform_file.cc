#include "io/static_transform_file.h"

#include <sstream>

#include <Eigen/Geometry>

#include "io/atomic_file.h"
#include "io/yaml_writer.h"

namespace selfcal::io {

std::string StaticTransformYaml(const StaticTransform& transform) {
  Eigen::Quaterniond q(transform.parent_from_child.rotation);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // the same rotation; w >= 0 by convention
  const Eigen::Vector3d& t = transform.parent_from_child.translation;
  const std::string x = YamlNumber(t.x() + 0.0), y = YamlNumber(t.y() + 0.0), z = YamlNumber(t.z() + 0.0);
  const std::string qx = YamlNumber(q.x() + 0.0), qy = YamlNumber(q.y() + 0.0), qz = YamlNumber(q.z() + 0.0),
                    qw = YamlNumber(q.w() + 0.0);
  std::ostringstream out;
  out << "# The calibrated flange-to-camera transform as a geometry_msgs/TransformStamped (selfcal,\n"
      << "# docs/ros-static-transform.md): translation in m, rotation a unit quaternion (x, y, z, w) of\n"
      << "# parent_from_child. The same transform on the command line:\n"
      << "#   ros2 run tf2_ros static_transform_publisher --x " << x << " --y " << y << " --z " << z << " --qx " << qx
      << " --qy " << qy << " --qz " << qz << " --qw " << qw << " --frame-id " << transform.parent_frame
      << " --child-frame-id " << transform.child_frame << "\n"
      << "header:\n"
      << "  frame_id: " << YamlQuoted(transform.parent_frame) << "\n"
      << "child_frame_id: " << YamlQuoted(transform.child_frame) << "\n"
      << "transform:\n"
      << "  translation: {x: " << x << ", y: " << y << ", z: " << z << "}\n"
      << "  rotation: {x: " << qx << ", y: " << qy << ", z: " << qz << ", w: " << qw << "}\n";
  return out.str();
}

Status SaveStaticTransform(const StaticTransform& transform, const std::string& path) {
  return WriteFileAtomically(path, StaticTransformYaml(transform));
}

}  // namespace selfcal::io
