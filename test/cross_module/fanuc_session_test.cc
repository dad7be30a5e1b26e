// The session loop (acquisition) driving the FANUC backend (robot/fanuc_robot.h) against its loopback fake
// (robot/fanuc_fake.h): the same safety as the network and UR backends. A dry run shows the preview with the
// controller's identity as real hardware and sends no instruction; the servos off, a move that never
// finishes, a dropped connection and a wrong answer each halt the run with the robot's reason, FRC_Abort is
// sent, and no instruction reaches the controller after the halt (the fake counts them).
#include <gtest/gtest.h>

#include "robot/fanuc_fake.h"
#include "robot/fanuc_robot.h"
#include "vendor_session_cell.h"

namespace selfcal {
namespace {

struct FanucCell : testing::VendorCell<robot::FanucFakeController> {
  explicit FanucCell(const robot::FanucFakeOptions& options)
      : VendorCell(robot::FanucFakeController::Listen(options).value(), options.start_rad, "fanuc_session") {
    robot::JointLimits limits;
    limits.lower_rad = Eigen::VectorXd::Constant(6, -3.0);
    limits.upper_rad = Eigen::VectorXd::Constant(6, 3.0);
    std::string host;
    const std::string address = "127.0.0.1:" + std::to_string(fake.connect_port());
    arm = std::make_unique<robot::FanucRobot>("127.0.0.1", robot::FanucRunOptions(address, limits, &host).value());
  }
  acquisition::RunReport Run(bool confirm) { return VendorCell::Run(arm.get(), confirm); }
  std::unique_ptr<robot::FanucRobot> arm;
};

TEST(FanucSession, ADryRunShowsTheControllersIdentityAsRealHardwareAndSendsNoInstruction) {
  FanucCell cell({});
  const std::string serial = "127.0.0.1:" + std::to_string(cell.fake.connect_port());
  cell.ExpectDryRunSentNothing(cell.Run(/*confirm=*/false), "robot fanuc FANUC RMI 1.0 serial " + serial + " (REAL HARDWARE)");
}

TEST(FanucSession, EachFaultDuringTheFirstMoveHaltsTheRunAndNoMoveFollows) {
  struct Case {
    const char* name;
    robot::FanucFakeOptions options;
    const char* halt_reason;
  };
  robot::FanucFakeOptions servo_off, stalled, dropped, wrong;
  servo_off.servo_off_move = 0;
  stalled.stall_move = 0;
  dropped.drop_move = 0;
  wrong.wrong_answer_move = 0;
  for (const Case& c : {Case{"servo off", servo_off, "fault"}, Case{"stall", stalled, "move_timeout"},
                        Case{"drop", dropped, "robot_disconnected"}, Case{"wrong answer", wrong, "robot_protocol"}}) {
    FanucCell cell(c.options);
    cell.ExpectHaltAfterFirstMove(cell.Run(/*confirm=*/true), c.halt_reason, c.name);
    // The session records the controller's identity.
    if (!cell.created) continue;  // said by the check above
    const std::vector<nlohmann::json>& records = cell.created->journal().records();
    EXPECT_EQ(records.front()["robot_backend"], "fanuc");
    EXPECT_EQ(records.front()["robot_model"], "FANUC RMI 1.0");
  }
}

}  // namespace
}  // namespace selfcal
