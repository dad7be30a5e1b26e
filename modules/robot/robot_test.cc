// The robot vocabulary (error names, the Status detail, target checks) and the clocks.
#include "robot/robot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robot/clock.h"
#include "robot/robot_test_util.h"

namespace selfcal::robot {
namespace {

using ::testing::HasSubstr;

TEST(RobotErrorTest, FailureCarriesTheErrorAsDetail) {
  const Status status = RobotFailure(RobotError::kProtectiveStop, "stopped");
  EXPECT_EQ(status.code(), ErrorCode::kHardware);
  EXPECT_EQ(status.message(), "stopped");
  EXPECT_EQ(RobotErrorOf(status), RobotError::kProtectiveStop);
  EXPECT_STREQ(RobotErrorName(RobotErrorOf(status)), "protective_stop");
  EXPECT_EQ(RobotErrorOf(Status::Ok()), RobotError::kNone);
  EXPECT_EQ(RobotErrorOf(Status::Error(ErrorCode::kHardware, "x").WithDetail("capture", 2)), RobotError::kNone);
  EXPECT_THROW(RobotFailure(RobotError::kNone, "no"), InvalidArgument);
  EXPECT_STREQ(RobotErrorName(RobotError::kOperatorAbort), "operator_abort");
  EXPECT_STREQ(MotionStateName(MotionState::kEmergencyStop), "emergency_stop");
  EXPECT_STREQ(MotionStateName(MotionState::kIdle), "idle");
}

TEST(RobotErrorTest, LimitAndTargetChecksNameTheJoint) {
  JointLimits limits = testing::ThreeJointOptions().limits;
  EXPECT_EQ(CheckJointLimits(limits), "");
  EXPECT_EQ(CheckMoveTarget(limits, Eigen::Vector3d(2, -2, 0), 1.0), "");
  EXPECT_THAT(CheckMoveTarget(limits, Eigen::Vector3d(0, -2.5, 0), 1.0),
              HasSubstr("joint 2: target -2.5 rad is outside its limits [-2, 2] rad"));
  limits.upper_rad[2] = -3;
  EXPECT_THAT(CheckJointLimits(limits), HasSubstr("joint 3: limits [-2, -3] rad"));
  limits.upper_rad.resize(2);
  EXPECT_THAT(CheckJointLimits(limits), HasSubstr("got 3, 2 and 3"));
}

TEST(ClockTest, MonotonicSleepsAndSimulatedJumps) {
  MonotonicClock monotonic;
  const double before = monotonic.Now();
  monotonic.SleepFor(0.02);
  const double after = monotonic.Now();
  EXPECT_GE(after - before, 0.02);
  EXPECT_LT(after - before, 0.5);
  SimulatedClock simulated(5);
  simulated.SleepFor(1.5);
  EXPECT_EQ(simulated.Now(), 6.5);
  simulated.SleepUntil(2);  // never backwards
  EXPECT_EQ(simulated.Now(), 6.5);
}

}  // namespace
}  // namespace selfcal::robot
