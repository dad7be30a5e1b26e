// The session loop (acquisition) driving the UR backend (robot/ur_robot.h) against its loopback fake
// (robot/ur_fake.h): the same safety as the network backend. A dry run shows the preview with the
// controller's identity as real hardware and sends no motion command; a protective stop, a move that never
// finishes and a dropped connection each halt the run with the robot's reason, and no movej reaches the
// controller after the halt (the fake counts them). The camera is a stub that opens and never gives a frame:
// the first pose's move needs none, and the run halts before its settle.
#include <atomic>
#include <thread>

#include <gtest/gtest.h>

#include "acquisition/session_runner.h"
#include "robot/clock.h"
#include "robot/ur_fake.h"
#include "robot/ur_robot.h"
#include "session/session_dir.h"
#include "support/temp_files.h"

namespace selfcal {
namespace {

class StubCamera : public capture::FrameSource {
 public:
  std::string Describe() const override { return "stub camera"; }
  Status Open() override { return Status::Ok(); }
  Result<capture::Frame> Grab(double, double) override {
    return Status::Error(ErrorCode::kHardware, "the stub camera has no frames");
  }
  void Close() override {}
};

struct UrCell {
  explicit UrCell(robot::UrFakeOptions fake_options)
      : fake(robot::UrFakeController::Listen(fake_options).value()), dir("ur_session") {
    thread = std::thread([this] { fake.Serve(stop_fake, nullptr); });
    const robot::UrFakeController::Ports p = fake.ports();
    robot::JointLimits limits;
    limits.lower_rad = Eigen::VectorXd::Constant(6, -6.28);
    limits.upper_rad = Eigen::VectorXd::Constant(6, 6.28);
    robot::UrRobotOptions options =
        robot::UrRunOptions("127.0.0.1", {p.rtde, p.secondary, p.dashboard}, limits).value();
    arm = std::make_unique<robot::UrRobot>("127.0.0.1", options);
    const Eigen::VectorXd start = fake_options.start_rad;
    for (int i = 0; i < 4; ++i) {
      Eigen::VectorXd q = start;
      q[0] += 0.1 * (i + 1);
      plan.push_back({"p0" + std::to_string(i), i < 3 ? PoseRole::kIdentification : PoseRole::kVerification, q});
    }
    run_options.safety.velocity_scaling = 1.0;
  }
  ~UrCell() { StopFake(); }
  void StopFake() {
    if (stop_fake) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the last lines read
    stop_fake = true;
    thread.join();
  }
  acquisition::RunReport Run(bool confirm) {
    acquisition::RunContext c;
    c.robot = arm.get();
    c.camera = &camera;
    c.clock = &clock;
    c.identifier = &identifier;
    c.stop_requested = &stop;
    c.create_session = [this]() -> Result<session::Session*> {
      session::CreateOptions create;
      create.created_utc = "2026-12-06T00:00:00Z";
      Result<session::Session> s = session::CreateSession(dir.path() + "/s", {{"plan.json", "{}"}}, "test", create);
      if (!s.ok()) return s.status();
      created.emplace(std::move(s).value());
      return &*created;
    };
    c.confirm = [this, confirm](const std::string& text, const robot::RobotIdentity& identity) {
      preview = text;
      real_hardware = identity.real_hardware;
      return confirm;
    };
    return acquisition::RunSession(plan, c, run_options);
  }

  robot::UrFakeController fake;
  std::atomic<bool> stop_fake{false};
  std::thread thread;
  testing::TempDir dir;
  std::unique_ptr<robot::UrRobot> arm;
  StubCamera camera;
  robot::MonotonicClock clock;
  acquisition::DetectionOrderIdentifier identifier;
  std::atomic<bool> stop{false};
  std::vector<acquisition::PlannedPose> plan;
  acquisition::RunOptions run_options;
  std::optional<session::Session> created;
  std::string preview;
  bool real_hardware = false;
};

TEST(UrSession, ADryRunShowsTheControllersIdentityAsRealHardwareAndSendsNoMotionCommand) {
  UrCell cell({});
  const acquisition::RunReport report = cell.Run(/*confirm=*/false);
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kRefused) << report.message;
  EXPECT_EQ(report.message, "not confirmed: nothing was sent to the arm");
  EXPECT_NE(cell.preview.find("robot ur UR5e serial 20235500001 (REAL HARDWARE)"), std::string::npos) << cell.preview;
  EXPECT_TRUE(cell.real_hardware);  // the operator types the serial before a UR moves
  EXPECT_FALSE(cell.created.has_value());
  cell.StopFake();
  EXPECT_EQ(cell.fake.motion_commands(), 0);
  EXPECT_EQ(cell.fake.stop_commands(), 0);
}

TEST(UrSession, EachFaultDuringTheFirstMoveHaltsTheRunAndNoMoveFollows) {
  struct Case {
    const char* name;
    robot::UrFakeOptions options;
    const char* halt_reason;
  };
  robot::UrFakeOptions stopped, stalled, dropped;
  stopped.protective_stop_move = 0;
  stalled.stall_move = 0;
  dropped.drop_move = 0;
  for (const Case& c : {Case{"protective stop", stopped, "protective_stop"}, Case{"stall", stalled, "move_timeout"},
                        Case{"drop", dropped, "robot_disconnected"}}) {
    UrCell cell(c.options);
    const acquisition::RunReport report = cell.Run(/*confirm=*/true);
    EXPECT_EQ(report.outcome, acquisition::RunOutcome::kHalted) << c.name << ": " << report.message;
    EXPECT_EQ(report.error, ErrorCode::kHardware) << c.name;
    EXPECT_EQ(report.halt_reason, c.halt_reason) << c.name << ": " << report.message;
    EXPECT_TRUE(report.stop_sent) << c.name;  // stopj; after a drop on a fresh connection
    // The session records the controller's identity, the factory calibration's checksums included, and
    // no move after its halt.
    ASSERT_TRUE(cell.created.has_value()) << c.name;
    const std::vector<nlohmann::json>& records = cell.created->journal().records();
    ASSERT_FALSE(records.empty());
    EXPECT_EQ(records.front()["type"], "session_started");
    EXPECT_EQ(records.front()["robot_backend"], "ur");
    EXPECT_EQ(records.front()["robot_model"], "UR5e");
    EXPECT_EQ(records.front()["robot_serial"], "20235500001");
    EXPECT_EQ(records.front()["robot_calibration"],
              "ur-kinematics-00001001-00001002-00001003-00001004-00001005-00001006");
    int moves = 0;
    for (const nlohmann::json& r : records) moves += r["type"] == "move_started" ? 1 : 0;
    EXPECT_EQ(moves, 1) << c.name;
    EXPECT_EQ(records.back()["type"], "halted") << records.back().dump();
    cell.StopFake();
    EXPECT_EQ(cell.fake.motion_commands(), 1) << c.name << ": only the first move, none after the halt";
    EXPECT_GE(cell.fake.stop_commands(), 1) << c.name;
  }
}

}  // namespace
}  // namespace selfcal
