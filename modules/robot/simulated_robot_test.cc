// The simulated robot: its motion profile and ring-down, and every injected fault observed through the
// Robot interface (../shared/RELIABILITY.md R4-R10), on a SimulatedClock.
#include "robot/simulated_robot.h"

#include <cmath>
#include <memory>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robot/robot_test_util.h"

namespace selfcal::robot {
namespace {

using ::testing::HasSubstr;

class SimulatedRobotTest : public ::testing::Test {
 protected:
  void SetUp() override { options_ = testing::ThreeJointOptions(); }
  SimulatedRobot& Make() {
    robot_ = std::make_unique<SimulatedRobot>(options_, clock_);
    EXPECT_TRUE(robot_->Connect().ok());
    return *robot_;
  }
  MotionState State() {
    const Result<RobotStatus> status = robot_->GetStatus();
    EXPECT_TRUE(status.ok()) << status.status().ToString();
    return status.ok() ? status->state : MotionState::kFault;
  }
  // Commands a move and waits (on the simulated clock) past its arrival plus `extra_s`.
  void MoveAndWait(const Eigen::VectorXd& target, double extra_s = 0) {
    ASSERT_TRUE(robot_->StartMove(target, 1.0).ok());
    const AcceptedMove& move = robot_->accepted_moves().back();
    clock_.SleepUntil(move.start_time_s + move.duration_s + extra_s);
  }

  SimulatedClock clock_{100.0};
  SimulatedRobotOptions options_;
  std::unique_ptr<SimulatedRobot> robot_;
};

TEST(SimulatedRobotOptionsTest, ValidateNamesEveryBadField) {
  SimulatedRobotOptions options = testing::ThreeJointOptions();
  EXPECT_TRUE(options.Validate().ok()) << options.Validate().ToString();
  options.latency_s = -1;
  options.settle_tau_s = 0;
  options.initial_joints_rad[2] = 5;
  options.faults.jog_offset_rad = Eigen::VectorXd::Zero(2);
  const Status status = options.Validate();
  EXPECT_EQ(status.code(), ErrorCode::kInvalidInput);
  EXPECT_THAT(status.message(), HasSubstr("latency_s = -1"));
  EXPECT_THAT(status.message(), HasSubstr("settle_tau_s = 0"));
  EXPECT_THAT(status.message(), HasSubstr("initial_joints_rad: joint 3: target 5 rad is outside"));
  EXPECT_THAT(status.message(), HasSubstr("faults.jog_offset_rad: 2 entries for 3 joints"));
  options = testing::ThreeJointOptions();
  options.limits.max_velocity_rad_s[1] = 0;
  EXPECT_THAT(options.Validate().message(), HasSubstr("joint 2: max velocity 0 rad/s"));
  SimulatedClock clock;
  EXPECT_THROW(SimulatedRobot(options, clock), InvalidArgument);
}

TEST_F(SimulatedRobotTest, IdentityLimitsAndNotConnected) {
  options_.identity.model = "puma560";
  options_.identity.real_hardware = true;  // ignored: a simulated robot never is (R12)
  options_.seed = 7;
  SimulatedRobot robot(options_, clock_);
  EXPECT_EQ(RobotErrorOf(robot.ReadJoints().status()), RobotError::kNotConnected);
  EXPECT_EQ(RobotErrorOf(robot.StartMove(options_.initial_joints_rad, 1.0)), RobotError::kNotConnected);
  EXPECT_EQ(robot.StartMove(options_.initial_joints_rad, 1.0).code(), ErrorCode::kHardware);
  ASSERT_TRUE(robot.Connect().ok());
  const Result<RobotIdentity> identity = robot.Identity();
  ASSERT_TRUE(identity.ok());
  EXPECT_EQ(identity->backend, "simulated");
  EXPECT_EQ(identity->model, "puma560");
  EXPECT_EQ(identity->serial, "sim-7");
  EXPECT_FALSE(identity->real_hardware);
  const Result<JointLimits> limits = robot.Limits();
  ASSERT_TRUE(limits.ok());
  EXPECT_EQ(limits->upper_rad, options_.limits.upper_rad);
  robot.Disconnect();
  EXPECT_EQ(RobotErrorOf(robot.GetStatus().status()), RobotError::kNotConnected);
}

TEST_F(SimulatedRobotTest, ArrivesAtThePredictedTimeWithinTheVelocityLimit) {
  SimulatedRobot& robot = Make();
  const Eigen::VectorXd start = options_.initial_joints_rad;
  const Eigen::VectorXd target = Eigen::Vector3d(0.9, -0.3, 0.2);
  const double scaling = 0.5;
  const double t_command = clock_.Now();
  ASSERT_TRUE(robot.StartMove(target, scaling).ok());
  // Joint 0 limits: 0.9 rad at 1 rad/s * 0.5 with peak rate 15/8.
  const double duration_s = 1.875 * 0.9 / 0.5;
  const AcceptedMove& move = robot.accepted_moves().back();
  EXPECT_DOUBLE_EQ(move.duration_s, duration_s);
  EXPECT_DOUBLE_EQ(move.start_time_s, t_command + options_.latency_s);
  EXPECT_EQ(State(), MotionState::kMoving);
  // Nothing moves during the command latency.
  EXPECT_EQ(robot.JointsAt(move.start_time_s - 1e-9), start);

  const double arrival_s = move.start_time_s + duration_s;
  double peak[3] = {0, 0, 0};
  for (int i = 0; i <= 2000; ++i) {
    const Eigen::VectorXd velocity = robot.JointVelocitiesAt(move.start_time_s + duration_s * i / 2000.0);
    for (int j = 0; j < 3; ++j) peak[j] = std::max(peak[j], std::abs(velocity[j]));
  }
  EXPECT_NEAR(peak[0], 1.0 * scaling, 1e-12);  // the limiting joint peaks exactly at its scaled limit
  EXPECT_LE(peak[1], 2.0 * scaling);
  EXPECT_LE(peak[2], 0.5 * scaling);

  clock_.SleepUntil(arrival_s - 1e-6);
  EXPECT_EQ(State(), MotionState::kMoving);
  clock_.SleepUntil(arrival_s);
  EXPECT_EQ(State(), MotionState::kIdle);
  EXPECT_TRUE(robot.JointsAt(arrival_s).isApprox(target, 1e-15));
}

TEST_F(SimulatedRobotTest, VelocityIsTheDerivativeOfTheJoints) {
  SimulatedRobot& robot = Make();
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0.4, 0.5, -0.1), 1.0).ok());
  const AcceptedMove& move = robot.accepted_moves().back();
  const double h = 1e-6;
  // In the middle of the quintic and during the ring-down after arrival.
  for (double t : {move.start_time_s + 0.3 * move.duration_s, move.start_time_s + move.duration_s + 0.05}) {
    const Eigen::VectorXd numeric = (robot.JointsAt(t + h) - robot.JointsAt(t - h)) / (2 * h);
    EXPECT_TRUE(numeric.isApprox(robot.JointVelocitiesAt(t), 1e-6)) << numeric.transpose() << " vs "
                                                                    << robot.JointVelocitiesAt(t).transpose();
  }
}

