// Module acquisition (ARCHITECTURE.md): the session loop RunSession (this header) and Preflight
// (motion_safety.h: limits, travel, velocity limits). The dots are named by dot_prediction.h (tracked ones
// checked against, lost ones named again by, their position predicted from the accepted samples; a dot seen
// once confirmed along its epipolar segment), bundled_cameras.h (from three samples on, the samples' cameras
// and f_x bundled from their own images over bundle/free_camera_bundle.h), late_naming.h (after the last
// pose, each accepted image read again and its missing dots named), seen_once.h (dots held by at most three
// samples named where further samples support it), identifiers.h (the first frame's identifiers of
// `run --identify`: detection order, grid, AprilTag, the setup's reference dots) and dot_naming.h (one frame
// named). Every frame goes to RunContext::observe as a FrameView (for a live view; no display code here).
// Never calibrates: its only solves are the predictions'. Uses planning, tracking, robot, session, capture,
// observations, kinematics, camera; bundle, geometry, base private.
//
// The operator's session loop (issue 6; ../shared/DESIGN.md "move / grab / track / record";
// ../shared/RELIABILITY.md design rule 3): drives a robot::Robot through a plan, grabs frames from a capture::FrameSource, tracks the dots
// through every move (identities never jump: vpDot2 follows them frame to frame), and records every event
// in a session directory's journal before it counts. It never solves anything: `selfcal calibrate SESSION`
// reads what it wrote.
//
// An arm that does not come to rest after a move (R7: joint velocities above the threshold until the
// settle timeout) is a halt, not a skip: the controller still moves it, so no further move is sent.
//
// States: preflight (the whole plan against the robot's limits, travel bound and velocity limits, before
// any command: motion_safety.h) -> armed (the caller's confirm callback said yes) -> per pose: moving
// (watchdog; frames tracked) -> settling (velocities below a threshold for N readings and a dwell) ->
// capturing (a frame exposed after the settle time, a fresh complete joint reading) -> recorded. Any stop,
// fault, lost device or stop request ends in `halted`: the robot is told to stop, the journal says why,
// and RunSession returns. Nothing here resumes by itself: continuing is a new RunSession on the same
// session (`selfcal run --resume`), started by a person, which re-reads the robot and re-checks the plan.
//
// A new session is created only once the run can start: RunContext::create_session is called after the
// robot answered, the preflight passed and the operator confirmed, so a dry run, a refusal or an
// unreachable robot leave nothing behind.
//
// Identities at a settled pose, with RunContext::prediction: the dots tracked into the frame that agree with
// their prediction, and the detections named by prediction (dots lost in earlier moves come back); a move
// that loses every dot then goes on, and the pose halts only when nothing can be named. A dot seen in one
// sample only is predicted as a segment of its epipolar line: a detection alone on it is journaled as a
// candidate (never an observation), which the next settled pose confirms by a short gate or forgets.
// From three accepted samples on, every prediction uses the samples' cameras and f_x as a bundle of their
// own images gives them (bundled_cameras.h). Once every pose of the route is visited, before `finished`:
// each accepted sample's image is read again and the dots it lacks are named from the other samples
// (late_naming.h), then the dots held by at most three samples where further samples support a point for
// them (seen_once.h), all journaled as dots_named_later.
//
// Resume: the journal decides. RunSession continues at the first pose with neither an accepted sample
// nor a final skip (session/samples.h), with the dots of the last accepted sample as the tracker's state;
// if the robot is no longer where that sample was taken (beyond the start tolerance) it first returns
// there (a move of its own in the preview) and re-finds the dots in a frame at that pose. Poses skipped
// for revisitable reasons (too_few_dots, not_settled, bad_frame, bad_reading) are visited again, at most
// RunOptions::revisit_skipped times each over the session: the route then starts at the accepted pose
// before the first of them and walks the plan, passing the accepted poses on the way without recording
// them (their moves are the plan's, so the tracker keeps the identities).
//
// A skipped pose keeps what it saw: every frame grabbed after settling and rejected there (the capture
// that had too few dots, a bad reading or a moved arm, a stale frame) is written to images/rejected/ and
// journaled (frame_rejected), and the sample_skipped record lists them (docs/session-format.md).
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "base/progress.h"
#include "capture/frame_source.h"
#include "acquisition/dot_prediction.h"
#include "acquisition/motion_safety.h"
#include "robot/clock.h"
#include "robot/robot.h"
#include "session/session_dir.h"
#include "session/session_snapshot.h"
#include "tracking/dot_detector.h"
#include "tracking/dot_tracker.h"
#include "tracking/predicted_match.h"

