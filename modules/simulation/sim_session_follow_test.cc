// --camera sim with another robot (FollowReportedJoints): every frame shows the cell's world at the joints
// that robot reports when the frame is delivered, one reading per frame, and a bad reading leaves the
// camera where the last good one put it. And a dry run (RunOptions::dry_run) opens no camera.
#include <gtest/gtest.h>

#include "simulation/sim_session.h"
#include "simulation/sim_session_test_harness.h"

namespace selfcal::simulation {
namespace {

// A robot that reports `joints` (or fails, or reads short) and counts the readings.
class ReportingRobot : public robot::Robot {
 public:
  explicit ReportingRobot(Eigen::VectorXd joints) : joints(std::move(joints)) {}
  Status Connect() override { return Status::Ok(); }
  void Disconnect() override {}
  Result<robot::RobotIdentity> Identity() override { return robot::RobotIdentity{}; }
  Result<robot::JointLimits> Limits() override { return robot::JointLimits{}; }
  Result<robot::JointReading> ReadJoints() override {
    ++readings;
    if (fail) return robot::RobotFailure(robot::RobotError::kDisconnected, "gone");
    robot::JointReading r;
    r.position_rad = short_reading ? joints.head(2) : joints;
    r.velocity_rad_s = Eigen::VectorXd::Zero(r.position_rad.size());
    return r;
  }
  Status StartMove(const Eigen::VectorXd&, double) override { return Status::Ok(); }
  Result<robot::RobotStatus> GetStatus() override { return robot::RobotStatus{}; }
  Status Stop() override { return Status::Ok(); }

  Eigen::VectorXd joints;
  int readings = 0;
  bool fail = false;
  bool short_reading = false;
};

// The largest distance between the dots of the camera's last frame and the dots the true arm's camera
// sees at `joints`.
double OffsetFrom(const SimCell& cell, const Eigen::VectorXd& joints) {
  const sim::SimTruth& truth = cell.world->truth;
  const Rigid3 cam_from_base = BaseFromCam(truth.nominal, truth.rho_true, joints).Inverse();
  double worst = 0;
  int seen = 0;
  for (const sim::RenderedDot& d : cell.camera->last_render().dots) {
    if (!d.visible) continue;
    const auto uv = Project(truth.camera_true, cam_from_base * truth.dots_in_base[d.id]);
    worst = std::max(worst, (*uv - d.projected_centre_px).norm());
    ++seen;
  }
  EXPECT_GT(seen, 8);
  return worst;
}

TEST(FollowReportedJoints, EachFrameShowsTheJointsTheRobotReports) {
  Harness h(4);
  const Eigen::VectorXd first = h.plan[0].joints_rad, second = h.plan[1].joints_rad;
  ReportingRobot arm(second);
  FollowReportedJoints(&h.cell, SimCellOptions(), &arm, first);
  EXPECT_EQ(h.cell.robot, nullptr);  // the cell's own arm is gone: nothing can drive it by mistake
  ASSERT_TRUE(h.cell.camera->Open().ok());
  ASSERT_TRUE(h.cell.camera->Grab(-1e300, 1.0).ok());
  EXPECT_EQ(arm.readings, 1);
  EXPECT_LT(OffsetFrom(h.cell, second), 1e-9);
  EXPECT_GT(OffsetFrom(h.cell, first), 10.0);  // the two poses are told apart
  arm.joints = first;
  ASSERT_TRUE(h.cell.camera->Grab(-1e300, 1.0).ok());
  EXPECT_EQ(arm.readings, 2);
  EXPECT_LT(OffsetFrom(h.cell, first), 1e-9);
  // A failed and a short reading: the camera stays where the last good reading put it.
  arm.joints = second;
  arm.fail = true;
  ASSERT_TRUE(h.cell.camera->Grab(-1e300, 1.0).ok());
  EXPECT_LT(OffsetFrom(h.cell, first), 1e-9);
  arm.fail = false;
  arm.short_reading = true;
  ASSERT_TRUE(h.cell.camera->Grab(-1e300, 1.0).ok());
  EXPECT_LT(OffsetFrom(h.cell, first), 1e-9);
  EXPECT_EQ(arm.readings, 4);
  EXPECT_NE(h.cell.camera->Describe().find("real time"), std::string::npos);  // the monotonic clock of live backends
}

// A camera that is not there: Open fails, and counts.
class AbsentCamera : public capture::FrameSource {
 public:
  std::string Describe() const override { return "absent camera"; }
  Status Open() override {
    ++opens;
    return Status::Error(ErrorCode::kHardware, "no such device");
  }
  Result<capture::Frame> Grab(double, double) override { return Status::Error(ErrorCode::kHardware, "closed"); }
  void Close() override {}
  int opens = 0;
};

TEST(FollowReportedJoints, ADryRunNeedsNoCameraAndIsNeverArmed) {
  Harness h(5);
  AbsentCamera absent;
  acquisition::RunContext c = h.Context();
  c.camera = &absent;
  h.options.dry_run = true;
  std::string shown;
  c.confirm = [&](const std::string& preview, const robot::RobotIdentity&) {
    shown = preview;
    return true;  // even a yes does not arm a dry run
  };
  const acquisition::RunReport report = acquisition::RunSession(h.plan, c, h.options);
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kRefused) << report.message;
  EXPECT_EQ(absent.opens, 0);
  EXPECT_NE(shown.find("5 moves"), std::string::npos) << shown;
  EXPECT_EQ(h.cell.robot->counts().start_move, 0);
  EXPECT_EQ(h.cell.robot->counts().stop, 0);
  EXPECT_TRUE(h.session->journal().records().empty());
}

}  // namespace
}  // namespace selfcal::simulation
