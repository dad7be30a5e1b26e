// The session loop on the simulated cell: a clean session against the hidden truth (identities through
// tracking alone), every fault of ../shared/RELIABILITY.md R2-R11 and V3-V6 triggered with its halt, skip or refusal
// and its count, no motion command in a dry run (F8), and a stopped session resumed to the same samples.
#include "acquisition/session_runner.h"

#include <atomic>
#include <cmath>

#include <gtest/gtest.h>

#include "capture/faulty_frame_source.h"
#include "simulation/sim_session.h"
#include "simulation/sim_session_test_harness.h"
#include "session/samples.h"
#include "sim/trajectory_generator.h"
#include "support/temp_files.h"
#include "support/test_robots.h"

namespace selfcal::simulation {
namespace {

// Every accepted dot's pixel against the truth: the true dot projected by the true camera from the true
// arm at the frame's exposure. An identity swap would be off by a dot spacing (> 10 px here).
double WorstDotError(Harness& h, const session::SessionLog& log, int* dots) {
  double worst = 0;
  *dots = 0;
  const sim::SimTruth& truth = h.cell.world->truth;
  for (const auto& sample : log.accepted) {
    if (!sample) continue;
    const Rigid3 cam_from_base =
        BaseFromCam(truth.nominal, truth.rho_true, h.cell.robot->JointsAt(sample->exposure_time_s)).Inverse();
    for (const session::SampleDot& d : sample->dots) {
      const auto uv = Project(truth.camera_true, cam_from_base * truth.dots_in_base[d.id]);
      worst = std::max(worst, (*uv - Eigen::Vector2d(d.u_px, d.v_px)).norm());
      ++*dots;
    }
  }
  return worst;
}

TEST(SessionRunner, CleanSessionTracksEveryIdentityThroughTheMotion) {
  Harness h(25);
  const acquisition::RunReport report = h.Run();
  ASSERT_EQ(report.outcome, acquisition::RunOutcome::kCompleted) << report.message;
  EXPECT_EQ(report.error, ErrorCode::kOk);
  EXPECT_EQ(report.accepted, 25);
  const session::SessionLog log = h.Log();
  EXPECT_TRUE(log.finished);
  EXPECT_EQ(log.NumAccepted(), 25);
  int dots = 0;
  const double worst = WorstDotError(h, log, &dots);
  std::printf("clean session: %d dots in 25 samples (%.1f per sample), worst error vs truth %.3f px, %d frames "
              "grabbed, %d tracked\n",
              dots, dots / 25.0, worst, report.frames_grabbed, report.frames_tracked);
  for (const auto& [kind, n] : report.faults) std::printf("  %s: %d\n", kind.c_str(), n);
  EXPECT_LT(worst, 0.5);       // grey noise 2: centroids ~0.01 px, ellipse bias < 0.04 px; a swap is > 10 px
  // Dots that cross another during a move merge and are dropped for good (never a stale or swapped id):
  // in this deep random scene 30 of 80 survive the 24 moves (measured; deterministic).
  EXPECT_GE(dots, 800);
  for (const auto& sample : log.accepted) {  // freshness invariant (design rule 4)
    ASSERT_TRUE(sample.has_value());
    EXPECT_GT(sample->exposure_time_s, sample->settle_time_s);
    EXPECT_GE(sample->joint_time_s, sample->settle_time_s);
  }
  EXPECT_TRUE(session::VerifySampleImages(*h.session, log).ok());
}

TEST(SessionRunner, DryRunSendsNoMotionCommand) {  // F8 (a), R1, R12
  Harness h(5);
  h.confirm = false;
  const acquisition::RunReport report = h.Run();
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kRefused);
  EXPECT_EQ(report.error, ErrorCode::kInvalidInput);  // exit 2, not 130: nobody pressed Ctrl-C
  EXPECT_NE(report.message.find("nothing was sent to the arm"), std::string::npos) << report.message;
  EXPECT_NE(report.preview.find("5 moves"), std::string::npos) << report.preview;
  EXPECT_EQ(h.cell.robot->counts().start_move, 0);
  EXPECT_EQ(h.cell.robot->counts().stop, 0);
  EXPECT_TRUE(h.session->journal().records().empty());  // nothing recorded: nothing happened
}

TEST(SessionRunner, PreflightRefusesExcessiveTravelBeforeAnyCommand) {  // R2, F8 (b)
  Harness h(5);
  h.plan[3].joints_rad[0] += 1.9;  // ~109 deg more on joint 1 than its neighbours
  h.plan[3].joints_rad[0] = std::min(h.plan[3].joints_rad[0], 2.7);
  const acquisition::RunReport report = h.Run();
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kRefused);
  EXPECT_NE(report.message.find("pose p03"), std::string::npos) << report.message;
  EXPECT_NE(report.message.find("joint_travel"), std::string::npos) << report.message;
  EXPECT_EQ(h.cell.robot->counts().start_move, 0);
}

