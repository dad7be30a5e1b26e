// Helpers shared by the robot module's tests: a small three-joint arm for the simulated robot.
#pragma once

#include <Eigen/Core>

#include "robot/simulated_robot.h"

namespace selfcal::robot::testing {

// Three joints in [-2, 2] rad with velocity limits 1, 2 and 0.5 rad/s, starting at zero.
inline SimulatedRobotOptions ThreeJointOptions() {
  SimulatedRobotOptions options;
  options.limits.lower_rad = Eigen::Vector3d::Constant(-2);
  options.limits.upper_rad = Eigen::Vector3d::Constant(2);
  options.limits.max_velocity_rad_s = Eigen::Vector3d(1.0, 2.0, 0.5);
  options.initial_joints_rad = Eigen::Vector3d::Zero();
  return options;
}

}  // namespace selfcal::robot::testing
