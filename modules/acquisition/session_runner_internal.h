// Internal to acquisition: the state of one RunSession invocation and its steps, shared by
// session_runner.cc (the run from the journal to the first move, and the loop over the route) and
// session_pose.cc (one pose: move with the watchdog while tracking, settle, capture, name the dots,
// record). Not part of the module's contract (session_runner.h is).
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "acquisition/session_runner.h"
#include "session/samples.h"

namespace selfcal::acquisition::internal {

nlohmann::json ToJson(const Eigen::VectorXd& v);
// The "dots" array of a sample record: [{"id", "u", "v", "area", "w", "h"}].
nlohmann::json DotsJson(const std::vector<tracking::PreviousDot>& dots);
const char* RoleName(PoseRole role);

// The robot as it answered before anything moved.
struct RobotAtStart {
  robot::RobotIdentity identity;
  robot::JointReading joints;  // where the arm is
};

// The poses this invocation visits: back to the last accepted sample's pose if the arm left it (resume),
// then the plan from the resume point; accepted poses between revisited ones are passed, not recorded.
struct Route {
  std::vector<PlannedPose> poses;
  std::vector<int> plan_index;  // plan index per route entry; the return move has the sample's pose
  std::vector<bool> pass;       // per route entry: visited without recording (the return, an accepted pose)
  bool returning = false;       // poses[0] is the return move
};

// A pose reached and settled.
struct Arrival {
  double arrival_s = 0;  // the controller said the move was done
  double settle_s = 0;   // the velocities were below the threshold long enough
  robot::JointReading settled;
};

// What a settled pose gave: a frame exposed after settling and a fresh joint reading.
struct Capture {
  capture::Frame frame;
  robot::JointReading joints;
};

// A frame grabbed after settling, kept until the pose is recorded or skipped (then written to
// images/rejected/ with its reason: empty for the capture, which takes the skip's).
struct RejectedFrame {
  capture::Frame frame;
  std::string reason;
};

// One invocation of the loop: the state shared by its steps.
class Runner {
 public:
  Runner(const std::vector<PlannedPose>& plan, const RunContext& c, const RunOptions& o)
      : plan_(plan), c_(c), o_(o) {}

  RunReport Run();

 private:
  // A step either succeeds, asks to skip the pose (reason), or ends the run (report_ already set).
  enum class Step { kOk, kSkip, kEnd };

  void Log(const std::string& line) {
    if (c_.log) c_.log(line);
  }
  bool StopRequested() const { return c_.stop_requested != nullptr && c_.stop_requested->load(); }
  double Now() { return c_.clock->Now(); }

  // The journal records of the session to continue: the open session's, or a dry run's snapshot's.
  const std::vector<nlohmann::json>& Records() const;
  const std::string& SessionPath() const;
  bool Resuming() const { return c_.session != nullptr || c_.dry_run_of != nullptr; }
  // Every pose visited: kCompleted with `message`, or kTooFewSamples when the session holds fewer
  // identification samples than RunOptions::min_identification_samples.
  void Conclude(const std::string& message);

  // Appends a record; a failure ends the run (kSessionError, P5) after stopping the robot.
  bool Record(nlohmann::json record);
  // Ends the run in `outcome` after telling the robot to stop and journaling why (never resumes, R9).
  Step Halt(RunOutcome outcome, ErrorCode code, const std::string& reason, const std::string& detail, int pose);
  Step Fault(const std::string& kind, int pose, const std::string& detail);
  void Skip(int pose, const std::string& reason, const std::string& detail);
  Step HaltOnRobotError(const Status& status, int pose, const std::string& what);

  // Before the first move (session_runner.cc); each returns false when the run ends there, report_ set.
  // C9 (the journal's plan is this one) and the poses to visit *todo (in plan order: the resume point
  // and the revisits); also false when every pose is done.
  bool StartFromJournal(const session::SessionLog& log, std::vector<int>* todo);
  // Connect, identity and limits (limits_), R13 (the robot the session started with), where the arm is.
  bool ConnectRobot(const session::SessionLog& log, RobotAtStart* robot);
  // Sets the tracker's state from the accepted sample the route starts from when resuming.
  Route PlanRoute(const session::SessionLog& log, const std::vector<int>& todo, const Eigen::VectorXd& now_rad);
  // V1 (the camera works), preflight of the whole route, the preview and the operator's confirmation.
  bool Arm(const Route& route, const RobotAtStart& robot);
  // The return move to the route's starting sample (its dots found again at its joints; R4).
  Step ReturnTo(const PlannedPose& target, int pose, Eigen::VectorXd* expected);
  // A new session made through create_session (c_.session set), after the confirmation.
  bool CreateSession();
  // The start (or the resumption) and the plan's poses, journaled before the first command.
  bool JournalStart(const session::SessionLog& log, const std::vector<int>& todo,
                    const robot::RobotIdentity& identity);

