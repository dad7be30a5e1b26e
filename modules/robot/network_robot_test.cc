// The network backend end to end on loopback: NetworkRobot against RobotServer serving a SimulatedRobot
// (on the monotonic clock, the server on a thread), and against scripted fake servers for the failure
// modes (../shared/RELIABILITY.md R5, R6, R8, R9, R10, R12, R13).
#include "robot/network_robot.h"

#include <atomic>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robot/robot_server.h"
#include "robot/robot_test_util.h"
#include "robot/simulated_robot.h"

namespace selfcal::robot {
namespace {

using ::testing::HasSubstr;

// Short moves on the real clock: latency 10 ms, the quintic at least 50 ms.
SimulatedRobotOptions FastOptions() {
  SimulatedRobotOptions options = testing::ThreeJointOptions();
  options.latency_s = 0.01;
  options.identity.model = "test arm";
  options.identity.serial = "sn-1";
  options.identity.calibration_id = "cal 2024/05";
  return options;
}

NetworkRobotOptions FastClientOptions() {
  NetworkRobotOptions options;
  options.connect_timeout_s = 1.0;
  options.reply_timeout_s = 1.0;
  return options;
}

// A SimulatedRobot served on a thread. Read robot() only after Shutdown() (no locking).
class ServedRobot {
 public:
  explicit ServedRobot(const SimulatedRobotOptions& options, RobotServerOptions server_options = {})
      : robot_(options, clock_), server_(robot_, std::move(server_options)) {
    const Status listening = server_.Listen();
    EXPECT_TRUE(listening.ok()) << listening.ToString();
    thread_ = std::thread([this] { server_.Serve(stop_); });
  }
  ~ServedRobot() { Shutdown(); }
  void Shutdown() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  int port() const { return server_.port(); }
  SimulatedRobot& robot() { return robot_; }

 private:
  MonotonicClock clock_;
  SimulatedRobot robot_;
  RobotServer server_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// A server that answers each request line with what `script` returns (nullopt: no answer at all).
class FakeServer {
 public:
  using Script = std::function<std::optional<std::string>(const std::string& request)>;
  explicit FakeServer(Script script) : script_(std::move(script)) {
    Result<TcpListener> listener = TcpListener::Listen("127.0.0.1", 0);
    EXPECT_TRUE(listener.ok());
    listener_ = std::move(listener).value();
    thread_ = std::thread([this] { Run(); });
  }
  ~FakeServer() {
    stop_ = true;
    thread_.join();
  }
  int port() const { return listener_.port(); }

  // The HELLO and LIMITS replies of a well-behaved three-joint controller; nullopt for anything else.
  static std::optional<std::string> Handshake(const std::string& request) {
    if (request.rfind("HELLO", 0) == 0) return protocol::HelloReply({"", "fake", "f-1", "", false}, 3);
    if (request == "LIMITS") return protocol::LimitsReply(testing::ThreeJointOptions().limits);
    return std::nullopt;
  }

 private:
  void Run() {
    std::optional<LineSocket> client;
    while (!stop_) {
      if (!client) {
        client = listener_.Accept(0.02, 1 << 20);
        continue;
      }
      std::string line;
      const LineIoResult read = client->ReadLine(&line, 0.02);
      if (read.outcome == LineIo::kTimeout) continue;
      if (!read.ok()) {
        client.reset();
        continue;
      }
      if (const std::optional<std::string> reply = script_(line)) client->WriteLine(*reply, 1.0);
    }
  }