TEST_F(SimulatedRobotTest, ReadingsAreTheHistoryAtTheirTime) {
  SimulatedRobot& robot = Make();
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0.4, 0.5, -0.1), 1.0).ok());
  for (int i = 0; i < 20; ++i) {
    clock_.SleepFor(0.037);
    const Result<JointReading> reading = robot.ReadJoints();
    ASSERT_TRUE(reading.ok());
    EXPECT_EQ(reading->time_s, clock_.Now());
    EXPECT_EQ(reading->position_rad, robot.JointsAt(reading->time_s));
    EXPECT_EQ(reading->velocity_rad_s, robot.JointVelocitiesAt(reading->time_s));
  }
}

TEST_F(SimulatedRobotTest, RingDownAfterArrivalDecays) {
  SimulatedRobot& robot = Make();
  const Eigen::VectorXd target = Eigen::Vector3d(0.2, 0.1, 0.0);
  MoveAndWait(target);
  const double arrival_s = clock_.Now();
  EXPECT_EQ(State(), MotionState::kIdle);  // idle at arrival although the arm still rings (R7)
  double max_early = 0;
  for (int i = 1; i <= 100; ++i) {
    const double since_s = i * 0.01;
    const double deviation = (robot.JointsAt(arrival_s + since_s) - target).cwiseAbs().maxCoeff();
    EXPECT_LE(deviation, options_.settle_amplitude_rad * std::exp(-since_s / options_.settle_tau_s) + 1e-15);
    if (since_s < 0.1) max_early = std::max(max_early, deviation);
  }
  EXPECT_GT(max_early, 0.5 * options_.settle_amplitude_rad);  // it does ring
  EXPECT_LT((robot.JointsAt(arrival_s + 1.0) - target).cwiseAbs().maxCoeff(), 1e-9);
}