TEST(SessionRunner, PreflightRefusesAPoseOutsideTheLimits) {  // C6
  Harness h(5);
  h.plan[2].joints_rad[4] = 3.0;  // joint 5 of the PUMA stops at 100 deg
  const acquisition::RunReport report = h.Run();
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kRefused);
  EXPECT_NE(report.message.find("pose p02 joint 5"), std::string::npos) << report.message;
  EXPECT_EQ(h.cell.robot->counts().start_move, 0);
}

SimCellOptions WithFaults(robot::SimulatedRobotFaults faults) {
  SimCellOptions o;
  o.faults = std::move(faults);
  return o;
}

TEST(SessionRunner, RejectedMoveSkipsThePoseAndGoesOn) {  // R5
  robot::SimulatedRobotFaults f;
  f.reject_moves = {2};
  Harness h(5, WithFaults(f));
  const acquisition::RunReport report = h.Run();
  ASSERT_EQ(report.outcome, acquisition::RunOutcome::kCompleted) << report.message;
  EXPECT_EQ(report.skips.at("move_failed"), 1);
  EXPECT_EQ(report.faults.at("move_rejected"), 1);
  EXPECT_EQ(report.accepted, 4);
  const session::SessionLog log = h.Log();
  EXPECT_EQ(log.skips_by_reason.at("move_failed"), 1);
  EXPECT_FALSE(log.accepted[2].has_value());
}

TEST(SessionRunner, HangingMoveTripsTheWatchdogAndHalts) {  // R6
  robot::SimulatedRobotFaults f;
  f.hang_moves = {2};
  Harness h(5, WithFaults(f));
  const acquisition::RunReport report = h.Run();
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kHalted);
  EXPECT_EQ(report.error, ErrorCode::kHardware);
  EXPECT_EQ(report.halt_reason, "move_timeout");
  EXPECT_GE(h.cell.robot->counts().stop, 1);
  EXPECT_EQ(h.cell.robot->counts().start_move, 3);  // never re-sent
  EXPECT_EQ(h.Log().halts_by_reason.at("move_timeout"), 1);
}

TEST(SessionRunner, ProtectiveStopHaltsAndNothingIsResent) {  // R9
  robot::SimulatedRobotFaults f;
  f.protective_stop_moves = {2};
  Harness h(5, WithFaults(f));
  const acquisition::RunReport report = h.Run();
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kHalted);
  EXPECT_EQ(report.halt_reason, "protective_stop");
  EXPECT_EQ(h.cell.robot->counts().start_move, 3);
  EXPECT_EQ(report.accepted, 2);
}

TEST(SessionRunner, LostConnectionHalts) {  // R10
  robot::SimulatedRobotFaults f;
  f.disconnect_moves = {1};
  Harness h(5, WithFaults(f));
  const acquisition::RunReport report = h.Run();
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kHalted);
  EXPECT_EQ(report.halt_reason, "robot_disconnected");
  EXPECT_EQ(report.error, ErrorCode::kHardware);
}

TEST(SessionRunner, JoggedArmIsCaughtBeforeTheNextMove) {  // R4
  robot::SimulatedRobotFaults f;
  f.jog_after_moves = {1};
  f.jog_delay_s = 0.1;
  Harness h(5, WithFaults(f));
  const acquisition::RunReport report = h.Run();
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kHalted);
  EXPECT_EQ(report.halt_reason, "start_state_mismatch");
  EXPECT_EQ(report.faults.at("start_state_mismatch"), 1);
  EXPECT_EQ(h.cell.robot->counts().start_move, 2);  // the move after the jog was never sent
}