  Script script_;
  TcpListener listener_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// FastOptions() with `faults`, served on a thread, and a client connected to it.
struct ServedAndConnected {
  explicit ServedAndConnected(const SimulatedRobotFaults& faults, RobotServerOptions server_options = {})
      : served(WithFaults(faults), std::move(server_options)),
        client("127.0.0.1", served.port(), FastClientOptions()) {
    const Status connected = client.Connect();
    EXPECT_TRUE(connected.ok()) << connected.ToString();
  }
  static SimulatedRobotOptions WithFaults(const SimulatedRobotFaults& faults) {
    SimulatedRobotOptions options = FastOptions();
    options.faults = faults;
    return options;
  }
  ServedRobot served;
  NetworkRobot client;
};

// Polls GetStatus until it is not kMoving (or fails), for at most 2 s.
Result<RobotStatus> WaitWhileMoving(Robot& robot) {
  MonotonicClock clock;
  const double deadline_s = clock.Now() + 2;
  while (true) {
    Result<RobotStatus> status = robot.GetStatus();
    if (!status.ok() || status->state != MotionState::kMoving || clock.Now() > deadline_s) return status;
    clock.SleepFor(0.005);
  }
}

TEST(NetworkRobotTest, RoundTripIsExactToTheBit) {
  ServedRobot served(FastOptions());
  NetworkRobot client("127.0.0.1", served.port(), FastClientOptions());
  EXPECT_EQ(RobotErrorOf(client.ReadJoints().status()), RobotError::kNotConnected);
  ASSERT_TRUE(client.Connect().ok());
  ASSERT_TRUE(client.Connect().ok());  // a no-op while connected

  const Result<RobotIdentity> identity = client.Identity();
  ASSERT_TRUE(identity.ok());
  EXPECT_EQ(identity->backend, "network");
  EXPECT_EQ(identity->model, "test arm");
  EXPECT_EQ(identity->serial, "sn-1");
  EXPECT_EQ(identity->calibration_id, "cal 2024/05");
  EXPECT_FALSE(identity->real_hardware);
  const Result<JointLimits> limits = client.Limits();
  ASSERT_TRUE(limits.ok());
  EXPECT_EQ(limits->lower_rad, FastOptions().limits.lower_rad);
  EXPECT_EQ(limits->max_velocity_rad_s, FastOptions().limits.max_velocity_rad_s);

  const Eigen::Vector3d target(0.1, -1.0 / 3, 0.02);
  ASSERT_TRUE(client.StartMove(target, 0.9).ok());
  std::vector<JointReading> readings;
  std::vector<double> controller_times;
  MonotonicClock clock;
  for (int i = 0; i < 5; ++i) {
    const double before_s = clock.Now();
    const Result<JointReading> reading = client.ReadJoints();
    ASSERT_TRUE(reading.ok()) << reading.status().ToString();
    EXPECT_GE(reading->time_s, before_s);  // stamped on this side when the reply arrived
    EXPECT_LE(reading->time_s, clock.Now());
    readings.push_back(*reading);
    controller_times.push_back(client.last_controller_time_s());
    clock.SleepFor(0.02);
  }
  const Result<RobotStatus> settled = WaitWhileMoving(client);
  ASSERT_TRUE(settled.ok());
  EXPECT_EQ(settled->state, MotionState::kIdle);
  ASSERT_TRUE(client.Stop().ok());
  client.Disconnect();
  EXPECT_EQ(RobotErrorOf(client.GetStatus().status()), RobotError::kNotConnected);
  served.Shutdown();

  SimulatedRobot& robot = served.robot();
  ASSERT_EQ(robot.accepted_moves().size(), 1u);
  EXPECT_EQ(robot.accepted_moves()[0].target_rad, Eigen::VectorXd(target));  // %.17g both ways
  EXPECT_EQ(robot.accepted_moves()[0].velocity_scaling, 0.9);
  for (size_t i = 0; i < readings.size(); ++i) {
    EXPECT_EQ(readings[i].position_rad, robot.JointsAt(controller_times[i]));
    EXPECT_EQ(readings[i].velocity_rad_s, robot.JointVelocitiesAt(controller_times[i]));
  }
  EXPECT_EQ(robot.counts().read, 5);
  EXPECT_GE(robot.counts().stop, 2);  // the client's STOP and the server's after BYE
}

TEST(NetworkRobotTest, RejectionsAndLocalRefusalR5) {
  SimulatedRobotFaults faults;
  faults.reject_moves = {0};
  ServedAndConnected connected(faults);
  NetworkRobot& client = connected.client;
  const Status rejected = client.StartMove(Eigen::Vector3d(0.1, 0, 0), 1.0);
  EXPECT_EQ(RobotErrorOf(rejected), RobotError::kRejected);
  EXPECT_THAT(rejected.message(), HasSubstr("controller error rejected"));
  EXPECT_THAT(rejected.message(), HasSubstr("move #0 rejected: the controller refused"));
  // Out of limits: refused before anything is sent (F8).
  const Status outside = client.StartMove(Eigen::Vector3d(0.1, 3, 0), 1.0);
  EXPECT_EQ(RobotErrorOf(outside), RobotError::kRejected);
  EXPECT_THAT(outside.message(), HasSubstr("refused before sending: joint 2"));
  client.Disconnect();
  connected.served.Shutdown();
  EXPECT_EQ(connected.served.robot().counts().start_move, 1);
}

TEST(NetworkRobotTest, ProtectiveStopIsReportedR9) {
  SimulatedRobotFaults faults;
  faults.protective_stop_moves = {0};
  ServedAndConnected connected(faults);
  NetworkRobot& client = connected.client;
  ASSERT_TRUE(client.StartMove(Eigen::Vector3d(0.2, 0, 0), 1.0).ok());
  const Result<RobotStatus> status = WaitWhileMoving(client);
  ASSERT_TRUE(status.ok());
  EXPECT_EQ(status->state, MotionState::kProtectiveStop);
  EXPECT_THAT(status->message, HasSubstr("protective stop during move #0"));
  EXPECT_EQ(RobotErrorOf(client.StartMove(Eigen::Vector3d(0.2, 0, 0), 1.0)), RobotError::kRejected);
}

TEST(NetworkRobotTest, BadReadingsPassThroughToTheCallerR8) {
  SimulatedRobotFaults faults;
  faults.nan_reads = {0};
  faults.short_reads = {1};
  ServedAndConnected connected(faults);
  NetworkRobot& client = connected.client;
  const Result<JointReading> with_nan = client.ReadJoints();
  ASSERT_TRUE(with_nan.ok());
  EXPECT_TRUE(std::isnan(with_nan->position_rad[1]));
  const Result<JointReading> short_reading = client.ReadJoints();
  ASSERT_TRUE(short_reading.ok());
  EXPECT_EQ(short_reading->position_rad.size(), 2);
}

TEST(NetworkRobotTest, LostRobotConnectionClosesTheSocketR10) {
  SimulatedRobotFaults faults;
  faults.disconnect_moves = {0};
  ServedAndConnected connected(faults);
  NetworkRobot& client = connected.client;
  ASSERT_TRUE(client.StartMove(Eigen::Vector3d(0.2, 0, 0), 1.0).ok());
  const Result<RobotStatus> status = WaitWhileMoving(client);
  EXPECT_EQ(RobotErrorOf(status.status()), RobotError::kDisconnected) << status.status().ToString();
  EXPECT_EQ(RobotErrorOf(client.ReadJoints().status()), RobotError::kDisconnected);
  EXPECT_EQ(RobotErrorOf(client.Stop()), RobotError::kDisconnected);
  EXPECT_EQ(RobotErrorOf(client.Identity().status()), RobotError::kDisconnected);
  ASSERT_TRUE(client.Connect().ok());  // HELLO reconnects the robot behind the server
  const Result<JointReading> reading = client.ReadJoints();
  ASSERT_TRUE(reading.ok()) << reading.status().ToString();
  EXPECT_NEAR(reading->position_rad[0], 0.1, 1e-12);  // halted half way
}

TEST(NetworkRobotTest, DroppedConnectionMidMoveAndReconnectChecksIdentityR10R13) {
  RobotServerOptions server_options;
  server_options.drop_client_after_moves = {0};
  auto first = std::make_unique<ServedRobot>(FastOptions(), server_options);
  const int port = first->port();
  NetworkRobot client("127.0.0.1", port, FastClientOptions());
  ASSERT_TRUE(client.Connect().ok());
  ASSERT_TRUE(client.StartMove(Eigen::Vector3d(0.5, 0, 0), 0.5).ok());
  const Result<RobotStatus> status = client.GetStatus();
  EXPECT_EQ(RobotErrorOf(status.status()), RobotError::kDisconnected) << status.status().ToString();
  EXPECT_EQ(RobotErrorOf(client.ReadJoints().status()), RobotError::kDisconnected);
  EXPECT_EQ(RobotErrorOf(client.StartMove(Eigen::Vector3d(0.5, 0, 0), 0.5)), RobotError::kDisconnected);
  // Same arm again: accepted.
  ASSERT_TRUE(client.Connect().ok());
  EXPECT_TRUE(client.ReadJoints().ok());
  first->Shutdown();
  EXPECT_GE(first->robot().counts().stop, 1);  // the server stopped the arm when the client went away
  EXPECT_EQ(first->robot().counts().connect, 2);
  first.reset();

  // Another arm on the same address: refused, and the client stays disconnected.
  SimulatedRobotOptions other = FastOptions();
  other.identity.serial = "sn-2";
  RobotServerOptions same_port;
  same_port.port = port;
  ServedRobot second(other, same_port);
  ASSERT_EQ(second.port(), port);
  EXPECT_EQ(RobotErrorOf(client.GetStatus().status()), RobotError::kDisconnected);
  const Status refused = client.Connect();
  EXPECT_EQ(RobotErrorOf(refused), RobotError::kProtocol);
  EXPECT_THAT(refused.message(), HasSubstr("serial \"sn-1\", now \"sn-2\""));
  EXPECT_EQ(RobotErrorOf(client.GetStatus().status()), RobotError::kDisconnected);
  second.Shutdown();
  EXPECT_EQ(second.robot().counts().start_move, 0);
}

TEST(NetworkRobotTest, ExpectedIdentityIsCheckedAtConnectR12) {
  ServedRobot served(FastOptions());
  NetworkRobotOptions options = FastClientOptions();
  options.expected_identity = RobotIdentity{"", "test arm", "sn-9", "", false};
  NetworkRobot client("127.0.0.1", served.port(), options);
  const Status refused = client.Connect();
  EXPECT_EQ(RobotErrorOf(refused), RobotError::kProtocol);
  EXPECT_THAT(refused.message(), HasSubstr("not the expected robot (expected serial \"sn-9\", now \"sn-1\")"));
  EXPECT_EQ(RobotErrorOf(client.GetStatus().status()), RobotError::kNotConnected);
}

// Issue 16 item 4: with the robot config's limits, Connect() checks the joint count, intersects the
// limits and checks the start reading; a refusal there sends neither MOVE nor STOP.
NetworkRobotOptions ConfigClientOptions(std::vector<std::string>* log) {
  NetworkRobotOptions options = FastClientOptions();
  options.config_limits = testing::ThreeJointOptions().limits;
  options.rest_interval_s = 0.01;
  options.log = [log](const std::string& line) { log->push_back(line); };
  return options;
}

JointReading Reading(const Eigen::Vector3d& q, const Eigen::Vector3d& qdot = Eigen::Vector3d::Zero()) {
  JointReading r;
  r.position_rad = q;
  r.velocity_rad_s = qdot;
  r.time_s = 1.0;
  return r;
}

// A three-joint controller with `hello` and `limits` replies and JOINTS answered by `joints(k)` for the
// k-th reading; counts the MOVE and STOP requests it received.
struct ScriptedController {
  ScriptedController(std::string hello, std::string limits, std::function<std::string(int)> joints)
      : server([this, hello, limits, joints](const std::string& request) -> std::optional<std::string> {
          if (request.rfind("HELLO", 0) == 0) return hello;
          if (request == "LIMITS") return limits;
          if (request == "JOINTS") return joints(readings++);
          if (request.rfind("MOVE", 0) == 0 || request == "STOP") ++motion_commands;
          return protocol::OkReply();
        }) {}
  std::atomic<int> readings{0}, motion_commands{0};
  FakeServer server;
};

TEST(NetworkRobotTest, ConnectChecksJointCountLimitsAndTheStartReadingAgainstTheConfig) {
  const std::string hello3 = protocol::HelloReply({"", "fake", "f-1", "", false}, 3);
  const std::string limits3 = protocol::LimitsReply(testing::ThreeJointOptions().limits);
  const std::string at_rest = protocol::JointsReply(Reading(Eigen::Vector3d(0.1, 0.2, 0.3)));
  JointLimits two;
  two.lower_rad = Eigen::Vector2d(-1, -1);
  two.upper_rad = Eigen::Vector2d(1, 1);
  two.max_velocity_rad_s = Eigen::Vector2d(1, 1);
  const std::string limits2 = protocol::LimitsReply(two);
  struct Case {
    const char* what;
    std::string hello, limits;
    std::function<std::string(int)> joints;
    const char* expected;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<Case> cases = {
      {"2 joints in HELLO", protocol::HelloReply({"", "fake", "f-1", "", false}, 2), limits2,
       [&](int) { return at_rest; }, "HELLO reports 2 joints, the robot config has 3"},
      {"2 joints in LIMITS", hello3, limits2,
       [&](int) { return at_rest; }, "LIMITS: malformed reply \"OK -1 -1 1 1 1 1\": 6 numbers, expected 3 x 3 joints"},
      {"short reading", hello3, limits3, [](int) { return std::string("OK 1 0.1 0.2 0 0"); },
       "the start reading has 2 joints, the robot config has 3"},
      {"NaN", hello3, limits3, [&](int) { return protocol::JointsReply(Reading(Eigen::Vector3d(0.1, nan, 0.3))); },
       "the start reading is not finite"},
      {"inf", hello3, limits3, [&](int) { return protocol::JointsReply(Reading(Eigen::Vector3d(inf, 0.2, 0.3))); },
       "the start reading is not finite"},
      {"out of limits", hello3, limits3,
       [&](int) { return protocol::JointsReply(Reading(Eigen::Vector3d(0.1, 2.5, 0.3))); },
       "has joint 2 at 2.5 rad, outside its limits [-2, 2] rad"},
      {"moving", hello3, limits3,
       [&](int k) { return protocol::JointsReply(Reading(Eigen::Vector3d(0.1 + 0.01 * k, 0.2, 0.3))); },
       "the arm is not at rest at connect"},
      {"moving, by its velocities", hello3, limits3,
       [&](int) { return protocol::JointsReply(Reading(Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0, 0.5, 0))); },
       "the arm is not at rest at connect"},
  };
  for (const Case& c : cases) {
    ScriptedController controller(c.hello, c.limits, c.joints);
    std::vector<std::string> log;
    NetworkRobot client("127.0.0.1", controller.server.port(), ConfigClientOptions(&log));
    const Status refused = client.Connect();
    EXPECT_FALSE(refused.ok()) << c.what;
    EXPECT_THAT(refused.message(), HasSubstr(c.expected)) << c.what;
    EXPECT_EQ(controller.motion_commands.load(), 0) << c.what << ": nothing is sent to the arm at connect";
    EXPECT_EQ(RobotErrorOf(client.GetStatus().status()), RobotError::kNotConnected) << c.what;
  }
  // Controller limits of +-10 rad, wider than the config's +-2: the config's are used, and the log says so.
  JointLimits wide = testing::ThreeJointOptions().limits;
  wide.lower_rad = Eigen::Vector3d(-10, -1, -10);
  wide.upper_rad = Eigen::Vector3d(10, 1, 1.5);
  ScriptedController controller(hello3, protocol::LimitsReply(wide), [&](int) { return at_rest; });
  std::vector<std::string> log;
  NetworkRobot client("127.0.0.1", controller.server.port(), ConfigClientOptions(&log));
  ASSERT_TRUE(client.Connect().ok());
  const Result<JointLimits> limits = client.Limits();
  ASSERT_TRUE(limits.ok());
  EXPECT_EQ(limits->lower_rad, Eigen::Vector3d(-2, -1, -2));
  EXPECT_EQ(limits->upper_rad, Eigen::Vector3d(2, 1, 1.5));
  ASSERT_EQ(log.size(), 4u);  // joints 1 and 3 at connect and again at Limits(); joint 2 is narrower already
  EXPECT_THAT(log[0], HasSubstr("joint 1: the controller's limits [-10, 10] rad and the robot config's [-2, 2] rad: "
                                "the narrower [-2 2] rad is used"));
  EXPECT_EQ(RobotErrorOf(client.StartMove(Eigen::Vector3d(0, 0, 1.8), 0.5)), RobotError::kRejected);
  EXPECT_EQ(controller.motion_commands.load(), 0);
}

TEST(NetworkRobotTest, ControllerTextIsSanitisedBeforeItReachesAMessage) {
  FakeServer server([](const std::string& request) -> std::optional<std::string> {
    if (request.rfind("HELLO", 0) == 0) return protocol::HelloReply({"", "arm\x1b[2J", "s\x01n", "", false}, 3);
    if (request == "LIMITS") return protocol::LimitsReply(testing::ThreeJointOptions().limits);
    if (request == "STATUS") return std::string("OK idle ready\x1b]0;owned\x07");
    if (request == "STOP") return std::string("ERR rejected no\x1b[31m red");
    return std::nullopt;
  });
  NetworkRobot client("127.0.0.1", server.port(), FastClientOptions());
  ASSERT_TRUE(client.Connect().ok());
  EXPECT_EQ(client.Identity()->model, "arm\\x1b[2J");
  EXPECT_EQ(client.Identity()->serial, "s\\x01n");
  EXPECT_EQ(client.GetStatus()->message, "ready\\x1b]0;owned\\x07");
  const Status stop = client.Stop();
  EXPECT_THAT(stop.message(), HasSubstr("no\\x1b[31m red"));
  EXPECT_EQ(stop.message().find('\x1b'), std::string::npos);
}

// End to end through the loopback server: a controller whose identity carries an ANSI clear-screen and
// a BEL reaches selfcal escaped (the preview prints it), its UTF-8 text unchanged.
TEST(NetworkRobotTest, AnsiClearScreenFromTheServedControllerComesOutEscaped) {
  SimulatedRobotOptions options = FastOptions();
  options.identity.model = "Gr\xc3\xb6\xc3\x9f" "e 5\x1b[2J\x1b[H";
  options.identity.calibration_id = "cal\x07 2024";
  ServedRobot served(options);
  NetworkRobot client("127.0.0.1", served.port(), FastClientOptions());
  const Status connected = client.Connect();
  ASSERT_TRUE(connected.ok()) << connected.ToString();
  EXPECT_EQ(client.Identity()->model, "Gr\xc3\xb6\xc3\x9f" "e 5\\x1b[2J\\x1b[H");
  EXPECT_EQ(client.Identity()->calibration_id, "cal\\x07 2024");
  client.Disconnect();
}

TEST(NetworkRobotTest, MalformedRepliesAreProtocolErrors) {
  FakeServer server([](const std::string& request) -> std::optional<std::string> {
    if (auto handshake = FakeServer::Handshake(request)) return handshake;
    if (request == "STATUS") return "OK flying";
    if (request == "JOINTS") return "OK 1 2 3 4";
    if (request == "STOP") return "hello world";
    return std::nullopt;
  });
  NetworkRobot client("127.0.0.1", server.port(), FastClientOptions());
  ASSERT_TRUE(client.Connect().ok());
  const Result<RobotStatus> status = client.GetStatus();
  EXPECT_EQ(RobotErrorOf(status.status()), RobotError::kProtocol);
  EXPECT_THAT(status.status().message(), HasSubstr("STATUS: malformed reply \"OK flying\""));
  EXPECT_THAT(client.ReadJoints().status().message(), HasSubstr("JOINTS: malformed reply \"OK 1 2 3 4\""));
  const Status stop = client.Stop();
  EXPECT_EQ(RobotErrorOf(stop), RobotError::kProtocol);
  EXPECT_THAT(stop.message(), HasSubstr("\"hello world\""));
}

TEST(NetworkRobotTest, SilentServerTimesOut) {
  FakeServer server(FakeServer::Handshake);
  NetworkRobotOptions options = FastClientOptions();
  options.reply_timeout_s = 0.2;
  NetworkRobot client("127.0.0.1", server.port(), options);
  ASSERT_TRUE(client.Connect().ok());
  MonotonicClock clock;
  const double start_s = clock.Now();
  const Result<RobotStatus> status = client.GetStatus();
  const double elapsed_s = clock.Now() - start_s;
  EXPECT_EQ(RobotErrorOf(status.status()), RobotError::kTimeout);
  EXPECT_THAT(status.status().message(), HasSubstr("no reply to STATUS within 0.2 s"));
  EXPECT_GE(elapsed_s, 0.2);
  EXPECT_LT(elapsed_s, 0.2 + 0.3);
  // The connection was closed: a late reply cannot be taken for the next request's.
  EXPECT_EQ(RobotErrorOf(client.ReadJoints().status()), RobotError::kDisconnected);
}

TEST(NetworkRobotTest, GarbageWithoutLineEndIsCut) {
  FakeServer server([](const std::string& request) -> std::optional<std::string> {
    if (auto handshake = FakeServer::Handshake(request)) return handshake;
    return std::string(100 * 1024, 'x');  // one 100 KiB "line"
  });
  NetworkRobot client("127.0.0.1", server.port(), FastClientOptions());
  ASSERT_TRUE(client.Connect().ok());
  const Result<JointReading> reading = client.ReadJoints();
  EXPECT_EQ(RobotErrorOf(reading.status()), RobotError::kProtocol);
  EXPECT_THAT(reading.status().message(), HasSubstr("reply too long"));
  EXPECT_EQ(RobotErrorOf(client.GetStatus().status()), RobotError::kDisconnected);
}

TEST(NetworkRobotTest, WrongProtocolVersionAndNoServer) {
  FakeServer server([](const std::string&) -> std::optional<std::string> {
    return std::string("OK selfcal-robot 2 model=a serial=b calibration= joints=3 real=0");
  });
  NetworkRobot client("127.0.0.1", server.port(), FastClientOptions());
  EXPECT_EQ(RobotErrorOf(client.Connect()), RobotError::kProtocol);

  int free_port = 0;
  {
    Result<TcpListener> listener = TcpListener::Listen("127.0.0.1", 0);
    ASSERT_TRUE(listener.ok());
    free_port = listener->port();
  }
  NetworkRobot nobody("127.0.0.1", free_port, FastClientOptions());
  const Status refused = nobody.Connect();
  EXPECT_EQ(RobotErrorOf(refused), RobotError::kNotConnected);
  EXPECT_THAT(refused.message(), HasSubstr("cannot connect to 127.0.0.1:" + std::to_string(free_port)));
}

TEST(RobotServerTest, RefusesBadRequestsAndASecondClient) {
  ServedRobot served(FastOptions());
  Result<LineSocket> connected = LineSocket::Connect("127.0.0.1", served.port(), 1.0, 1 << 20);
  ASSERT_TRUE(connected.ok());
  LineSocket raw = std::move(connected).value();
  const auto ask = [&](const std::string& request) {
    std::string reply;
    EXPECT_TRUE(raw.WriteLine(request, 1.0).ok());
    EXPECT_TRUE(raw.ReadLine(&reply, 1.0).ok()) << request;
    return reply;
  };
  EXPECT_EQ(ask("JOINTS"), "ERR bad_request send HELLO first");
  EXPECT_THAT(ask("HELLO selfcal-robot 7"), HasSubstr("ERR bad_request unsupported protocol"));
  EXPECT_EQ(ask("HELLO selfcal-robot 1"),
            "OK selfcal-robot 1 model=test%20arm serial=sn-1 calibration=cal%202024/05 joints=3 real=0");
  EXPECT_EQ(ask("FLY"), "ERR bad_request unknown request \"FLY\"");
  EXPECT_THAT(ask("MOVE 1 0 0"), HasSubstr("ERR rejected"));
  EXPECT_THAT(ask("MOVE 1 0 0"), HasSubstr("target has 2 joints, the robot has 3"));
  EXPECT_EQ(ask("STATUS"), "OK idle");

  Result<LineSocket> second_connected = LineSocket::Connect("127.0.0.1", served.port(), 1.0, 1 << 20);
  ASSERT_TRUE(second_connected.ok());
  LineSocket second = std::move(second_connected).value();
  std::string busy;
  ASSERT_TRUE(second.ReadLine(&busy, 1.0).ok());
  EXPECT_EQ(busy, "ERR fault busy: another client is connected");

  EXPECT_EQ(ask("BYE"), "OK");
  std::string after;
  EXPECT_EQ(raw.ReadLine(&after, 1.0).outcome, LineIo::kClosed);
}

}  // namespace
}  // namespace selfcal::robot