TEST_F(SimulatedRobotTest, StartMoveRejectsBadTargetsNamingJointAndLimit) {
  SimulatedRobot& robot = Make();
  const Status outside = robot.StartMove(Eigen::Vector3d(0, 2.5, 0), 1.0);
  EXPECT_EQ(RobotErrorOf(outside), RobotError::kRejected);
  EXPECT_THAT(outside.message(), HasSubstr("move #0 rejected: joint 2: target 2.5 rad is outside its limits [-2, 2]"));
  EXPECT_THAT(robot.StartMove(Eigen::Vector2d(0, 0), 1.0).message(), HasSubstr("target has 2 joints, the robot has 3"));
  EXPECT_THAT(robot.StartMove(Eigen::Vector3d(0, NAN, 0), 1.0).message(), HasSubstr("joint 2: target nan rad is not finite"));
  EXPECT_THAT(robot.StartMove(Eigen::Vector3d::Zero(), 0.0).message(), HasSubstr("velocity scaling 0 is not in (0, 1]"));
  EXPECT_THAT(robot.StartMove(Eigen::Vector3d::Zero(), 1.5).message(), HasSubstr("velocity scaling 1.5"));
  EXPECT_TRUE(robot.accepted_moves().empty());
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0.5, 0, 0), 1.0).ok());
  const Status busy = robot.StartMove(Eigen::Vector3d::Zero(), 1.0);
  EXPECT_EQ(RobotErrorOf(busy), RobotError::kRejected);
  EXPECT_THAT(busy.message(), HasSubstr("move #5 is still running"));
  EXPECT_EQ(robot.counts().start_move, 7);
  EXPECT_EQ(robot.accepted_moves().size(), 1u);
}

TEST_F(SimulatedRobotTest, StopHaltsWhereTheArmIs) {
  SimulatedRobot& robot = Make();
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0.8, 0, 0), 1.0).ok());
  const AcceptedMove move = robot.accepted_moves().back();
  clock_.SleepUntil(move.start_time_s + 0.3 * move.duration_s);
  const double stop_s = clock_.Now();
  const Eigen::VectorXd here = robot.JointsAt(stop_s);
  ASSERT_TRUE(robot.Stop().ok());
  EXPECT_EQ(State(), MotionState::kIdle);
  EXPECT_GT(here[0], 0.05);
  EXPECT_LT(here[0], 0.75);
  EXPECT_EQ(robot.JointsAt(stop_s + 10), here);
  EXPECT_EQ(robot.JointVelocitiesAt(stop_s + 10), Eigen::VectorXd::Zero(3));
  EXPECT_TRUE(robot.Stop().ok());  // repeatedly, in any state
  // Stopped during the latency: the arm never starts.
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0.0, 0, 0), 1.0).ok());
  ASSERT_TRUE(robot.Stop().ok());
  clock_.SleepFor(5);
  EXPECT_EQ(robot.JointsAt(clock_.Now()), here);
  EXPECT_EQ(robot.counts().stop, 3);
}

TEST_F(SimulatedRobotTest, RejectedMoveR5) {
  options_.faults.reject_moves = {1};
  SimulatedRobot& robot = Make();
  MoveAndWait(Eigen::Vector3d(0.1, 0, 0));
  const Status rejected = robot.StartMove(Eigen::Vector3d(0.2, 0, 0), 1.0);
  EXPECT_EQ(RobotErrorOf(rejected), RobotError::kRejected);
  EXPECT_THAT(rejected.message(), HasSubstr("move #1 rejected"));
  EXPECT_EQ(State(), MotionState::kIdle);
  EXPECT_TRUE(robot.StartMove(Eigen::Vector3d(0.2, 0, 0), 1.0).ok());
  EXPECT_EQ(robot.accepted_moves().size(), 2u);
  EXPECT_EQ(robot.accepted_moves()[1].index, 2);
}

TEST_F(SimulatedRobotTest, HangingMoveStaysMovingUntilStopR6) {
  options_.faults.hang_moves = {0};
  SimulatedRobot& robot = Make();
  const Eigen::VectorXd target = Eigen::Vector3d(0.6, -0.4, 0);
  ASSERT_TRUE(robot.StartMove(target, 1.0).ok());
  const AcceptedMove move = robot.accepted_moves().back();
  clock_.SleepUntil(move.start_time_s + 10 * move.duration_s);
  EXPECT_EQ(State(), MotionState::kMoving);
  const Eigen::VectorXd midpoint = 0.5 * (options_.initial_joints_rad + target);
  EXPECT_TRUE(robot.JointsAt(clock_.Now()).isApprox(midpoint, 1e-15));
  ASSERT_TRUE(robot.Stop().ok());
  EXPECT_EQ(State(), MotionState::kIdle);
  EXPECT_TRUE(robot.StartMove(target, 1.0).ok());
}