// An arm that does not settle halts the session: sim_session_settle_test.cc.

TEST(SessionRunner, BadJointReadingsAreRetriedAndCounted) {  // R8
  robot::SimulatedRobotFaults f;
  f.stale_reads = {3};
  f.nan_reads = {6};
  f.short_reads = {9};
  Harness h(4, WithFaults(f));
  const acquisition::RunReport report = h.Run();
  ASSERT_EQ(report.outcome, acquisition::RunOutcome::kCompleted) << report.message;
  EXPECT_EQ(report.faults.at("stale_reading") + report.faults.at("nan_reading") + report.faults.at("short_reading"), 3);
  EXPECT_EQ(report.accepted, 4);
  EXPECT_EQ(h.Log().faults_by_kind.at("nan_reading"), 1);
}

TEST(SessionRunner, StopRequestHaltsWithTheInterruptedCode) {  // R11
  Harness h(5);
  h.Context();
  int lines = 0;
  acquisition::RunContext c = h.Context();
  c.log = [&](const std::string&) {
    if (++lines == 4) h.stop = true;  // the operator presses Ctrl-C after the first sample
  };
  const acquisition::RunReport report = acquisition::RunSession(h.plan, c, h.options);
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kInterrupted);
  EXPECT_EQ(report.error, ErrorCode::kInterrupted);
  EXPECT_GE(h.cell.robot->counts().stop, 1);
  EXPECT_EQ(h.Log().halts_by_reason.at("interrupted"), 1);
}

TEST(SessionRunner, CameraTimeoutIsRetriedThenHalts) {  // V3
  capture::FrameFaults once;
  once.timeouts = {0};
  Harness h1(4, SimCellOptions(), once);
  const acquisition::RunReport r1 = h1.Run();
  ASSERT_EQ(r1.outcome, acquisition::RunOutcome::kCompleted) << r1.message;
  EXPECT_EQ(r1.faults.at("frame_timeout"), 1);
  capture::FrameFaults silent;
  silent.timeouts = {0, 1, 2, 3};
  Harness h2(4, SimCellOptions(), silent);
  const acquisition::RunReport r2 = h2.Run();
  EXPECT_EQ(r2.outcome, acquisition::RunOutcome::kHalted);
  EXPECT_EQ(r2.halt_reason, "camera_timeout");
  EXPECT_EQ(r2.faults.at("frame_timeout"), 4);
}

TEST(SessionRunner, UnpluggedCameraHalts) {  // V4
  capture::FrameFaults f;
  f.disconnects = {0};
  Harness h(4, SimCellOptions(), f);
  const acquisition::RunReport report = h.Run();
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kHalted);
  EXPECT_EQ(report.halt_reason, "camera_disconnected");
  EXPECT_GE(h.cell.robot->counts().stop, 1);
}

TEST(SessionRunner, StaleFrameIsNeverAccepted) {  // V5
  capture::FrameFaults f;
  f.stale_frames = {0};
  Harness h(4, SimCellOptions(), f);
  const acquisition::RunReport report = h.Run();
  ASSERT_EQ(report.outcome, acquisition::RunOutcome::kCompleted) << report.message;
  EXPECT_EQ(report.faults.at("stale_frame"), 1);
  const session::SessionLog log = h.Log();
  ASSERT_TRUE(log.accepted[0].has_value());
  EXPECT_GT(log.accepted[0]->exposure_time_s, log.accepted[0]->settle_time_s);
}

TEST(SessionRunner, BadFramesAreRetriedThenThePoseIsSkipped) {  // V6
  capture::FrameFaults f;
  f.bad_frames = {0, 1, 2, 3};
  Harness h(4, SimCellOptions(), f);
  const acquisition::RunReport report = h.Run();
  // Every pose visited, but one identification sample of two is too few to calibrate: not "completed".
  ASSERT_EQ(report.outcome, acquisition::RunOutcome::kTooFewSamples) << report.message;
  EXPECT_EQ(report.error, ErrorCode::kDegenerateData);
  EXPECT_EQ(report.faults.at("bad_frame"), 4);
  EXPECT_EQ(report.skips.at("bad_frame"), 1);
  EXPECT_FALSE(h.Log().accepted[0].has_value());
  EXPECT_EQ(report.accepted, 3);
}

}  // namespace
}  // namespace selfcal::simulation

