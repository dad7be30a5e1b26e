// Known robots built in code for unit tests of the numerical core (which never reads files). The
// shipped configs in config/robots/ hold the same numbers; io's tests check that they parse to these.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"

namespace selfcal::testing {

// PUMA 560, standard DH from Corke's Robotics Toolbox (mdl_puma560): a2 = 0.4318, a3 = 0.0203,
// d3 = 0.15005, d4 = 0.4318 m. The camera sits 60 mm along the flange z axis, 40 mm off-axis.
RobotModel Puma560();

// UR5e-class arm, standard DH from Universal Robots' published table: three parallel axes (2, 3, 4).
RobotModel Ur5e();

// gtest predicate: rotation angle and translation distance within tolerances; says which failed.
::testing::AssertionResult RigidNear(const Rigid3& expected, const Rigid3& actual, double rot_tol_rad,
                                     double trans_tol_m);

}  // namespace selfcal::testing