TEST_F(SimulatedRobotTest, ProtectiveStopNeedsAcknowledgementR9) {
  options_.faults.protective_stop_moves = {0};
  SimulatedRobot& robot = Make();
  const Eigen::VectorXd target = Eigen::Vector3d(0.6, 0, 0);
  ASSERT_TRUE(robot.StartMove(target, 1.0).ok());
  const AcceptedMove move = robot.accepted_moves().back();
  clock_.SleepUntil(move.start_time_s + 0.49 * move.duration_s);
  EXPECT_EQ(State(), MotionState::kMoving);
  clock_.SleepUntil(move.start_time_s + move.duration_s + 1);
  const Result<RobotStatus> status = robot.GetStatus();
  ASSERT_TRUE(status.ok());
  EXPECT_EQ(status->state, MotionState::kProtectiveStop);
  EXPECT_THAT(status->message, HasSubstr("protective stop during move #0"));
  EXPECT_NEAR(robot.JointsAt(clock_.Now())[0], 0.3, 1e-15);
  ASSERT_TRUE(robot.Stop().ok());
  EXPECT_EQ(State(), MotionState::kProtectiveStop);  // Stop does not clear it: a person must
  const Status refused = robot.StartMove(target, 1.0);
  EXPECT_EQ(RobotErrorOf(refused), RobotError::kRejected);
  EXPECT_THAT(refused.message(), HasSubstr("acknowledge"));
  robot.AcknowledgeStop();
  EXPECT_EQ(State(), MotionState::kIdle);
  EXPECT_TRUE(robot.StartMove(target, 1.0).ok());
}

TEST_F(SimulatedRobotTest, EmergencyStopR9) {
  options_.faults.emergency_stop_moves = {1};
  SimulatedRobot& robot = Make();
  MoveAndWait(Eigen::Vector3d(0.2, 0, 0), 3.0);  // long enough for the ring-down to vanish
  EXPECT_EQ(State(), MotionState::kIdle);
  MoveAndWait(Eigen::Vector3d(0.4, 0, 0));
  EXPECT_EQ(State(), MotionState::kEmergencyStop);
  EXPECT_NEAR(robot.JointsAt(clock_.Now())[0], 0.3, 1e-15);
  EXPECT_EQ(RobotErrorOf(robot.StartMove(Eigen::Vector3d(0.4, 0, 0), 1.0)), RobotError::kRejected);
  robot.AcknowledgeStop();
  EXPECT_TRUE(robot.StartMove(Eigen::Vector3d(0.4, 0, 0), 1.0).ok());
}

TEST_F(SimulatedRobotTest, ConnectionLostMidMoveR10) {
  options_.faults.disconnect_moves = {0};
  SimulatedRobot& robot = Make();
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0.6, 0, 0), 1.0).ok());
  const AcceptedMove move = robot.accepted_moves().back();
  clock_.SleepUntil(move.start_time_s + 0.25 * move.duration_s);
  EXPECT_EQ(State(), MotionState::kMoving);
  clock_.SleepUntil(move.start_time_s + 0.75 * move.duration_s);
  const Result<RobotStatus> status = robot.GetStatus();
  EXPECT_EQ(RobotErrorOf(status.status()), RobotError::kDisconnected);
  EXPECT_THAT(status.status().message(), HasSubstr("connection lost during move #0"));
  EXPECT_EQ(RobotErrorOf(robot.ReadJoints().status()), RobotError::kDisconnected);
  EXPECT_EQ(RobotErrorOf(robot.Stop()), RobotError::kDisconnected);
  EXPECT_EQ(RobotErrorOf(robot.Identity().status()), RobotError::kDisconnected);
  EXPECT_EQ(RobotErrorOf(robot.StartMove(Eigen::Vector3d::Zero(), 1.0)), RobotError::kDisconnected);
  EXPECT_NEAR(robot.JointsAt(clock_.Now())[0], 0.3, 1e-15);  // the arm stopped half way
  ASSERT_TRUE(robot.Connect().ok());
  EXPECT_EQ(State(), MotionState::kIdle);
  const Result<JointReading> reading = robot.ReadJoints();
  ASSERT_TRUE(reading.ok());
  EXPECT_NEAR(reading->position_rad[0], 0.3, 1e-15);
}

