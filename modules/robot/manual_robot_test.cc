// The manual backend with scripted operator input: done, abort, end of input, typed joints re-asked.
#include "robot/manual_robot.h"

#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robot/robot_test_util.h"
#include "robot/simulated_robot.h"

namespace selfcal::robot {
namespace {

using ::testing::HasSubstr;

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

class ManualRobotTest : public ::testing::Test {
 protected:
  // A manual robot reading the operator's answers from `input`.
  ManualRobot& Make(const std::string& input) {
    in_.str(input);
    robot_ = std::make_unique<ManualRobot>(in_, out_, testing::ThreeJointOptions().limits, clock_);
    EXPECT_TRUE(robot_->Connect().ok());
    return *robot_;
  }

  std::istringstream in_;
  std::ostringstream out_;
  SimulatedClock clock_{10};
  std::unique_ptr<ManualRobot> robot_;
};

TEST_F(ManualRobotTest, DoneEndsTheMoveAndTypedJointsAreTheReading) {
  ManualRobot& robot = Make("0 0 0\n\n  Done \n10, -20.5, 30\n");
  const Result<RobotIdentity> identity = robot.Identity();
  ASSERT_TRUE(identity.ok());
  EXPECT_EQ(identity->backend, "manual");
  EXPECT_TRUE(identity->real_hardware);
  ASSERT_TRUE(robot.ReadJoints().ok());
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(1, 0, -0.5), 0.5).ok());
  EXPECT_THAT(out_.str(), HasSubstr("move #0: jog the robot to these joint angles, then type `done`"));
  EXPECT_THAT(out_.str(), HasSubstr("joint 1:    57.296 deg  (+57.296 deg from the last reading)"));
  EXPECT_THAT(out_.str(), HasSubstr("joint 3:   -28.648 deg  (-28.648 deg from the last reading)"));
  const Result<RobotStatus> waiting = robot.GetStatus();  // an empty line: still moving
  ASSERT_TRUE(waiting.ok());
  EXPECT_EQ(waiting->state, MotionState::kMoving);
  EXPECT_EQ(RobotErrorOf(robot.StartMove(Eigen::Vector3d::Zero(), 1.0)), RobotError::kRejected);
  const Result<RobotStatus> done = robot.GetStatus();
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->state, MotionState::kIdle);
  // Never assumed at the target: the reading is what the operator typed.
  clock_.SleepFor(3);
  const Result<JointReading> reading = robot.ReadJoints();
  ASSERT_TRUE(reading.ok()) << reading.status().ToString();
  EXPECT_TRUE(reading->position_rad.isApprox(Eigen::Vector3d(10, -20.5, 30) * kRadPerDeg, 1e-15));
  EXPECT_EQ(reading->velocity_rad_s, Eigen::VectorXd::Zero(3));
  EXPECT_EQ(reading->time_s, 13);
  EXPECT_EQ(robot.GetStatus()->state, MotionState::kIdle);  // nothing pending: reads no input
}

TEST_F(ManualRobotTest, AbortAndEndOfInputAreOperatorAborts) {
  ManualRobot& robot = Make("abort\n");
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0.1, 0, 0), 1.0).ok());
  EXPECT_THAT(out_.str(), HasSubstr("no joint reading yet"));
  const Result<RobotStatus> aborted = robot.GetStatus();
  EXPECT_EQ(RobotErrorOf(aborted.status()), RobotError::kOperatorAbort);
  EXPECT_THAT(aborted.status().message(), HasSubstr("aborted move #0"));
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0.1, 0, 0), 1.0).ok());
  EXPECT_EQ(RobotErrorOf(robot.GetStatus().status()), RobotError::kOperatorAbort);  // end of input
  EXPECT_EQ(RobotErrorOf(robot.ReadJoints().status()), RobotError::kOperatorAbort);
}

TEST_F(ManualRobotTest, TypedJointsAreCheckedAndAskedAgain) {
  ManualRobot& robot = Make("0 0 500\n1 2\n0 x 1\n0 0 10\n");
  const Result<JointReading> reading = robot.ReadJoints();
  ASSERT_TRUE(reading.ok()) << reading.status().ToString();
  EXPECT_NEAR(reading->position_rad[2], 10 * kRadPerDeg, 1e-15);
  EXPECT_THAT(out_.str(), HasSubstr("joint 3: 500 deg is outside its limits"));
  EXPECT_THAT(out_.str(), HasSubstr("expected 3 values, got 2"));
  EXPECT_THAT(out_.str(), HasSubstr("joint 2: \"x\" is not a finite number"));

  ManualRobot& stubborn = Make("999 0 0\n999 0 0\n999 0 0\n999 0 0\n0 0 0\n");
  const Result<JointReading> refused = stubborn.ReadJoints();
  EXPECT_EQ(RobotErrorOf(refused.status()), RobotError::kBadReading);
  EXPECT_THAT(refused.status().message(), HasSubstr("after 4 attempts"));
}

TEST_F(ManualRobotTest, BadTargetsAreRejectedAndStopCancels) {
  ManualRobot& robot = Make("");
  const Status outside = robot.StartMove(Eigen::Vector3d(0, 0, 2.5), 1.0);
  EXPECT_EQ(RobotErrorOf(outside), RobotError::kRejected);
  EXPECT_THAT(outside.message(), HasSubstr("joint 3: target 2.5 rad is outside"));
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0, 0, 1), 1.0).ok());
  ASSERT_TRUE(robot.Stop().ok());
  EXPECT_THAT(out_.str(), HasSubstr("STOP: stop moving the robot now. Move #1 is cancelled."));
  EXPECT_EQ(robot.GetStatus()->state, MotionState::kIdle);
  ManualRobot unconnected(in_, out_, testing::ThreeJointOptions().limits, clock_);
  EXPECT_EQ(RobotErrorOf(unconnected.StartMove(Eigen::Vector3d::Zero(), 1.0)), RobotError::kNotConnected);
}

TEST_F(ManualRobotTest, JointReaderSuppliesReadingsAndIdentity) {
  SimulatedRobotOptions options = testing::ThreeJointOptions();
  options.initial_joints_rad = Eigen::Vector3d(0.1, 0.2, 0.3);
  options.identity.model = "puma560";
  SimulatedRobot reader(options, clock_);
  in_.str("done\n");
  ManualRobot robot(in_, out_, options.limits, clock_, &reader);
  ASSERT_TRUE(robot.Connect().ok());
  const Result<RobotIdentity> identity = robot.Identity();
  ASSERT_TRUE(identity.ok());
  EXPECT_EQ(identity->backend, "manual");
  EXPECT_EQ(identity->model, "puma560");
  EXPECT_TRUE(identity->real_hardware);
  const Result<JointReading> reading = robot.ReadJoints();
  ASSERT_TRUE(reading.ok());
  EXPECT_EQ(reading->position_rad, options.initial_joints_rad);
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0.1, 0.2, 0.4), 1.0).ok());
  EXPECT_THAT(out_.str(), HasSubstr("joint 3:    22.918 deg  (+5.730 deg from the last reading)"));
  EXPECT_EQ(robot.GetStatus()->state, MotionState::kIdle);
  EXPECT_EQ(reader.counts().start_move, 0);  // the person moves the arm, not the reader
}

}  // namespace
}  // namespace selfcal::robot