namespace selfcal::simulation {
namespace {

// A stand-in for a real robot backend (real_hardware = true) that records every command (R12, F8 (a)).
class RecordingRealRobot : public robot::Robot {
 public:
  explicit RecordingRealRobot(Eigen::VectorXd joints) : joints_(std::move(joints)) {}
  Status Connect() override { return Status::Ok(); }
  void Disconnect() override {}
  Result<robot::RobotIdentity> Identity() override { return robot::RobotIdentity{"network", "puma560", "SN-1", "", true}; }
  Result<robot::JointLimits> Limits() override {
    const int n = static_cast<int>(joints_.size());
    return robot::JointLimits{Eigen::VectorXd::Constant(n, -4.0), Eigen::VectorXd::Constant(n, 4.0),
                              Eigen::VectorXd::Constant(n, 1.0)};
  }
  Result<robot::JointReading> ReadJoints() override {
    return robot::JointReading{joints_, Eigen::VectorXd::Zero(joints_.size()), 0.0};
  }
  Status StartMove(const Eigen::VectorXd&, double) override {
    ++motion_commands;
    return Status::Ok();
  }
  Result<robot::RobotStatus> GetStatus() override { return robot::RobotStatus{}; }
  Status Stop() override {
    ++motion_commands;
    return Status::Ok();
  }
  int motion_commands = 0;