TEST_F(SimulatedRobotTest, JogAfterSettlingMovesTheStartStateR4) {
  options_.faults.jog_after_moves = {0};
  options_.faults.jog_offset_rad = Eigen::Vector3d(0, -0.01, 0.03);
  SimulatedRobot& robot = Make();
  const Eigen::VectorXd target = Eigen::Vector3d(0.2, 0.2, 0.2);
  MoveAndWait(target, 0.9 * options_.faults.jog_delay_s);
  EXPECT_LT((robot.ReadJoints()->position_rad - target).cwiseAbs().maxCoeff(), 1e-5);
  clock_.SleepFor(0.2 * options_.faults.jog_delay_s);
  const Eigen::VectorXd jogged = robot.ReadJoints()->position_rad;
  EXPECT_TRUE(jogged.isApprox(target + options_.faults.jog_offset_rad, 1e-5)) << jogged.transpose();
  // The next move starts from where the arm really is.
  ASSERT_TRUE(robot.StartMove(target, 1.0).ok());
  const AcceptedMove move = robot.accepted_moves().back();
  EXPECT_TRUE(robot.JointsAt(move.start_time_s).isApprox(jogged, 1e-5));
}

TEST_F(SimulatedRobotTest, DefaultJogIsOnJointZeroAndHappensBeforeAnEarlyNextMove) {
  options_.faults.jog_after_moves = {0};
  SimulatedRobot& robot = Make();
  const Eigen::VectorXd target = Eigen::Vector3d(0.2, 0.2, 0.2);
  MoveAndWait(target, 0.01);
  ASSERT_TRUE(robot.StartMove(target, 1.0).ok());  // before the jog delay: the jog comes first
  const AcceptedMove move = robot.accepted_moves().back();
  EXPECT_NEAR(robot.JointsAt(move.start_time_s)[0], 0.22, 1e-4);
  clock_.SleepUntil(move.start_time_s + move.duration_s + 2);
  EXPECT_TRUE(robot.ReadJoints()->position_rad.isApprox(target, 1e-9));
}

TEST_F(SimulatedRobotTest, SlowSettleR7) {
  options_.faults.slow_settle_moves = {1};
  SimulatedRobot& robot = Make();
  const Eigen::VectorXd target = Eigen::Vector3d(0.2, 0, 0);
  MoveAndWait(target);
  const double fast_arrival_s = clock_.Now();
  const auto deviation_at = [&](double t) { return (robot.JointsAt(t) - target).cwiseAbs().maxCoeff(); };
  // Half a second after arrival: a normal ring-down is gone, the slow one is not (sin(2 pi 6 Hz t) = 0 at
  // t = 0.5 s exactly, so look a quarter period later).
  const double probe_s = 0.5 + 1.0 / 24;
  EXPECT_LT(deviation_at(fast_arrival_s + probe_s), 1e-6);
  clock_.SleepFor(1);
  MoveAndWait(Eigen::Vector3d(0.2, 0, 0.1));
  const Eigen::VectorXd second = Eigen::Vector3d(0.2, 0, 0.1);
  const double slow = (robot.JointsAt(clock_.Now() + probe_s) - second).cwiseAbs().maxCoeff();
  EXPECT_NEAR(slow, options_.settle_amplitude_rad * std::exp(-probe_s / (20 * options_.settle_tau_s)), 1e-12);
}

TEST_F(SimulatedRobotTest, AnArmThatNeverSettlesReadsMovingAfterItsMoveR7) {
  options_.faults.never_settle_moves = {1};
  SimulatedRobot& robot = Make();
  MoveAndWait(Eigen::Vector3d(0.2, 0, 0));
  clock_.SleepFor(2);
  EXPECT_LT(robot.ReadJoints()->velocity_rad_s.cwiseAbs().maxCoeff(), 1e-6);  // move #0 rests
  const Eigen::VectorXd second = Eigen::Vector3d(0.2, 0, 0.1);
  MoveAndWait(second);
  clock_.SleepFor(10);
  const Result<JointReading> restless = robot.ReadJoints();
  ASSERT_TRUE(restless.ok());
  EXPECT_EQ(restless->velocity_rad_s, Eigen::VectorXd::Constant(3, 0.05));  // every joint, long after arrival
  EXPECT_TRUE(restless->position_rad.isApprox(second, 1e-6));
  EXPECT_EQ(robot.GetStatus()->state, MotionState::kIdle);
}

