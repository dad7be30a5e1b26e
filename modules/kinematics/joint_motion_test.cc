#include "kinematics/joint_motion.h"

#include <gtest/gtest.h>

#include "geometry/rigid3.h"

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

}  // namespace
}  // namespace selfcal