 private:
  Eigen::VectorXd joints_;
};

TEST(SessionRunner, DryRunOnARealBackendSendsItNoMotionCommand) {  // R12, F8 (a)
  Harness h(5);
  RecordingRealRobot real(h.plan.front().joints_rad);
  acquisition::RunContext c = h.Context();
  c.robot = &real;
  bool saw_real = false;
  c.confirm = [&](const std::string& preview, const robot::RobotIdentity& identity) {
    saw_real = identity.real_hardware && preview.find("REAL HARDWARE") != std::string::npos;
    return false;  // --dry-run: preview only
  };
  const acquisition::RunReport report = acquisition::RunSession(h.plan, c, h.options);
  EXPECT_TRUE(saw_real);
  EXPECT_EQ(report.outcome, acquisition::RunOutcome::kRefused);
  EXPECT_EQ(real.motion_commands, 0);
  EXPECT_EQ(h.cell.robot->counts().start_move, 0);  // nor to the simulated one
}

// The times of `pose` (move #pose): the arm's true arrival (the robot's, before the loop sees it idle),
// the journaled settle and the accepted frame's exposure.
struct PoseTimes {
  double arrival_s = 0, settle_s = 0, exposure_s = 0;
};
PoseTimes TimesOf(Harness& h, int pose) {
  PoseTimes t;
  double started_s = 0;
  for (const nlohmann::json& r : h.session->journal().records()) {
    if (r.value("pose", -1) != pose) continue;
    if (r["type"] == "move_started") started_s = r["time_s"];
    if (r["type"] == "settled") t.settle_s = r["time_s"];
    if (r["type"] == "frame_written") t.exposure_s = r["exposure_time_s"];
  }
  for (const robot::AcceptedMove& move : h.cell.robot->accepted_moves()) {
    if (move.command_time_s >= started_s) return t.arrival_s = move.start_time_s + move.duration_s, t;
  }
  return t;
}

// A person's --resume: a new cell at rest where the last accepted sample was taken, its clock at the
// journaled time, with `faults` (counted afresh), revisiting skipped poses at most `revisit` times.
acquisition::RunReport Resume(Harness& h, const robot::SimulatedRobotFaults& faults, int revisit) {
  const session::SessionLog log = h.Log();
  const session::AcceptedSample* last = log.LastAcceptedSample();
  EXPECT_NE(last, nullptr);
  SimCellOptions options;
  options.camera.render.supersampling = 4;
  options.camera.render.noise_std_grey = 2;
  options.faults = faults;
  Result<SimCell> restarted =
      MakeSimCell(testing::Puma560(), h.plan, options, h.plan[last->pose].joints_rad, last->sim_clock_s.value());
  EXPECT_TRUE(restarted.ok());
  h.cell = std::move(restarted).value();
  h.camera = std::make_unique<capture::FaultyFrameSource>(h.cell.camera.get(), capture::FrameFaults());
  h.options.revisit_skipped = revisit;
  return h.Run();
}

// A stopped session continued by a second RunSession (a person's --resume) on a cell rebuilt where the
// last accepted sample left the arm gives the very samples an uninterrupted session gives (P3, F4).
TEST(SessionRunner, ResumedSessionEqualsTheUninterruptedOne) {
  Harness clean(8);
  ASSERT_EQ(clean.Run().outcome, acquisition::RunOutcome::kCompleted);
  Harness h(8);
  int lines = 0;
  acquisition::RunContext c = h.Context();
  c.log = [&](const std::string&) {
    if (++lines == 7) h.stop = true;
  };
  ASSERT_EQ(acquisition::RunSession(h.plan, c, h.options).outcome, acquisition::RunOutcome::kInterrupted);
  const session::SessionLog stopped = h.Log();
  const session::AcceptedSample* last = stopped.LastAcceptedSample();
  ASSERT_NE(last, nullptr);
  // The restart: a new cell at rest at the last sample's target, the clock at its journaled time.
  h.stop = false;
  const acquisition::RunReport resumed = Resume(h, robot::SimulatedRobotFaults(), h.options.revisit_skipped);
  ASSERT_EQ(resumed.outcome, acquisition::RunOutcome::kCompleted) << resumed.message;
  EXPECT_EQ(resumed.first_pose, last->pose + 1);
  const session::SessionLog a = clean.Log(), b = h.Log();
  ASSERT_EQ(a.NumAccepted(), b.NumAccepted());
  for (size_t p = 0; p < a.accepted.size(); ++p) {
    ASSERT_TRUE(a.accepted[p] && b.accepted[p]);
    ASSERT_EQ(a.accepted[p]->dots.size(), b.accepted[p]->dots.size()) << "pose " << p;
    for (size_t k = 0; k < a.accepted[p]->dots.size(); ++k) {
      EXPECT_EQ(a.accepted[p]->dots[k].id, b.accepted[p]->dots[k].id);
      EXPECT_EQ(a.accepted[p]->dots[k].u_px, b.accepted[p]->dots[k].u_px);
      EXPECT_EQ(a.accepted[p]->dots[k].v_px, b.accepted[p]->dots[k].v_px);
    }
    EXPECT_EQ(a.accepted[p]->joints_rad, b.accepted[p]->joints_rad);
  }
}

}  // namespace
}  // namespace selfcal::simulation