namespace selfcal::acquisition {

// Names the dots of a frame when there is no previous frame to track from (the first pose of a session).
class DotIdentifier {
 public:
  virtual ~DotIdentifier() = default;
  // The named dots (ids >= 0, distinct) among `detections` of `frame`, or an error saying why not.
  virtual Result<std::vector<tracking::PreviousDot>> Identify(const capture::Frame& frame,
                                                              const tracking::DetectionReport& detections) = 0;
  // Dots whose identity any single image shows (marked ones: the yardstick's ends carry a tag or a
  // distinct size), found among `detections`. The loop asks at every settled pose for the marked dots it
  // is no longer tracking, so that a yardstick end lost in a move comes back. Default: none are marked.
  virtual std::vector<tracking::PreviousDot> FindMarked(const capture::Frame& /*frame*/,
                                                        const tracking::DetectionReport& /*detections*/,
                                                        const std::vector<int>& /*missing_ids*/) {
    return {};
  }
  virtual std::vector<int> MarkedIds() const { return {}; }
};

// Ids 0, 1, ... in the detector's raster order: for scenes of unknown dots, where an id is only a label
// that tracking keeps. The yardstick's ends must then be named by the operator from the first image.
class DetectionOrderIdentifier : public DotIdentifier {
 public:
  Result<std::vector<tracking::PreviousDot>> Identify(const capture::Frame& frame,
                                                      const tracking::DetectionReport& detections) override;
};

// The tracker as a session uses it: the identity check (a robust planar fit between consecutive frames)
// tolerates the parallax of a deep 3-D scene over one frame of motion (4 px); a swap moves a dot by about
// one dot spacing, which the spacing of a usable scene keeps above 3 dot radii.
tracking::DotTrackerOptions DefaultSessionTracker();

struct SettleOptions {
  double velocity_threshold_rad_s = 1e-3;  // R7: every joint below this...
  int consecutive_readings = 3;            // ...for this many readings in a row...
  double min_dwell_s = 0.2;                // ...and at least this long after the controller said done
  double timeout_s = 5.0;                  // not settled by then: the session halts (not_settled)
  double reading_period_s = 0.02;
};

struct RunOptions {
  MotionSafetyOptions safety;
  // The plan file and robot config, checked whole by the preflight (planning::CheckPlanFor, the words of
  // `selfcal plan --check`); unset: the route is checked against the controller's limits only.
  std::optional<PlanToCheck> plan_check;
  SettleOptions settle;
  double watchdog_factor = 1.1;     // R6: a move may take factor x its planned duration + slack
  double watchdog_slack_s = 0.5;
  int reading_retries = 3;          // R8: invalid joint readings retried, then the pose is skipped
  double frame_timeout_s = 1.0;     // V3: per grab
  int frame_retries = 3;            // V3, V6: timeouts / bad frames retried at the same pose, then skip
  double tracking_interval_s = 0.0; // frames grabbed during a move at least this far apart (0: every one)
  tracking::DotDetectorOptions detector;
  tracking::DotTrackerOptions tracker = DefaultSessionTracker();
  int min_dots = 8;                 // D1: fewer named dots in a sample -> skipped (too_few_dots)
  // Naming by prediction (RunContext::prediction): the 3-D prediction, its correction on the tracked
  // dots and the gate (dot_prediction.h, tracking/predicted_match.h).
  DotPredictionOptions prediction;
  tracking::PredictionCorrectionOptions prediction_correction;
  tracking::PredictedMatchOptions predicted_match;
  // With prediction, once every pose is visited and before the session is marked finished: each accepted
  // sample's frame is read again and the dots it lacks are named from the other samples' predictions
  // (late_naming.h), journaled as dots_named_later; at most this many passes over the samples (0: none).
  int late_naming_passes = 2;
  int late_min_other_samples = 4;      // LateNamingOptions::min_other_samples
  int png_compression = 1;
  std::uint64_t frame_bytes_estimate = 400 * 1024;  // P5: free space needed per frame
  bool journal_sim_clock = false;   // simulated sessions: journal the clock with each sample (resume)
  std::string mode = "simulated";   // session_started.mode
  // A dry run: the robot is read and the preview made, and the run is never armed, whatever confirm
  // answers; the camera is not opened (a dry run needs none).
  bool dry_run = false;
  int revisit_skipped = 1;          // resume: further attempts per pose skipped for a revisitable reason
  // A session whose every pose is visited with fewer accepted identification samples than this ends in
  // kTooFewSamples, not kCompleted: the default calibration (the bundle adjustment,
  // bundle::BundleOptions::min_identification_poses) refuses fewer.
  int min_identification_samples = 3;
  std::string Validate() const;     // empty when valid
};

enum class RunOutcome {
  kCompleted = 0,  // every pose has an accepted sample or a final skip
  kRefused,        // preflight or the operator said no: nothing moved
  kHalted,         // a stop, fault or lost device: the robot was told to stop
  kInterrupted,    // the stop request (Ctrl-C, SIGTERM) was honoured
  kSessionError,   // the session directory could not be written or read
  kTooFewSamples,  // every pose visited, but fewer identification samples than the calibration needs
};
const char* RunOutcomeName(RunOutcome outcome);

struct RunReport {
  RunOutcome outcome = RunOutcome::kRefused;
  ErrorCode error = ErrorCode::kInvalidInput;
  std::string message;
  std::string preview;          // the dry-run preview shown to confirm
  int first_pose = 0;           // where this invocation started (resume point)
  int accepted = 0;             // samples accepted by this invocation
  std::map<std::string, int> skips;   // by reason, this invocation
  std::map<std::string, int> faults;  // by kind, this invocation (each retried or tolerated fault)
  std::string halt_reason;      // when halted / interrupted
  bool stop_sent = false;       // the halt's STOP was sent and acknowledged (false: not sent, or it failed)
  int frames_grabbed = 0, frames_tracked = 0;
  int identity_flags = 0;       // D4: merged + inconsistent dots dropped by the tracker
  // Naming by prediction, over this invocation's settled frames:
  int named_by_prediction = 0;     // detections named by their predicted position
  int dropped_by_prediction = 0;   // tracked dots far outside their prediction's gate, not recorded
  int ambiguous_by_prediction = 0; // detections left unnamed: two gates, or two detections in one gate
  int prediction_uncorrected = 0;  // settled frames where no correction of the predictions was found
  int named_later = 0;             // dots named in recorded samples' frames at the end (late_naming.h)
  int samples_named_later = 0;     // samples that gained dots so
};

// What a live view is shown of the loop (RunContext::observe): one frame, its dots and the pose.
enum class FramePhase {
  kMoving,    // a frame tracked during the move
  kSettled,   // the frame exposed after settling, its dots named
  kAccepted,  // that frame, recorded as the pose's sample
  kSkipped,   // the last frame rejected at a pose that was skipped (FrameView::detail: the reason)
};
const char* FramePhaseName(FramePhase phase);  // "moving", "settled", "accepted", "skipped"

enum class ViewDotState {
  kTracked,    // carried by tracking into this frame
  kNamed,      // named at this settled frame (first identification, prediction, a marked dot found again)
  kLost,       // lost at this pose: its last tracked position
  kCandidate,  // a detection on the epipolar segment of a dot seen once (never an observation)
};

struct ViewDot {
  int id = 0;
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Zero();
  ViewDotState state = ViewDotState::kTracked;
};

struct FrameView {
  const capture::Frame* frame = nullptr;  // valid during the call only
  FramePhase phase = FramePhase::kMoving;
  int pose = 0;  // plan index
  std::string pose_id;
  int num_poses = 0;
  std::vector<ViewDot> dots;
  std::string detail;  // kSkipped: the skip reason
};

struct RunContext {
  robot::Robot* robot = nullptr;
  capture::FrameSource* camera = nullptr;
  robot::Clock* clock = nullptr;
  // The session to continue (a resume), or null with create_session: called once the operator confirmed,
  // just before the first record; returns the new session (owned by the caller) or why it could not be
  // made (the run then ends in kSessionError, nothing having moved).
  session::Session* session = nullptr;
  std::function<Result<session::Session*>()> create_session;
  DotIdentifier* identifier = nullptr;
  // The nominal cell (robot model, camera, pixel noise) that predicts where the dots of the accepted
  // samples appear at a settled pose, so that dots tracking lost are named again (dot_prediction.h).
  // Optional: without it, dots are named by tracking alone and a move that loses every dot halts.
  const PredictionModel* prediction = nullptr;
  // Polled between every step; set by a signal handler (the handler only sets it, R11).
  const std::atomic<bool>* stop_requested = nullptr;
  // Shown the preview after a successful preflight; returns true to arm (typed confirmation for real
  // robots, automatic for the simulated one, false for a dry run). Required.
  std::function<bool(const std::string& preview, const robot::RobotIdentity& robot)> confirm;
  // Progress lines for the operator (optional).
  std::function<void(const std::string& line)> log;
  // A dry run of a resume (instead of `session`): the recorded session as read without changing anything
  // (session::ReadSession). The run goes as far as the preview, which `confirm` is shown; it is never
  // armed, whatever `confirm` answers, and nothing is written, repaired or sent to the arm beyond the
  // questions of the preflight (identity, limits, joints).
  const session::SessionSnapshot* dry_run_of = nullptr;
  // Told the poses of this run's route done (optional), for the operator's progress line.
  ProgressSink* progress = nullptr;
  // Every frame the loop looks at, with its dots, for a live view (optional). Called on the loop's
  // thread: it must return quickly (a view throttles its own drawing).
  std::function<void(const FrameView& view)> observe;
};

// Runs (or continues) the session of `plan` (see the header comment). The plan must be the one the
// session's journal recorded, if it recorded one (else kRefused).
RunReport RunSession(const std::vector<PlannedPose>& plan, const RunContext& context, const RunOptions& options);

}  // namespace selfcal::acquisition
