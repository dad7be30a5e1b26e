// The chain of Universal Robots' ur_description built from a kinematics parameters file the way its xacro
// builds it (urdf/ur_macro.xacro): per joint <origin xyz="x y z" rpy="roll pitch yaw"/> (URDF's rpy,
// R = Rz(yaw) Ry(pitch) Rx(roll)), then a turn about z by the joint value; base_link_inertia -> wrist_3_link.
// Read with yaml-cpp: the reader of the tests of io/ur_kinematics_file.h, not selfcal's own.
#pragma once

#include <yaml-cpp/yaml.h>

#include "geometry/rigid3.h"

namespace selfcal::testing {

inline Rigid3 UrDescriptionChain(const YAML::Node& kinematics, const Eigen::VectorXd& q) {
  Rigid3 chain;
  int i = 0;
  for (const char* joint : {"shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3"}) {
    const YAML::Node j = kinematics[joint];
    const Eigen::Matrix3d r = RotZ(j["yaw"].as<double>()) * RotY(j["pitch"].as<double>()) * RotX(j["roll"].as<double>());
    chain = chain * Rigid3(r, Eigen::Vector3d(j["x"].as<double>(), j["y"].as<double>(), j["z"].as<double>())) *
            Rigid3::FromRotation(RotZ(q[i++]));
  }
  return chain;
}

}  // namespace selfcal::testing