namespace selfcal::simulation {
namespace {

// R4 between settle and capture: pose 3 is jogged after the session saw it settle and before its frame,
// so the joints read with the frame differ from the settled ones and the pose is skipped
// (moved_after_settle); the next move is refused because the arm is not where the plan left it.
robot::SimulatedRobotFaults JogBetweenSettleAndCapture(int move, const PoseTimes& clean) {
  robot::SimulatedRobotFaults f;
  f.jog_after_moves = {move};
  f.jog_delay_s = 0.5 * (clean.settle_s + clean.exposure_s) - clean.arrival_s;
  f.jog_offset_rad = Eigen::VectorXd::Zero(6);
  f.jog_offset_rad[0] = 0.15;  // enough to lose most tracked dots (0.1 rad is not, at this seed)
  return f;
}

// A clean run of 8 poses (the times of pose 3) and the cell options that jog the arm at pose 3.
struct JoggedAtPose3 {
  JoggedAtPose3() {
    EXPECT_EQ(clean.Run().outcome, acquisition::RunOutcome::kCompleted);
    times = TimesOf(clean, 3);
    options.faults = JogBetweenSettleAndCapture(3, times);
  }
  Harness clean{8};
  PoseTimes times;
  SimCellOptions options;
};

TEST(SessionRunner, JogBetweenSettleAndCaptureThenResumeRevisitsTheSkippedPose) {  // R4, issue 12 item 6
  JoggedAtPose3 jog;
  Harness& clean = jog.clean;
  const PoseTimes& times = jog.times;
  Harness h(8, jog.options);
  const acquisition::RunReport first = h.Run();
  EXPECT_EQ(first.halt_reason, "start_state_mismatch") << first.message;
  // The jog came after the settle and before the exposure (the times are those of the clean run).
  const PoseTimes seen = TimesOf(h, 3);
  EXPECT_EQ(seen.settle_s, times.settle_s);
  EXPECT_NEAR((h.cell.robot->JointsAt(seen.settle_s + 1e-3) - h.cell.robot->JointsAt(seen.settle_s - 1e-3)).norm(),
              0, 1e-9);
  EXPECT_NEAR((h.cell.robot->JointsAt(times.exposure_s) - h.cell.robot->JointsAt(times.settle_s)).norm(), 0.15, 1e-9);
  session::SessionLog log = h.Log();
  ASSERT_EQ(log.skips[3].size(), 1u);
  EXPECT_EQ(log.skips[3][0].reason, "moved_after_settle");

  const acquisition::RunReport resumed = Resume(h, robot::SimulatedRobotFaults(), 1);
  ASSERT_EQ(resumed.outcome, acquisition::RunOutcome::kCompleted) << resumed.message;
  EXPECT_EQ(resumed.first_pose, 3);
  log = h.Log();
  EXPECT_EQ(log.NumAccepted(), 8);
  EXPECT_EQ(log.SkippedThenAccepted(), 1);
  EXPECT_EQ(log.skips_by_reason.at("moved_after_settle"), 1);  // the skip record stays; the pose counts as accepted
  ASSERT_TRUE(log.accepted[3]);
  EXPECT_GE(log.accepted[3]->dots.size(), clean.Log().accepted[3]->dots.size() * 9 / 10);
  // Every dot of the revisited sample against the truth, on the restarted arm's history (a swap: > 10 px).
  const sim::SimTruth& truth = h.cell.world->truth;
  const Rigid3 cam_from_base =
      BaseFromCam(truth.nominal, truth.rho_true, h.cell.robot->JointsAt(log.accepted[3]->exposure_time_s)).Inverse();
  for (const session::SampleDot& d : log.accepted[3]->dots) {
    const auto uv = Project(truth.camera_true, cam_from_base * truth.dots_in_base[d.id]);
    EXPECT_LT((*uv - Eigen::Vector2d(d.u_px, d.v_px)).norm(), 1.0) << "dot " << d.id;
  }
}

TEST(SessionRunner, RevisitsOfSkippedPosesStayWithinTheOperatorsBound) {  // issue 12 item 6
  JoggedAtPose3 jog;
  Harness h(8, jog.options);
  h.Run();
  // 0: today's rule, the skip is final.
  acquisition::RunReport r = Resume(h, robot::SimulatedRobotFaults(), 0);
  ASSERT_EQ(r.outcome, acquisition::RunOutcome::kCompleted) << r.message;
  EXPECT_EQ(r.first_pose, 4);
  EXPECT_FALSE(h.Log().accepted[3]);
  // 1: one more attempt, from the accepted pose before it (p02); without the jog it is accepted.
  r = Resume(h, robot::SimulatedRobotFaults(), 1);
  ASSERT_EQ(r.outcome, acquisition::RunOutcome::kCompleted) << r.message;
  EXPECT_EQ(r.first_pose, 3);
  EXPECT_TRUE(h.Log().accepted[3]);
  EXPECT_EQ(h.Log().NumAccepted(), 8);
  EXPECT_EQ(h.Log().SkippedThenAccepted(), 1);
  // Nothing is left to visit (the spent bound itself: session's samples_test, PosesToVisit).
  r = Resume(h, robot::SimulatedRobotFaults(), 1);
  EXPECT_EQ(r.outcome, acquisition::RunOutcome::kCompleted);
  EXPECT_EQ(r.message, "every pose of the session is done");
  EXPECT_EQ(h.cell.robot->counts().start_move, 0);
}

}  // namespace
}  // namespace selfcal::simulation
