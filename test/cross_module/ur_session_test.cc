// The session loop (acquisition) driving the UR backend (robot/ur_robot.h) against its loopback fake
// (robot/ur_fake.h): the same safety as the network backend. A dry run shows the preview with the
// controller's identity as real hardware and sends no motion command; a protective stop, a move that never
// finishes and a dropped connection each halt the run with the robot's reason, and no movej reaches the
// controller after the halt (the fake counts them). The cell: vendor_session_cell.h.
#include <gtest/gtest.h>

#include "robot/ur_fake.h"
#include "robot/ur_robot.h"
#include "vendor_session_cell.h"

namespace selfcal {
namespace {

struct UrCell : testing::VendorCell<robot::UrFakeController> {
  explicit UrCell(const robot::UrFakeOptions& fake_options)
      : VendorCell(robot::UrFakeController::Listen(fake_options).value(), fake_options.start_rad, "ur_session") {
    const robot::UrFakeController::Ports p = fake.ports();
    robot::JointLimits limits;
    limits.lower_rad = Eigen::VectorXd::Constant(6, -6.28);
    limits.upper_rad = Eigen::VectorXd::Constant(6, 6.28);
    robot::UrRobotOptions options =
        robot::UrRunOptions("127.0.0.1", {p.rtde, p.secondary, p.dashboard}, limits).value();
    arm = std::make_unique<robot::UrRobot>("127.0.0.1", options);
  }
  acquisition::RunReport Run(bool confirm) { return VendorCell::Run(arm.get(), confirm); }
  std::unique_ptr<robot::UrRobot> arm;
};

TEST(UrSession, ADryRunShowsTheControllersIdentityAsRealHardwareAndSendsNoMotionCommand) {
  UrCell cell({});
  cell.ExpectDryRunSentNothing(cell.Run(/*confirm=*/false), "robot ur UR5e serial 20235500001 (REAL HARDWARE)");
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
    cell.ExpectHaltAfterFirstMove(cell.Run(/*confirm=*/true), c.halt_reason, c.name);  // stopj; after a drop on a fresh connection
    // The session records the controller's identity, the factory calibration's checksums included.
    if (!cell.created) continue;  // said by the check above
    const std::vector<nlohmann::json>& records = cell.created->journal().records();
    EXPECT_EQ(records.front()["type"], "session_started");
    EXPECT_EQ(records.front()["robot_backend"], "ur");
    EXPECT_EQ(records.front()["robot_model"], "UR5e");
    EXPECT_EQ(records.front()["robot_serial"], "20235500001");
    EXPECT_EQ(records.front()["robot_calibration"],
              "ur-kinematics-00001001-00001002-00001003-00001004-00001005-00001006");
  }
}

}  // namespace
}  // namespace selfcal