  // One pose of the route (session_pose.cc): kEnd when the run ends there, else the next pose follows
  // (the pose was recorded, skipped, or was the return move).
  Step VisitPose(const PlannedPose& target, int pose, bool is_return, Eigen::VectorXd* expected);
  // A stop request, free space (P5), a valid reading and R4 (the arm is where the last move left it).
  Step CheckBeforeMove(int pose, const Eigen::VectorXd& expected, robot::JointReading* before);
  // The move, then settling; *expected becomes the target once the move is done (R4).
  Step MoveAndSettle(int pose, const robot::JointReading& before, const PlannedPose& target,
                     Eigen::VectorXd* expected, Arrival* arrival);
  // A frame exposed strictly after settling, then a joint reading stamped after it.
  Step CaptureAtPose(int pose, double settle_s, Capture* capture);
  // The frame's dots named (tracked or identified), marked ones found again; kEnd when none is left.
  Step NameDots(int pose, const Capture& capture);
  // min_dots (D1), then the image (atomic) and the records naming it (P1).
  Step RecordSample(int pose, const PlannedPose& target, const Arrival& arrival, const Capture& capture);

  // A complete, finite, in-limits reading stamped at or after `after_s` (R8), retried; kSkip when none.
  Step ReadJoints(int pose, double after_s, robot::JointReading* reading);
  // Moves from `from` (read just before, R4) to `target` and waits for arrival, tracking dots on the way
  // (R5, R6, R9, R10, R11).
  Step Move(int pose, const robot::JointReading& from, const Eigen::VectorXd& target, double* arrival_s);
  Step Settle(int pose, double arrival_s, double* settle_s, robot::JointReading* reading);
  // A frame exposed after `not_before_s` (V3-V6), retried; kSkip when none.
  Step Grab(int pose, double not_before_s, bool during_move, capture::Frame* frame);
  // Names the dots of `frame`: tracked from tracked_, or identified when there is no state.
  Step Identify(int pose, const capture::Frame& frame);
  // With RunContext::prediction (session_naming.cc): the tracked dots checked against their predictions
  // at the capture's joints, and detections named by prediction.
  void NameByPrediction(const Capture& capture);
  // The accepted samples of the session so far (the journal's), as prediction reads them, by pose: read
  // from the journal once, then kept up to date as this run accepts samples (RememberSample).
  std::vector<ViewedSample> AcceptedSamples();
  // With prediction, after the last pose (session_naming.cc): the dots each accepted sample's frame lacks,
  // named from the other samples (late_naming.h) and journaled as dots_named_later; false when the
  // journal could not be written (report_ set).
  bool NameLater();
  void RememberSample(int pose, const Eigen::VectorXd& joints_rad, const std::vector<tracking::PreviousDot>& dots,
                      const std::vector<tracking::PreviousDot>& candidates);
  // Marked dots (DotIdentifier::FindMarked) that tracking lost, found again in a settled frame.
  void FindMarkedAgain(const capture::Frame& frame);

  // What the operator sees of a pose (session_view.cc). A new pose: no rejected frame, lost or named dot.
  void StartPoseView();
  // RunContext::observe with the frame and the dots of tracked_, lost_, named_ids_ and candidates_.
  void Observe(const capture::Frame& frame, FramePhase phase, int pose, const std::string& detail = "");
  // The rejected frames of the pose written to images/rejected/ with their frame_rejected records; their
  // record paths. A frame that cannot be written is a fault (counted), not a halt: it is not data.
  std::vector<std::string> SaveRejectedFrames(int pose, const std::string& reason);

  const std::vector<PlannedPose>& plan_;
  RunContext c_;  // a copy: c_.session is set when the run creates its session
  const RunOptions& o_;
  RunReport report_;
  robot::JointLimits limits_;
  std::vector<tracking::PreviousDot> tracked_;
  std::vector<tracking::PreviousDot> candidates_;  // of the settled frame being recorded (session_naming.cc)
  std::optional<std::map<int, ViewedSample>> viewed_;  // AcceptedSamples, once read from the journal
  double last_frame_s_ = -std::numeric_limits<double>::infinity();
  std::map<int, int> frames_written_;  // per pose: frame_written records so far (image names)
  std::map<int, int> rejected_written_;  // per pose: frame_rejected records so far (their names)
  std::vector<RejectedFrame> pose_frames_;  // grabbed after settling at this pose (session_view.cc)
  std::map<int, Eigen::Vector2d> lost_;     // dots lost at this pose: their last tracked position
  std::set<int> named_ids_;                 // ids named (not tracked) at this pose's settled frame
};

}  // namespace selfcal::acquisition::internal
