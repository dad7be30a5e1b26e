// How far each joint moves over a set of poses: a joint that barely moves leaves the offsets of the links
// beside it hard to tell apart (the kinematic bundle adjustment holds what the data cannot determine, and
// `identifiability` warns of it from the poses alone).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "kinematics/robot_model.h"

namespace selfcal {

inline constexpr double kBarelyMovingRad = 0.0349065850398866;  // 2 deg

struct BarelyMovingJoint {
  int joint = 0;          // 1-based
  double range_rad = 0;   // max - min of its angle over the poses
};

// The joints whose angle varies by less than `threshold_rad` over `joints` (one vector per pose, all of one
// size); none for an empty list.
std::vector<BarelyMovingJoint> BarelyMovingJoints(const std::vector<Eigen::VectorXd>& joints,
                                                  double threshold_rad = kBarelyMovingRad);

// The one sentence every command says of it: "joint 3 barely moves (0.5 deg over `poses`): the parameters
// beside it are hard to tell apart" (degrees to one decimal).
std::string BarelyMovesSentence(const BarelyMovingJoint& joint, const std::string& poses);

// How each joint's reading moves the camera against the unknown points (PointsFromCam) at joints `q`:
// column k is the small motion e = (v, omega) of the camera in its own frame (p_cam -> p_cam + omega x p_cam
// + v; m and rad) per unit (rad) of joint k, by central differences. A reading's error dq moves the camera by
// A dq: the shape of a joint set's per-image pose error (bundle/error_model.h).
Eigen::Matrix<double, 6, Eigen::Dynamic> CameraMotionPerJoint(const RobotModel& robot, const Eigen::VectorXd& rho,
                                                              const Eigen::VectorXd& q);

}  // namespace selfcal
