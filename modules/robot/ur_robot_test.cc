// The UR backend against the loopback fake (ur_fake.h) on a thread: connect, identity and the factory
// calibration, a move to its settled end, and each fault: a refusal at connect sends no script at all, a
// fault during a move is reported and nothing moves after it.
#include "robot/ur_robot.h"

#include <atomic>
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "robot/ur_fake.h"

namespace selfcal::robot {
namespace {

JointLimits Ur5eLimits() {
  JointLimits limits;
  limits.lower_rad = Eigen::VectorXd::Constant(6, -6.28);
  limits.upper_rad = Eigen::VectorXd::Constant(6, 6.28);
  limits.max_velocity_rad_s = Eigen::VectorXd::Constant(6, 2.0);
  return limits;
}

// The fake served on a thread; the counts are read after Shutdown().
class ServedFake {
 public:
  explicit ServedFake(UrFakeOptions options) : fake_(UrFakeController::Listen(options).value()) {
    thread_ = std::thread([this] { fake_.Serve(stop_, nullptr); });
  }
  ~ServedFake() { Shutdown(); }
  void Shutdown() {
    if (!stop_) std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the last lines read
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  UrRobotOptions ClientOptions() const {
    UrRobotOptions o;
    const UrFakeController::Ports p = fake_.ports();
    o.rtde_port = p.rtde;
    o.secondary_port = p.secondary;
    o.dashboard_port = p.dashboard;
    o.limits = Ur5eLimits();
    return o;
  }
  const UrFakeController& fake() const { return fake_; }

 private:
  UrFakeController fake_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

Result<RobotStatus> WaitForMove(UrRobot& arm, double timeout_s) {
  const auto start = std::chrono::steady_clock::now();
  while (true) {
    Result<RobotStatus> s = arm.GetStatus();
    if (!s.ok() || s->state != MotionState::kMoving) return s;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout_s) return s;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

// Connects and starts a move of 0.2 rad on joint 1 at 1 rad/s (*target).
bool StartFirstMove(UrRobot& arm, Eigen::VectorXd* target) {
  if (!arm.Connect().ok()) return false;
  *target = arm.ReadJoints()->position_rad;
  (*target)[0] += 0.2;
  return arm.StartMove(*target, 0.5).ok();
}

TEST(UrRobotTest, ConnectsReadsIdentityAndCalibrationAndMovesToASettledEnd) {
  ServedFake served({});
  UrRobot arm("127.0.0.1", served.ClientOptions());
  ASSERT_TRUE(arm.Connect().ok());
  const Result<RobotIdentity> id = arm.Identity();
  ASSERT_TRUE(id.ok());
  EXPECT_EQ(id->backend, "ur");
  EXPECT_EQ(id->model, "UR5e");
  EXPECT_EQ(id->serial, "20235500001");
  EXPECT_EQ(id->calibration_id, "ur-kinematics-00001001-00001002-00001003-00001004-00001005-00001006");
  EXPECT_TRUE(id->real_hardware);
  ASSERT_TRUE(arm.factory_kinematics().has_value());
  EXPECT_DOUBLE_EQ(arm.factory_kinematics()->dh_a[1], -0.425);
  const Result<JointReading> start = arm.ReadJoints();
  ASSERT_TRUE(start.ok());
  EXPECT_NEAR(start->position_rad[1], -1.5708, 1e-12);
  Eigen::VectorXd target = start->position_rad;
  target[0] += 0.1;
  ASSERT_TRUE(arm.StartMove(target, 0.5).ok());  // 1 rad/s: 0.1 s
  EXPECT_EQ(arm.GetStatus()->state, MotionState::kMoving);
  const Result<RobotStatus> done = WaitForMove(arm, 3.0);
  ASSERT_TRUE(done.ok()) << done.status().message();
  EXPECT_EQ(done->state, MotionState::kIdle);
  EXPECT_NEAR(arm.ReadJoints()->position_rad[0], target[0], 1e-3);
  // Outside the limits: refused here, nothing sent.
  target[0] = 7.0;
  EXPECT_EQ(RobotErrorOf(arm.StartMove(target, 0.5)), RobotError::kRejected);
  arm.Disconnect();
  served.Shutdown();
  EXPECT_EQ(served.fake().motion_commands(), 1);
}

// Both streams are read while nobody calls (the operator reading the preview before typing the serial):
// the RTDE packages keep being consumed at the stream's rate, and the arm answers at once afterwards.
TEST(UrRobotTest, TheStreamsAreReadWhileTheCallerWaits) {
  ServedFake served({});
  UrRobot arm("127.0.0.1", served.ClientOptions());
  ASSERT_TRUE(arm.Connect().ok());
  const uint64_t before = arm.packages_read();
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  EXPECT_GE(arm.packages_read() - before, 50u);  // 125 Hz: 100 in 0.8 s
  const Result<JointReading> now = arm.ReadJoints();
  ASSERT_TRUE(now.ok()) << now.status().message();
  EXPECT_LT(MonotonicClock().Now() - now->time_s, 0.25);  // a fresh package, stamped when it arrived
}

// Each refusal at connect: the message says what a person must do, and no script reached the controller.
TEST(UrRobotTest, RefusalsAtConnectSendNoMotionCommand) {
  struct Case {
    UrFakeOptions options;
    RobotError error;
    const char* says;
  };
  UrFakeOptions remote_off, stopped, wrong_recipe, outside, running;
  running.program_running = true;
  remote_off.remote_control_off = true;
  stopped.protective_stop_at_start = true;
  wrong_recipe.wrong_recipe = true;
  outside.start_rad[2] = 7.0;  // beyond the config's limits
  for (const Case& c : {Case{remote_off, RobotError::kRejected, "remote control is off"},
                        Case{stopped, RobotError::kProtectiveStop, "PROTECTIVE_STOP"},
                        Case{wrong_recipe, RobotError::kProtocol, "NOT_FOUND"},
                        Case{outside, RobotError::kBadReading, "outside its limits"},
                        Case{running, RobotError::kRejected, "a program is running on the controller"}}) {
    ServedFake served(c.options);
    UrRobot arm("127.0.0.1", served.ClientOptions());
    const Status s = arm.Connect();
    EXPECT_EQ(RobotErrorOf(s), c.error) << s.message();
    EXPECT_NE(s.message().find(c.says), std::string::npos) << s.message();
    EXPECT_EQ(RobotErrorOf(arm.StartMove(Eigen::VectorXd::Zero(6), 0.1)), RobotError::kNotConnected);
    served.Shutdown();
    EXPECT_EQ(served.fake().motion_commands(), 0) << c.says;
    EXPECT_EQ(served.fake().stop_commands(), 0) << c.says;
  }
}

TEST(UrRobotTest, ProtectiveStopDuringAMoveIsReportedAndTheNextMoveRefused) {
  UrFakeOptions options;
  options.protective_stop_move = 0;
  ServedFake served(options);
  UrRobot arm("127.0.0.1", served.ClientOptions());
  Eigen::VectorXd target;
  ASSERT_TRUE(StartFirstMove(arm, &target));
  const Result<RobotStatus> done = WaitForMove(arm, 3.0);
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->state, MotionState::kProtectiveStop) << done->message;
  EXPECT_EQ(RobotErrorOf(arm.StartMove(target, 0.5)), RobotError::kRejected);
  EXPECT_TRUE(arm.Stop().ok());
  served.Shutdown();
  EXPECT_EQ(served.fake().motion_commands(), 1);
  EXPECT_EQ(served.fake().stop_commands(), 1);
}

TEST(UrRobotTest, AMoveThatNeverFinishesStaysMovingAndStopjIsSent) {
  UrFakeOptions options;
  options.stall_move = 0;
  ServedFake served(options);
  UrRobot arm("127.0.0.1", served.ClientOptions());
  Eigen::VectorXd target;
  ASSERT_TRUE(StartFirstMove(arm, &target));
  const Result<RobotStatus> after = WaitForMove(arm, 1.0);  // the move takes 0.2 s; it never ends
  ASSERT_TRUE(after.ok());
  EXPECT_EQ(after->state, MotionState::kMoving);
  EXPECT_TRUE(arm.Stop().ok());
  served.Shutdown();
  EXPECT_EQ(served.fake().stop_commands(), 1);
}

TEST(UrRobotTest, ADroppedConnectionIsStickyAndTheStopGoesOutOnAFreshConnection) {
  UrFakeOptions options;
  options.drop_move = 0;
  ServedFake served(options);
  UrRobot arm("127.0.0.1", served.ClientOptions());
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

}  // namespace
}  // namespace selfcal::robot

namespace selfcal::robot {
namespace {

// R10, R13: a reconnect re-reads the identity and refuses another arm; R12: an expected identity is
// checked at connect. Both refusals come before anything is sent.
TEST(UrRobotTest, AReconnectRefusesAnotherArmAndTheExpectedIdentityIsChecked) {
  auto first = std::make_unique<ServedFake>(UrFakeOptions{});
  const UrRobotOptions options = first->ClientOptions();
  UrRobot arm("127.0.0.1", options);
  ASSERT_TRUE(arm.Connect().ok());
  arm.Disconnect();
  ASSERT_TRUE(arm.Connect().ok());  // the same controller again
  arm.Disconnect();
  first.reset();
  UrFakeOptions other;
  other.serial = "20235599999";
  other.rtde_port = options.rtde_port;  // another controller where the first one was
  other.secondary_port = options.secondary_port;
  other.dashboard_port = options.dashboard_port;
  ServedFake second(other);
  const Status again = arm.Connect();
  EXPECT_EQ(RobotErrorOf(again), RobotError::kProtocol) << again.message();
  EXPECT_NE(again.message().find("not the one first connected"), std::string::npos) << again.message();
  UrRobotOptions expecting = options;
  expecting.expected_identity = RobotIdentity{"", "UR5e", "20235500001", "", true};
  UrRobot expected("127.0.0.1", expecting);
  const Status refused = expected.Connect();
  EXPECT_EQ(RobotErrorOf(refused), RobotError::kProtocol) << refused.message();
  EXPECT_NE(refused.message().find("not the expected robot"), std::string::npos) << refused.message();
  second.Shutdown();
  EXPECT_EQ(second.fake().motion_commands(), 0);
  EXPECT_EQ(second.fake().stop_commands(), 0);
}

// The controller's text reaches messages and the identity escaped (no terminal control from a controller).
TEST(UrRobotTest, ControllerTextIsSanitised) {
  UrFakeOptions options;
  options.model = "UR5e\x1b[2J\a";
  ServedFake served(options);
  UrRobot arm("127.0.0.1", served.ClientOptions());
  ASSERT_TRUE(arm.Connect().ok());
  EXPECT_EQ(arm.Identity()->model, "UR5e\\x1b[2J\\x07");
}

// A controller that accepts the connection and never answers: a timeout at connect, not a hang.
TEST(UrRobotTest, ASilentControllerTimesOutAtConnect) {
  Result<TcpListener> silent = TcpListener::Listen("127.0.0.1", 0);
  ASSERT_TRUE(silent.ok());
  UrRobotOptions options = ServedFake(UrFakeOptions{}).ClientOptions();
  options.dashboard_port = silent->port();
  options.reply_timeout_s = 0.2;
  UrRobot arm("127.0.0.1", options);
  const auto start = std::chrono::steady_clock::now();
  const Status s = arm.Connect();
  EXPECT_EQ(RobotErrorOf(s), RobotError::kTimeout) << s.message();
  EXPECT_NE(s.message().find("greeting"), std::string::npos) << s.message();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

}  // namespace
}  // namespace selfcal::robot
