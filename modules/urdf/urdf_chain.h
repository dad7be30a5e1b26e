// The chain of a URDF between two links at q = 0, in the base link's frame (internal to the module).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"
#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"
#include "urdf/urdf_robot.h"

namespace urdf {
class ModelInterface;
class Joint;
class Pose;
}

namespace selfcal::urdf {

// One movable joint: its axis as a line in the base frame at q = 0 (unit direction, a point on it).
struct AxisLine {
  std::string name;
  Eigen::Vector3d point;
  Eigen::Vector3d direction;
  JointLimits limits;
};

struct UrdfChain {
  std::string robot_name;
  std::vector<AxisLine> axes;             // base to tip
  Rigid3 base_from_tip;                   // at q = 0
  std::optional<Rigid3> tip_from_camera;  // when a camera link was named
};

// A urdfdom pose (a joint's origin) as a Rigid3.
Rigid3 RigidOf(const ::urdf::Pose& pose);

// The joints from link `top` down to link `bottom` (top first); empty with *error set when bottom is not below top.
std::vector<std::shared_ptr<const ::urdf::Joint>> JointsBetween(const ::urdf::ModelInterface& model,
                                                                const std::string& top, const std::string& bottom,
                                                                std::string* error);

// The chain base_link -> tip_link (and tip_link -> camera_link) of `model`; `name` is the file in messages.
Result<UrdfChain> ExtractChain(const ::urdf::ModelInterface& model, const std::string& name, const UrdfChainSpec& spec);

// The modified-DH + Hayati model whose forward kinematics is the chain's (exact up to rounding).
RobotModel ModelFromAxes(const UrdfChain& chain, const Rigid3& flange_from_cam);

}  // namespace selfcal::urdf
