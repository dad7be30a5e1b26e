#include "io/ur_kinematics_file.h"

#include <array>
#include <cctype>
#include <cmath>
#include <functional>
#include <regex>
#include <sstream>

#include "io/atomic_file.h"
#include "io/transform_yaml.h"
#include "io/yaml_writer.h"

namespace selfcal::io {
namespace {

constexpr std::array<const char*, 6> kUrJoints = {"shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3"};

// A tail within this of turning about and sliding along z commutes with RotZ(q_6) to rounding.
constexpr double kOnAxisTolerance = 1e-12;

}  // namespace

bool IsUniversalRobotsArm(const RobotModel& model) {
  std::string name = model.name;
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  static const std::regex kUrName("ur(3|5|10|15|16|20|30)e?");
  return model.num_joints() == 6 && std::regex_match(name, kUrName);
}

Result<std::string> UrKinematicsYaml(const RobotModel& model) {
  if (model.num_joints() != 6) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "a Universal Robots arm has 6 joints, the model " + std::to_string(model.num_joints()));
  }
  // RotZ(q) commutes with TransZ(d): each link is LinkTransform(alpha, a, beta, theta, d) * RotZ(q).
  std::array<Rigid3, 6> origins;
  for (int i = 0; i < 6; ++i) {
    const LinkParameters& p = model.links[i];
    origins[i] = LinkTransform<double>(p.alpha, p.a, p.beta, p.theta, p.d);
  }
  origins[0] = model.base_from_link0 * origins[0];
  const Rigid3& tail = model.link_n_from_flange;  // after RotZ(q_6)
  const Eigen::Matrix3d& r = tail.rotation;
  if (std::abs(r(2, 2) - 1) > kOnAxisTolerance || std::hypot(tail.translation.x(), tail.translation.y()) > kOnAxisTolerance) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "the flange is not on the last joint's axis (ur_description's wrist_3_link turns about it)");
  }
  origins[5] = origins[5] * tail;
  std::ostringstream out, values;
  out << "# The calibrated arm as ur_description's kinematics parameters (selfcal, docs/calibrated-model-format.md):\n"
      << "# per joint the <origin> of ur_description's xacro, m and rad, URDF roll-pitch-yaw. `hash` is not the\n"
      << "# controller's calibration checksum: the driver will say the robot's own calibration differs.\n"
      << "kinematics:\n";
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d& t = origins[i].translation;
    const Eigen::Vector3d rpy = RpyFromRotation(origins[i].rotation);
    const std::array<double, 6> v = {t.x(), t.y(), t.z(), rpy[0], rpy[1], rpy[2]};
    out << "  " << kUrJoints[i] << ":\n";
    const char* keys[] = {"x", "y", "z", "roll", "pitch", "yaw"};
    for (int k = 0; k < 6; ++k) {
      out << "    " << keys[k] << ": " << YamlNumber(v[k] + 0.0) << "\n";
      values << v[k];  // as the driver streams its DH values: default precision
    }
  }
  out << "  hash: calib_" << std::hash<std::string>{}(values.str()) << "\n";
  return out.str();
}

Status SaveUrKinematics(const RobotModel& model, const std::string& path) {
  Result<std::string> text = UrKinematicsYaml(model);
  if (!text.ok()) return text.status();
  return WriteFileAtomically(path, *text);
}

}  // namespace selfcal::io
