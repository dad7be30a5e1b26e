// The FANUC backend against the loopback fake (fanuc_fake.h) on a thread: connect, identity, a move to
// its end, and each fault: a refusal at connect sends no instruction at all, a fault during a move is
// reported and nothing moves after it.
#include "robot/fanuc_robot.h"

#include <atomic>
#include <chrono>
#include <memory>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robot/fanuc_fake.h"

namespace selfcal::robot {
namespace {

using ::testing::HasSubstr;

JointLimits ArmLimits() {
  JointLimits limits;
  limits.lower_rad = Eigen::VectorXd::Constant(6, -3.0);
  limits.upper_rad = Eigen::VectorXd::Constant(6, 3.0);
  limits.max_velocity_rad_s = Eigen::VectorXd::Constant(6, kFanucJointSpeedLimit_rad_s);
  return limits;
}

// The fake served on a thread; the counts are read after Shutdown().
class ServedFake {
 public:
  explicit ServedFake(FanucFakeOptions options) : fake_(FanucFakeController::Listen(options).value()) {
    thread_ = std::thread([this] { fake_.Serve(stop_, nullptr); });
  }
  ~ServedFake() { Shutdown(); }
  void Shutdown() {
    if (!stop_) std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the last packets read
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  FanucRobotOptions ClientOptions() const {
    FanucRobotOptions o;
    o.connect_port = fake_.connect_port();
    o.limits = ArmLimits();
    return o;
  }
  const FanucFakeController& fake() const { return fake_; }

 private:
  FanucFakeController fake_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

Result<RobotStatus> WaitForMove(FanucRobot& arm, double timeout_s) {
  const auto start = std::chrono::steady_clock::now();
  while (true) {
    Result<RobotStatus> s = arm.GetStatus();
    if (!s.ok() || s->state != MotionState::kMoving) return s;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout_s) return s;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

// Connects and starts a move of 0.1 rad on joint 1 at full speed (*target).
bool StartFirstMove(FanucRobot& arm, Eigen::VectorXd* target) {
  if (!arm.Connect().ok()) return false;
  *target = arm.ReadJoints()->position_rad;
  (*target)[0] += 0.1;
  return arm.StartMove(*target, 1.0).ok();
}

TEST(FanucRobotTest, ConnectsReadsIdentityAndMovesToItsEnd) {
  ServedFake served({});
  FanucRobot arm("127.0.0.1", served.ClientOptions());
  ASSERT_TRUE(arm.Connect().ok());
  const Result<RobotIdentity> id = arm.Identity();
  ASSERT_TRUE(id.ok());
  EXPECT_EQ(id->backend, "fanuc");
  EXPECT_EQ(id->model, "FANUC RMI 1.0");
  EXPECT_EQ(id->serial, "127.0.0.1:" + std::to_string(served.fake().connect_port()));
  EXPECT_TRUE(id->real_hardware);
  const Result<JointReading> start = arm.ReadJoints();
  ASSERT_TRUE(start.ok());
  EXPECT_NEAR(start->position_rad[4], -1.5708, 1e-9);
  Eigen::VectorXd target = start->position_rad;
  target[0] += 0.1;
  ASSERT_TRUE(arm.StartMove(target, 1.0).ok());  // 60 deg/s: 0.1 s
  EXPECT_EQ(arm.GetStatus()->state, MotionState::kMoving);
  EXPECT_EQ(RobotErrorOf(arm.StartMove(target, 1.0)), RobotError::kRejected);  // one move at a time
  const Result<RobotStatus> done = WaitForMove(arm, 3.0);
  ASSERT_TRUE(done.ok()) << done.status().message();
  EXPECT_EQ(done->state, MotionState::kIdle);
  EXPECT_NEAR(arm.ReadJoints()->position_rad[0], target[0], 1e-6);
  target[0] = 7.0;  // outside the limits: refused here, nothing sent
  EXPECT_EQ(RobotErrorOf(arm.StartMove(target, 0.5)), RobotError::kRejected);
  arm.Disconnect();
  served.Shutdown();
  EXPECT_EQ(served.fake().motion_commands(), 1);
  EXPECT_EQ(served.fake().stop_commands(), 0);
}

TEST(FanucRobotTest, RefusalsAtConnectSendNoInstruction) {
  struct Case {
    FanucFakeOptions options;
    RobotError error;
    const char* says;
  };
  FanucFakeOptions servo_off, pendant, outside;
  servo_off.servo_off_at_start = true;
  pendant.teach_pendant_enabled = true;
  outside.start_rad[2] = 3.5;  // beyond the limits
  for (const Case& c : {Case{servo_off, RobotError::kRejected, "the servos are not ready"},
                        Case{pendant, RobotError::kRejected, "the teach pendant is enabled"},
                        Case{outside, RobotError::kBadReading, "outside its limits"}}) {
    ServedFake served(c.options);
    FanucRobot arm("127.0.0.1", served.ClientOptions());
    const Status s = arm.Connect();
    EXPECT_EQ(RobotErrorOf(s), c.error) << s.message();
    EXPECT_NE(s.message().find(c.says), std::string::npos) << s.message();
    EXPECT_EQ(RobotErrorOf(arm.StartMove(Eigen::VectorXd::Zero(6), 0.1)), RobotError::kNotConnected);
    served.Shutdown();
    EXPECT_EQ(served.fake().motion_commands(), 0) << c.says;
    EXPECT_EQ(served.fake().stop_commands(), 0) << c.says;
  }
}

TEST(FanucRobotTest, ServoOffDuringAMoveIsAFaultAndTheNextMoveIsRefused) {
  FanucFakeOptions options;
  options.servo_off_move = 0;
  ServedFake served(options);
  FanucRobot arm("127.0.0.1", served.ClientOptions());
  Eigen::VectorXd target;
  ASSERT_TRUE(StartFirstMove(arm, &target));
  const Result<RobotStatus> done = WaitForMove(arm, 3.0);
  ASSERT_TRUE(done.ok()) << done.status().message();
  EXPECT_EQ(done->state, MotionState::kFault) << done->message;
  EXPECT_EQ(RobotErrorOf(arm.StartMove(target, 0.5)), RobotError::kRejected);
  EXPECT_TRUE(arm.Stop().ok());
  served.Shutdown();
  EXPECT_EQ(served.fake().motion_commands(), 1);
  EXPECT_EQ(served.fake().stop_commands(), 1);
}

TEST(FanucRobotTest, AMoveThatNeverFinishesStaysMovingAndAbortIsSent) {
  FanucFakeOptions options;
  options.stall_move = 0;
  ServedFake served(options);
  FanucRobot arm("127.0.0.1", served.ClientOptions());
  Eigen::VectorXd target;
  ASSERT_TRUE(StartFirstMove(arm, &target));
  const Result<RobotStatus> after = WaitForMove(arm, 1.0);  // the move takes 0.1 s; it never ends
  ASSERT_TRUE(after.ok());
  EXPECT_EQ(after->state, MotionState::kMoving);
  EXPECT_TRUE(arm.Stop().ok());
  served.Shutdown();
  EXPECT_EQ(served.fake().stop_commands(), 1);
}

TEST(FanucRobotTest, ADroppedConnectionIsStickyAndTheAbortGoesOutOnAFreshConnection) {
  FanucFakeOptions options;
  options.drop_move = 0;
  ServedFake served(options);
  FanucRobot arm("127.0.0.1", served.ClientOptions());
  Eigen::VectorXd target;
  ASSERT_TRUE(StartFirstMove(arm, &target));
  const Result<RobotStatus> cut = WaitForMove(arm, 3.0);
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(RobotErrorOf(cut.status()), RobotError::kDisconnected) << cut.status().message();
  EXPECT_EQ(RobotErrorOf(arm.StartMove(target, 0.5)), RobotError::kDisconnected);  // sticky: nothing sent
  EXPECT_TRUE(arm.Stop().ok());
  served.Shutdown();
  EXPECT_EQ(served.fake().motion_commands(), 1);
  EXPECT_EQ(served.fake().stop_commands(), 1);
}

TEST(FanucRobotTest, AnAbortOnAFreshConnectionThatIsNeverAnsweredIsNotReportedAsAStop) {
  FanucFakeOptions options;
  options.drop_move = 0;
  options.silent_abort = true;
  ServedFake served(options);
  FanucRobot arm("127.0.0.1", served.ClientOptions());
  Eigen::VectorXd target;
  ASSERT_TRUE(StartFirstMove(arm, &target));
  ASSERT_FALSE(WaitForMove(arm, 3.0).ok());
  const Status stop = arm.Stop();
  EXPECT_EQ(RobotErrorOf(stop), RobotError::kDisconnected) << stop.message();
  EXPECT_THAT(stop.message(), HasSubstr("FRC_Abort was sent"));
  EXPECT_THAT(stop.message(), HasSubstr("not acknowledged"));
  served.Shutdown();
  EXPECT_EQ(served.fake().stop_commands(), 1);  // it was sent, and the controller got it
}

TEST(FanucRobotTest, AWrongAnswerBreaksTheLink) {
  FanucFakeOptions options;
  options.wrong_answer_move = 0;
  ServedFake served(options);
  FanucRobot arm("127.0.0.1", served.ClientOptions());
  Eigen::VectorXd target;
  ASSERT_TRUE(StartFirstMove(arm, &target));
  const Result<RobotStatus> wrong = WaitForMove(arm, 3.0);
  ASSERT_FALSE(wrong.ok());
  EXPECT_EQ(RobotErrorOf(wrong.status()), RobotError::kProtocol) << wrong.status().message();
  EXPECT_NE(wrong.status().message().find("FRC_ReadCartesianPosition"), std::string::npos) << wrong.status().message();
  EXPECT_EQ(RobotErrorOf(arm.StartMove(target, 0.5)), RobotError::kDisconnected);
  served.Shutdown();
  EXPECT_EQ(served.fake().motion_commands(), 1);
}

// A reconnect refuses another controller; an expected identity is checked at connect (before anything).
TEST(FanucRobotTest, AReconnectRefusesAnotherControllerAndTheExpectedIdentityIsChecked) {
  auto first = std::make_unique<ServedFake>(FanucFakeOptions{});
  const FanucRobotOptions options = first->ClientOptions();
  FanucRobot arm("127.0.0.1", options);
  ASSERT_TRUE(arm.Connect().ok());
  arm.Disconnect();
  ASSERT_TRUE(arm.Connect().ok());  // the same controller again
  arm.Disconnect();
  FanucRobotOptions expecting = options;
  expecting.expected_identity = RobotIdentity{"", "FANUC RMI 2.0", "", "", true};
  FanucRobot expected("127.0.0.1", expecting);
  const Status refused = expected.Connect();
  EXPECT_EQ(RobotErrorOf(refused), RobotError::kProtocol) << refused.message();
  EXPECT_NE(refused.message().find("not the expected robot"), std::string::npos) << refused.message();
  first->Shutdown();
  EXPECT_EQ(first->fake().motion_commands(), 0);
}

// A controller that accepts the connection and never answers: a timeout at connect, not a hang.
TEST(FanucRobotTest, ASilentControllerTimesOutAtConnect) {
  Result<TcpListener> silent = TcpListener::Listen("127.0.0.1", 0);
  ASSERT_TRUE(silent.ok());
  FanucRobotOptions options;
  options.connect_port = silent->port();
  options.limits = ArmLimits();
  options.reply_timeout_s = 0.2;
  FanucRobot arm("127.0.0.1", options);
  const auto start = std::chrono::steady_clock::now();
  const Status s = arm.Connect();
  EXPECT_EQ(RobotErrorOf(s), RobotError::kTimeout) << s.message();
  EXPECT_NE(s.message().find("FRC_Connect"), std::string::npos) << s.message();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

TEST(FanucRobotTest, RunOptionsTakeHostOrHostPort) {
  std::string host;
  Result<FanucRobotOptions> plain = FanucRunOptions("10.0.0.5", ArmLimits(), &host);
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(host, "10.0.0.5");
  EXPECT_EQ(plain->connect_port, 16001);
  Result<FanucRobotOptions> fake = FanucRunOptions("127.0.0.1:40001", ArmLimits(), &host);
  ASSERT_TRUE(fake.ok());
  EXPECT_EQ(fake->connect_port, 40001);
  EXPECT_DOUBLE_EQ(fake->limits.max_velocity_rad_s[0], kFanucJointSpeedLimit_rad_s);
  for (const char* bad : {"", ":16001", "host:", "host:70000", "host:x1"}) {
    EXPECT_EQ(FanucRunOptions(bad, ArmLimits(), &host).status().code(), ErrorCode::kInvalidInput) << bad;
  }
}

}  // namespace
}  // namespace selfcal::robot
