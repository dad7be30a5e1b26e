// An arm that does not come to rest halts the session (../shared/RELIABILITY.md R7, design rule 3): a controller
// that reports 0.05 rad/s on every joint from its third move on (the simulated cell's arm behind a wrapper
// that records every command; the network backend cannot carry the simulated clock, its readings are
// stamped on CLOCK_MONOTONIC). The session halts at the first pose that does not settle, the arm is told
// to stop, the journal says why, and no further move is sent. The same through `selfcal run` with the
// simulated robot's fault: test/integration/run_safety_test.cc. And a session whose every pose was visited with too few identification samples
// for the calibration does not end as completed.
#include <atomic>
#include <vector>

#include <gtest/gtest.h>

#include "acquisition/session_runner.h"
#include "session/samples.h"
#include "simulation/sim_session_test_harness.h"

namespace selfcal::simulation {
namespace {

// The cell's arm, except that from move `restless_from` (0-based) on every joint reads 0.05 rad/s: the
// controller says the move is done, but the arm never comes to rest. Records the order of moves and stops.
class RestlessArm : public robot::Robot {
 public:
  RestlessArm(robot::Robot* arm, int restless_from) : arm_(arm), restless_from_(restless_from) {}

  Status Connect() override { return arm_->Connect(); }
  void Disconnect() override { arm_->Disconnect(); }
  Result<robot::RobotIdentity> Identity() override { return arm_->Identity(); }
  Result<robot::JointLimits> Limits() override { return arm_->Limits(); }
  Result<robot::JointReading> ReadJoints() override {
    Result<robot::JointReading> reading = arm_->ReadJoints();
    if (reading.ok() && moves_ > restless_from_) reading.value().velocity_rad_s.setConstant(0.05);
    return reading;
  }
  Status StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) override {
    ++moves_;
    events_.push_back('M');
    return arm_->StartMove(target_rad, velocity_scaling);
  }
  Result<robot::RobotStatus> GetStatus() override { return arm_->GetStatus(); }
  Status Stop() override {
    events_.push_back('S');
    return arm_->Stop();
  }

  int moves() const { return moves_; }
  const std::string& events() const { return events_; }  // 'M' per MOVE, 'S' per STOP, in order

 private:
  robot::Robot* arm_;
  int restless_from_;
  int moves_ = 0;
  std::string events_;
};

TEST(SessionSettle, AControllerThatNeverSettlesHaltsAtTheFirstUnsettledPoseAndNothingMovesAfter) {  // R7
  Harness h(8);
  RestlessArm restless(h.cell.robot.get(), 2);
  acquisition::RunContext context = h.Context();
  context.robot = &restless;
  const acquisition::RunReport report = acquisition::RunSession(h.plan, context, h.options);

  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kHalted) << report.message;
  EXPECT_EQ(report.error, ErrorCode::kHardware);  // exit 4
  EXPECT_EQ(report.halt_reason, "not_settled");
  EXPECT_TRUE(report.stop_sent);
  EXPECT_EQ(report.accepted, 2);
  EXPECT_EQ(report.skips.count("not_settled"), 0u);
  // Three MOVEs (poses 0, 1 and the one that did not settle), then the STOP; no MOVE after it.
  EXPECT_EQ(restless.moves(), 3);
  const std::string& events = restless.events();
  ASSERT_NE(events.find('S'), std::string::npos) << events;
  EXPECT_EQ(events.find('M', events.find('S')), std::string::npos) << events;
  const session::SessionLog log = h.Log();
  EXPECT_EQ(log.halts_by_reason.at("not_settled"), 1);
  EXPECT_FALSE(log.finished);
  EXPECT_TRUE(log.skips[2].empty());  // not a skip: the pose is visited again on resume
  EXPECT_EQ(log.PosesToVisit(1).front(), 2);
}

TEST(SessionSettle, TheSimulatedSlowSettleFaultHaltsWithoutAnotherMove) {  // R7
  robot::SimulatedRobotFaults f;
  f.slow_settle_moves = {1};
  SimCellOptions cell;
  cell.faults = f;
  Harness h(4, cell);
  h.options.settle.timeout_s = 1.0;
  const acquisition::RunReport report = h.Run();
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kHalted) << report.message;
  EXPECT_EQ(report.halt_reason, "not_settled");
  EXPECT_EQ(report.error, ErrorCode::kHardware);
  EXPECT_EQ(h.cell.robot->counts().start_move, 2);  // the move after the unsettled pose was never sent
  EXPECT_GE(h.cell.robot->counts().stop, 1);
  EXPECT_FALSE(h.Log().accepted[1].has_value());
}

TEST(SessionSettle, TooFewIdentificationSamplesIsNotACompletedSession) {
  robot::SimulatedRobotFaults f;
  f.reject_moves = {1};  // pose 1 skipped for good (move_failed): two of the three identification poses
  SimCellOptions cell;
  cell.faults = f;
  Harness h(5, cell);
  h.options.min_identification_samples = 3;
  const acquisition::RunReport report = h.Run();
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kTooFewSamples) << report.message;
  EXPECT_EQ(report.error, ErrorCode::kDegenerateData);  // exit 3, not 0
  EXPECT_STREQ(acquisition::RunOutcomeName(report.outcome), "too_few_samples");
  EXPECT_NE(report.message.find("2 accepted identification samples"), std::string::npos) << report.message;
  EXPECT_EQ(report.accepted, 4);
  EXPECT_TRUE(h.Log().finished);  // every pose was visited
}

}  // namespace
}  // namespace selfcal::simulation