TEST_F(SimulatedRobotTest, BadReadingsR8) {
  options_.faults.stale_reads = {0, 2};
  options_.faults.nan_reads = {3};
  options_.faults.short_reads = {4};
  SimulatedRobot& robot = Make();
  const Result<JointReading> first = robot.ReadJoints();  // #0: stale without a previous reading
  ASSERT_TRUE(first.ok());
  EXPECT_EQ(first->time_s, clock_.Now() - 1);
  ASSERT_TRUE(robot.StartMove(Eigen::Vector3d(0.5, 0, 0), 1.0).ok());
  clock_.SleepFor(0.3);
  const JointReading good = robot.ReadJoints().value();  // #1
  EXPECT_EQ(good.time_s, clock_.Now());
  clock_.SleepFor(0.1);
  const JointReading stale = robot.ReadJoints().value();  // #2
  EXPECT_EQ(stale.time_s, good.time_s - 1);
  EXPECT_EQ(stale.position_rad, good.position_rad);
  EXPECT_NE(robot.JointsAt(clock_.Now()), good.position_rad);
  const JointReading with_nan = robot.ReadJoints().value();  // #3
  EXPECT_TRUE(std::isnan(with_nan.position_rad[1]));
  EXPECT_TRUE(std::isfinite(with_nan.position_rad[0]));
  const JointReading short_reading = robot.ReadJoints().value();  // #4
  EXPECT_EQ(short_reading.position_rad.size(), 2);
  EXPECT_EQ(short_reading.velocity_rad_s.size(), 2);
  const JointReading fine = robot.ReadJoints().value();  // #5
  EXPECT_EQ(fine.position_rad.size(), 3);
  EXPECT_TRUE(fine.position_rad.allFinite());
  EXPECT_EQ(robot.counts().read, 6);
}

TEST_F(SimulatedRobotTest, EncoderNoiseIsSeeded) {
  options_.encoder_noise_rad = 1e-4;
  options_.seed = 3;
  SimulatedClock clock_a(0), clock_b(0), clock_c(0);
  SimulatedRobot a(options_, clock_a), b(options_, clock_b);
  options_.seed = 4;
  SimulatedRobot c(options_, clock_c);
  for (SimulatedRobot* robot : {&a, &b, &c}) ASSERT_TRUE(robot->Connect().ok());
  const Eigen::VectorXd ra = a.ReadJoints()->position_rad;
  EXPECT_EQ(ra, b.ReadJoints()->position_rad);
  EXPECT_NE(ra, c.ReadJoints()->position_rad);
  EXPECT_NE(ra, a.JointsAt(0));
  EXPECT_LT((ra - a.JointsAt(0)).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_EQ(a.JointsAt(0), options_.initial_joints_rad);  // the truth carries no noise
}

TEST_F(SimulatedRobotTest, CommandLogForF8) {
  SimulatedRobot& robot = Make();
  ASSERT_TRUE(robot.Identity().ok());
  ASSERT_TRUE(robot.Limits().ok());
  const Eigen::VectorXd target = Eigen::Vector3d(0.1, 0.2, 0.3);
  ASSERT_TRUE(robot.StartMove(target, 0.25).ok());
  const double command_s = clock_.Now();
  State();
  State();
  ASSERT_TRUE(robot.Stop().ok());
  robot.ReadJoints();
  robot.Disconnect();
  const CommandCounts& counts = robot.counts();
  EXPECT_EQ(counts.connect, 1);
  EXPECT_EQ(counts.identity, 1);
  EXPECT_EQ(counts.limits, 1);
  EXPECT_EQ(counts.start_move, 1);
  EXPECT_EQ(counts.status, 2);
  EXPECT_EQ(counts.stop, 1);
  EXPECT_EQ(counts.read, 1);
  EXPECT_EQ(counts.disconnect, 1);
  ASSERT_EQ(robot.accepted_moves().size(), 1u);
  const AcceptedMove& move = robot.accepted_moves()[0];
  EXPECT_EQ(move.index, 0);
  EXPECT_EQ(move.target_rad, target);
  EXPECT_EQ(move.velocity_scaling, 0.25);
  EXPECT_EQ(move.command_time_s, command_s);
  EXPECT_EQ(move.start_time_s, command_s + options_.latency_s);
}

}  // namespace
}  // namespace selfcal::robot
