#include "kinematics/joint_motion.h"

#include <gtest/gtest.h>

#include "geometry/rigid3.h"
#include "support/test_robots.h"

namespace selfcal {
namespace {

// The kvasios Franka sessions: joint 3 moves 0.5 deg over 12 poses, every other joint tens of degrees.
TEST(BarelyMovingJoints, NamesTheJointsThatMoveLessThanTheThreshold) {
  std::vector<Eigen::VectorXd> poses;
  for (int p = 0; p < 12; ++p) {
    Eigen::VectorXd q(3);
    q << 0.1 * p, -0.0005 + 0.0008 * (p % 2), 0.03 * p;
    poses.push_back(q);
  }
  const std::vector<BarelyMovingJoint> barely = BarelyMovingJoints(poses);
  ASSERT_EQ(barely.size(), 1u);
  EXPECT_EQ(barely[0].joint, 2);
  EXPECT_NEAR(barely[0].range_rad, 0.0008, 1e-15);
  // Joint 3 moves 0.33 rad: above a threshold of 0.3 rad it counts as barely moving too.
  EXPECT_EQ(BarelyMovingJoints(poses, 0.34).size(), 2u);
  EXPECT_TRUE(BarelyMovingJoints({}).empty());
}

// identifiability, plan --check and calibrate say it in the same words and digits.
TEST(JointMotion, OneSentenceForEveryCommand) {
  EXPECT_EQ(BarelyMovesSentence({3, DegToRad(0.5)}, "the identification poses"),
            "joint 3 barely moves (0.5 deg over the identification poses): the parameters beside it are hard to tell "
            "apart");
}

// A small change dq of the readings moves a point in the camera's frame by SmallMotionJacobian(p_cam) A dq, in
// both mounts (eye-to-hand: the points ride on the flange, the camera is fixed); the second-order remainder
// at |dq| ~ 1e-4 rad is ~1e-8 of a metre-sized lever, far below the tolerance.
TEST(JointMotion, CameraMotionPerJointIsTheFirstOrderMotionOfThePoints) {
  RobotModel eye_to_hand = testing::Puma560();
  eye_to_hand.mount = CameraMount::kEyeToHand;
  eye_to_hand.base_from_cam = Rigid3(RotZ(0.3) * RotX(2.8), Eigen::Vector3d(0.9, -0.1, 0.6));
  for (const RobotModel& robot : {testing::Puma560(), eye_to_hand}) {
    const Eigen::VectorXd rho = KinematicParameters::Nominal(robot);
    const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.1, -0.4, 0.5, 0.7, -0.3, 0.2).finished();
    const Eigen::VectorXd dq = (Eigen::VectorXd(6) << 1e-4, -2e-4, 1.5e-4, -1e-4, 2e-4, 1e-4).finished();
    const Eigen::Matrix<double, 6, Eigen::Dynamic> a = CameraMotionPerJoint(robot, rho, q);
    ASSERT_EQ(a.cols(), 6);
    const Eigen::Vector3d p(0.4, 0.2, 0.3);  // in the points' frame
    const Eigen::Vector3d before = PointsFromCam(robot, rho, q).Inverse() * p;
    const Eigen::Vector3d after = PointsFromCam(robot, rho, q + dq).Inverse() * p;
    const Eigen::Vector3d predicted = SmallMotionJacobian(before) * (a * dq);
    EXPECT_GT(predicted.norm(), 2e-5);
    EXPECT_LT((after - before - predicted).norm(), 1e-3 * predicted.norm() + 1e-9);
  }
}

}  // namespace
}  // namespace selfcal
