#include "acquisition/session_runner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "base/crc32.h"
#include "capture/png_codec.h"
#include "session/samples.h"

namespace selfcal::acquisition {

namespace {

using nlohmann::json;

json ToJson(const Eigen::VectorXd& v) {
  json a = json::array();
  for (int i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

Eigen::VectorXd FromVector(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

const char* RoleName(PoseRole role) { return role == PoseRole::kVerification ? "verification" : "identification"; }

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

  // Appends a record; a failure ends the run (kSessionError, P5) after stopping the robot.
  bool Record(json record);
  // Ends the run in `outcome` after telling the robot to stop and journaling why (never resumes, R9).
  Step Halt(RunOutcome outcome, ErrorCode code, const std::string& reason, const std::string& detail, int pose);
  Step Fault(const std::string& kind, int pose, const std::string& detail);
  void Skip(int pose, const std::string& reason, const std::string& detail);
  Step HaltOnRobotError(const Status& status, int pose, const std::string& what);

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
  // Marked dots (DotIdentifier::FindMarked) that tracking lost, found again in a settled frame.
  void FindMarkedAgain(const capture::Frame& frame);

  const std::vector<PlannedPose>& plan_;
  const RunContext& c_;
  const RunOptions& o_;
  RunReport report_;
  robot::JointLimits limits_;
  std::vector<tracking::PreviousDot> tracked_;
  double last_frame_s_ = -std::numeric_limits<double>::infinity();
  std::map<int, int> frames_written_;  // per pose: frame_written records so far (image names)

};

bool Runner::Record(json record) {
  if (Status s = c_.session->journal().Append(record); !s.ok()) {
    if (c_.robot != nullptr) c_.robot->Stop();
    report_.outcome = RunOutcome::kSessionError;
    report_.error = s.code();
    report_.message = "session journal: " + s.message();
    report_.halt_reason = "journal_write_failed";
    return false;
  }
  return true;
}

Runner::Step Runner::Halt(RunOutcome outcome, ErrorCode code, const std::string& reason, const std::string& detail,
                          int pose) {
  const Status stop = c_.robot->Stop();
  report_.outcome = outcome;
  report_.error = code;
  report_.halt_reason = reason;
  report_.message = "halted at pose " + (pose >= 0 ? plan_[pose].id : std::string("-")) + ": " + reason + ": " +
                    detail + (stop.ok() ? "" : " (stop command failed: " + stop.message() + ")");
  Record({{"type", "halted"}, {"reason", reason}, {"pose", pose}, {"detail", detail}, {"time_s", Now()}});
  Log(report_.message);
  return Step::kEnd;
}

Runner::Step Runner::Fault(const std::string& kind, int pose, const std::string& detail) {
  ++report_.faults[kind];
  Log("fault at pose " + plan_[pose].id + ": " + kind + ": " + detail);
  return Record({{"type", "fault"}, {"kind", kind}, {"pose", pose}, {"detail", detail}}) ? Step::kOk : Step::kEnd;
}

void Runner::Skip(int pose, const std::string& reason, const std::string& detail) {
  ++report_.skips[reason];
  Log("pose " + plan_[pose].id + " skipped: " + reason + ": " + detail);
  Record({{"type", "sample_skipped"}, {"pose", pose}, {"reason", reason}, {"detail", detail}});
}

Runner::Step Runner::HaltOnRobotError(const Status& status, int pose, const std::string& what) {
  const robot::RobotError e = robot::RobotErrorOf(status);
  return Halt(RunOutcome::kHalted, ErrorCode::kHardware, std::string("robot_") + robot::RobotErrorName(e),
              what + ": " + status.message(), pose);
}

Runner::Step Runner::ReadJoints(int pose, double after_s, robot::JointReading* reading) {
  const int n = static_cast<int>(limits_.lower_rad.size());
  for (int attempt = 0; attempt <= o_.reading_retries; ++attempt) {
    if (attempt > 0) c_.clock->SleepFor(o_.settle.reading_period_s);
    Result<robot::JointReading> r = c_.robot->ReadJoints();
    if (!r.ok()) return HaltOnRobotError(r.status(), pose, "reading the joints");
    std::string kind, detail;
    if (r->position_rad.size() != n || r->velocity_rad_s.size() != n) {
      kind = "short_reading";
      detail = std::to_string(r->position_rad.size()) + " positions and " + std::to_string(r->velocity_rad_s.size()) +
               " velocities for " + std::to_string(n) + " joints";
    } else if (!r->position_rad.allFinite() || !r->velocity_rad_s.allFinite() || !std::isfinite(r->time_s)) {
      kind = "nan_reading";
      detail = "non-finite joint value or timestamp";
    } else if (r->time_s < after_s) {
      kind = "stale_reading";
      std::ostringstream d;
      d << "reading stamped " << r->time_s << " s, before " << after_s << " s";
      detail = d.str();
    } else {
      for (int j = 0; j < n && kind.empty(); ++j) {
        const double q = r->position_rad[j];
        if (q < limits_.lower_rad[j] - 1e-9 || q > limits_.upper_rad[j] + 1e-9) {
          kind = "reading_out_of_limits";
          detail = "joint " + std::to_string(j + 1) + " reads " + std::to_string(q) + " rad";
        }
      }
    }
    if (kind.empty()) {
      *reading = std::move(r).value();
      return Step::kOk;
    }
    if (Fault(kind, pose, detail) == Step::kEnd) return Step::kEnd;
  }
  return Step::kSkip;
}

Runner::Step Runner::Grab(int pose, double not_before_s, bool during_move, capture::Frame* frame) {
  const int attempts = during_move ? 1 : o_.frame_retries + 1;
  for (int attempt = 0; attempt < attempts; ++attempt) {
    const double not_before = std::max(not_before_s, last_frame_s_ + 1e-6);
    Result<capture::Frame> f = c_.camera->Grab(not_before, o_.frame_timeout_s);
    ++report_.frames_grabbed;
    if (f.ok()) {
      c_.clock->SleepUntil(f->exposure_time_s);  // simulated time: the frame's moment has come
      last_frame_s_ = std::max(last_frame_s_, f->exposure_time_s);
      // V5: the freshness invariant, checked, not assumed (1 ns of slack for grid times in floating point).
      if (!(f->exposure_time_s >= not_before - 1e-9)) {
        if (Fault("stale_frame", pose, "frame exposed at " + std::to_string(f->exposure_time_s) + " s, before " +
                                           std::to_string(not_before) + " s") == Step::kEnd) {
          return Step::kEnd;
        }
        continue;
      }
      *frame = std::move(f).value();
      return Step::kOk;
    }
    const capture::CaptureError e = capture::CaptureErrorOf(f.status());
    if (e == capture::CaptureError::kTimeout || e == capture::CaptureError::kBadFrame) {
      const bool timeout = e == capture::CaptureError::kTimeout;
      if (Fault(timeout ? "frame_timeout" : "bad_frame", pose, f.status().message()) == Step::kEnd) return Step::kEnd;
      if (timeout && !during_move && attempt + 1 == attempts) {  // V3: the camera is silent; stop here
        return Halt(RunOutcome::kHalted, ErrorCode::kHardware, "camera_timeout",
                    "no frame after " + std::to_string(attempts) + " attempts: " + f.status().message(), pose);
      }
      continue;
    }
    return Halt(RunOutcome::kHalted, ErrorCode::kHardware,
                std::string("camera_") + (e == capture::CaptureError::kNone ? "error" : capture::CaptureErrorName(e)),
                f.status().message(), pose);
  }
  return Step::kSkip;
}

void Runner::FindMarkedAgain(const capture::Frame& frame) {
  std::vector<int> missing;
  for (int id : c_.identifier->MarkedIds()) {
    bool tracked = false;
    for (const tracking::PreviousDot& d : tracked_) tracked = tracked || d.id == id;
    if (!tracked) missing.push_back(id);
  }
  if (missing.empty()) return;
  const tracking::DetectionReport detections = tracking::DetectDots(frame.image, o_.detector);
  for (const tracking::PreviousDot& found : c_.identifier->FindMarked(frame, detections, missing)) {
    bool clash = false;  // never two ids on one blob
    for (const tracking::PreviousDot& d : tracked_) clash = clash || (d.centroid_px - found.centroid_px).norm() < 3.0;
    if (clash) continue;
    tracked_.push_back(found);
    ++report_.faults["dot_marked_found_again"];
  }
}

Runner::Step Runner::Identify(int pose, const capture::Frame& frame) {
  if (tracked_.empty()) {
    const tracking::DetectionReport detections = tracking::DetectDots(frame.image, o_.detector);
    Result<std::vector<tracking::PreviousDot>> named = c_.identifier->Identify(frame, detections);
    if (!named.ok()) {
      Skip(pose, "too_few_dots", "identification: " + named.status().message());
      return Step::kSkip;
    }
    tracked_ = std::move(named).value();
    return Step::kOk;
  }
  const tracking::TrackReport track = tracking::TrackDots(frame.image, tracked_, o_.tracker);
  ++report_.frames_tracked;
  report_.identity_flags += track.IdentityFlags();
  std::vector<tracking::PreviousDot> next;
  for (const tracking::TrackedDot& d : track.dots) {
    if (d.status == tracking::TrackStatus::kTracked) {
      next.push_back(tracking::MakePreviousDot(d.id, d.measurement));
    } else {
      ++report_.faults[std::string("dot_") + tracking::TrackStatusName(d.status)];  // D1-D4, counted by status
    }
  }
  tracked_ = std::move(next);
  return Step::kOk;
}

Runner::Step Runner::Move(int pose, const robot::JointReading& from, const Eigen::VectorXd& target,
                          double* arrival_s) {
  const double start = Now();
  if (!Record({{"type", "move_started"}, {"pose", pose}, {"time_s", start}, {"from_rad", ToJson(from.position_rad)}})) {
    return Step::kEnd;
  }
  if (Status s = c_.robot->StartMove(target, o_.safety.velocity_scaling); !s.ok()) {
    if (robot::RobotErrorOf(s) == robot::RobotError::kRejected) {
      if (Fault("move_rejected", pose, s.message()) == Step::kEnd) return Step::kEnd;
      Skip(pose, "move_failed", s.message());
      return Step::kSkip;
    }
    return HaltOnRobotError(s, pose, "starting the move");
  }
  const double planned =
      robot::QuinticMoveDuration(from.position_rad, target, limits_.max_velocity_rad_s, o_.safety.velocity_scaling);
  const double deadline = start + o_.watchdog_factor * planned + o_.watchdog_slack_s;
  while (true) {
    if (StopRequested()) {
      return Halt(RunOutcome::kInterrupted, ErrorCode::kInterrupted, "interrupted", "stop requested during the move",
                  pose);
    }
    Result<robot::RobotStatus> status = c_.robot->GetStatus();
    if (!status.ok()) return HaltOnRobotError(status.status(), pose, "during the move");
    if (status->state == robot::MotionState::kIdle) break;
    if (status->state != robot::MotionState::kMoving) {
      return Halt(RunOutcome::kHalted, ErrorCode::kHardware, robot::MotionStateName(status->state),
                  "the controller stopped the arm: " + status->message, pose);
    }
    if (Now() > deadline) {  // R6: the move never finished
      std::ostringstream d;
      d << "the move did not finish within " << (deadline - start) << " s (planned " << planned << " s)";
      return Halt(RunOutcome::kHalted, ErrorCode::kHardware, "move_timeout", d.str(), pose);
    }
    if (tracked_.empty()) {
      c_.clock->SleepFor(o_.settle.reading_period_s);
      continue;
    }
    capture::Frame frame;
    const Step grabbed = Grab(pose, Now() + o_.tracking_interval_s, /*during_move=*/true, &frame);
    if (grabbed == Step::kEnd) return Step::kEnd;
    if (grabbed == Step::kOk) {
      if (Step s = Identify(pose, frame); s == Step::kEnd) return s;
      if (tracked_.empty()) {
        return Halt(RunOutcome::kHalted, ErrorCode::kDegenerateData, "lost_track",
                    "every dot was lost during the move: identities cannot be carried on", pose);
      }
    }
  }
  *arrival_s = Now();
  return Record({{"type", "move_done"}, {"pose", pose}, {"time_s", *arrival_s}}) ? Step::kOk : Step::kEnd;
}

Runner::Step Runner::Settle(int pose, double arrival_s, double* settle_s, robot::JointReading* reading) {
  int calm = 0;
  while (true) {
    if (StopRequested()) {
      return Halt(RunOutcome::kInterrupted, ErrorCode::kInterrupted, "interrupted", "stop requested while settling",
                  pose);
    }
    if (Step s = ReadJoints(pose, arrival_s, reading); s != Step::kOk) return s;
    calm = reading->velocity_rad_s.cwiseAbs().maxCoeff() < o_.settle.velocity_threshold_rad_s ? calm + 1 : 0;
    if (calm >= o_.settle.consecutive_readings && reading->time_s - arrival_s >= o_.settle.min_dwell_s) {
      *settle_s = std::max(reading->time_s, Now());
      return Record({{"type", "settled"}, {"pose", pose}, {"time_s", *settle_s}}) ? Step::kOk : Step::kEnd;
    }
    if (Now() - arrival_s > o_.settle.timeout_s) {
      std::ostringstream d;
      d << "joint velocities still above " << o_.settle.velocity_threshold_rad_s << " rad/s after "
        << o_.settle.timeout_s << " s";
      if (Fault("not_settled", pose, d.str()) == Step::kEnd) return Step::kEnd;
      Skip(pose, "not_settled", d.str());
      return Step::kSkip;
    }
    c_.clock->SleepFor(o_.settle.reading_period_s);
  }
}

RunReport Runner::Run() {
  SELFCAL_CHECK(c_.robot && c_.camera && c_.clock && c_.session && c_.identifier && c_.confirm,
                "RunContext needs a robot, camera, clock, session, identifier and confirm callback");
  report_.outcome = RunOutcome::kRefused;
  report_.error = ErrorCode::kInvalidInput;
  if (const std::string bad = o_.Validate(); !bad.empty()) {
    report_.message = "run options: " + bad;
    return report_;
  }
  // The journal decides where this invocation starts.
  Result<session::SessionLog> log = session::ReadSessionLog(c_.session->journal().records());
  if (!log.ok()) {
    report_.outcome = RunOutcome::kSessionError;
    report_.error = log.status().code();
    report_.message = log.status().message();
    return report_;
  }
  const int num_poses = static_cast<int>(plan_.size());
  if (log->started) {
    // The recorded plan (a prefix of it if a crash came while it was being journaled) must be this one.
    bool same = log->num_poses == num_poses && static_cast<int>(log->plan.size()) <= num_poses;
    for (int i = 0; same && i < static_cast<int>(log->plan.size()); ++i) {
      same = log->plan[i].id == plan_[i].id && log->plan[i].joints_rad.size() == plan_[i].joints_rad.size() &&
             log->plan[i].joints_rad == plan_[i].joints_rad;
    }
    if (!same) {
      report_.message = "session " + c_.session->path() + " recorded another plan than the one given (C9)";
      return report_;
    }
  }
  const int first = log->started ? log->FirstPoseWithoutAcceptedSample() : 0;
  report_.first_pose = first;
  if (first >= num_poses) {
    if (!log->finished && !Record({{"type", "finished"}, {"time_s", Now()}})) return report_;
    report_.outcome = RunOutcome::kCompleted;
    report_.error = ErrorCode::kOk;
    report_.message = "every pose of the session is done";
    return report_;
  }

  // The robot: identity, limits, where it is.
  if (Status s = c_.robot->Connect(); !s.ok()) {
    report_.outcome = RunOutcome::kHalted;
    report_.error = ErrorCode::kHardware;
    report_.message = "connecting to the robot: " + s.message();
    return report_;
  }
  Result<robot::RobotIdentity> identity = c_.robot->Identity();
  Result<robot::JointLimits> limits = identity.ok() ? c_.robot->Limits() : Result<robot::JointLimits>(identity.status());
  if (!limits.ok()) {
    report_.outcome = RunOutcome::kHalted;
    report_.error = ErrorCode::kHardware;
    report_.message = "asking the robot for its identity and limits: " + limits.status().message();
    return report_;
  }
  limits_ = *limits;
  if (log->started) {  // R13: the same robot as when the session started
    const json& started = c_.session->journal().records().front();
    if (started.value("robot_model", "") != identity->model || started.value("robot_serial", "") != identity->serial) {
      report_.message = "session " + c_.session->path() + " was recorded with robot " +
                        started.value("robot_model", "?") + " serial " + started.value("robot_serial", "?") +
                        "; this robot is " + identity->model + " serial " + identity->serial + " (R13)";
      return report_;
    }
  }
  Result<robot::JointReading> now_joints = c_.robot->ReadJoints();
  if (!now_joints.ok()) {
    report_.outcome = RunOutcome::kHalted;
    report_.error = ErrorCode::kHardware;
    report_.message = "reading the robot's joints: " + now_joints.status().message();
    return report_;
  }

  // The route: back to the last accepted sample's pose if the arm left it (resume), then the plan.
  const session::AcceptedSample* last = log->started ? log->LastAcceptedSample() : nullptr;
  std::vector<PlannedPose> route;
  std::vector<int> route_pose;  // plan index per route entry; the return move has the sample's pose
  bool returning = false;
  if (last != nullptr) {
    for (const session::SampleDot& d : last->dots) {
      tracking::PreviousDot p;
      p.id = d.id;
      p.centroid_px = {d.u_px, d.v_px};
      p.area_px2 = d.area_px2;
      p.width_px = d.width_px;
      p.height_px = d.height_px;
      tracked_.push_back(p);
    }
    last_frame_s_ = last->exposure_time_s;
    const Eigen::VectorXd there = FromVector(last->joints_rad);
    if (now_joints->position_rad.size() != there.size() ||
        (now_joints->position_rad - there).cwiseAbs().maxCoeff() > o_.safety.start_tolerance_rad) {
      returning = true;
      route.push_back({plan_[last->pose].id + "-return", plan_[last->pose].role, there});
      route_pose.push_back(last->pose);
    }
  }
  for (int i = first; i < num_poses; ++i) {
    route.push_back(plan_[i]);
    route_pose.push_back(i);
  }
  // V1: the camera must work before anything moves (its Open grabs a test frame where it can).
  if (Status s = c_.camera->Open(); !s.ok()) {
    report_.outcome = RunOutcome::kHalted;
    report_.error = ErrorCode::kHardware;
    report_.message = "opening the camera " + c_.camera->Describe() + ": " + s.message();
    return report_;
  }
  const PreflightReport preflight = Preflight(route, limits_, now_joints->position_rad, o_.safety);
  report_.preview = "robot " + identity->backend + " " + identity->model + " serial " + identity->serial +
                    (identity->real_hardware ? " (REAL HARDWARE)" : " (no hardware)") + "\n" +
                    (returning ? "first returning to the pose of the last accepted sample, then\n" : "") +
                    preflight.Preview(route, o_.safety.velocity_scaling);
  if (!preflight.ok()) {
    report_.message = "preflight refused the plan:\n";
    for (const std::string& p : preflight.problems) report_.message += "  " + p + "\n";
    return report_;
  }
  if (!c_.confirm(report_.preview, *identity)) {
    report_.error = ErrorCode::kInterrupted;
    report_.message = "not confirmed: nothing moved";
    return report_;
  }

  // Armed. Journal the start (or the resumption) before the first command.
  if (!log->started) {
    if (!Record({{"type", "session_started"}, {"time_s", Now()}, {"num_poses", num_poses}, {"mode", o_.mode},
                 {"robot_backend", identity->backend}, {"robot_model", identity->model},
                 {"robot_serial", identity->serial}, {"robot_calibration", identity->calibration_id},
                 {"camera", c_.camera->Describe()}})) {
      return report_;
    }
  } else if (!Record({{"type", "resumed"}, {"time_s", Now()}, {"first_pose", first}})) {
    return report_;
  }
  for (int i = log->started ? static_cast<int>(log->plan.size()) : 0; i < num_poses; ++i) {
    if (!Record({{"type", "pose_planned"}, {"pose", i}, {"id", plan_[i].id}, {"role", RoleName(plan_[i].role)},
                 {"joints_rad", ToJson(plan_[i].joints_rad)}})) {
      return report_;
    }
  }
  for (const auto& [image, frame] : log->frames) ++frames_written_[frame.pose];

  // R4: where the arm should be before each move: the previous move's target (the reading at the start).
  Eigen::VectorXd expected = now_joints->position_rad;
  for (size_t r = 0; r < route.size(); ++r) {
    const int pose = route_pose[r];
    const bool is_return = returning && r == 0;
    const PlannedPose& target = route[r];
    if (StopRequested()) {
      Halt(RunOutcome::kInterrupted, ErrorCode::kInterrupted, "interrupted", "stop requested between poses", pose);
      return report_;
    }
    if (Status s = c_.session->CheckFreeSpace(o_.frame_bytes_estimate * 4); !s.ok()) {
      Halt(RunOutcome::kHalted, s.code(), "disk_space", s.message(), pose);
      return report_;
    }
    robot::JointReading before;
    Step step = ReadJoints(pose, -std::numeric_limits<double>::infinity(), &before);
    if (step == Step::kEnd) return report_;
    if (step == Step::kSkip) {
      Halt(RunOutcome::kHalted, ErrorCode::kHardware, "bad_reading", "no valid joint reading before the move", pose);
      return report_;
    }
    const double deviation = (before.position_rad - expected).cwiseAbs().maxCoeff();
    if (deviation > o_.safety.start_tolerance_rad) {  // R4: someone moved the arm
      std::ostringstream d;
      d << "the arm is " << deviation << " rad away from where it should be (tolerance "
        << o_.safety.start_tolerance_rad << " rad): check the cell, then resume";
      Fault("start_state_mismatch", pose, d.str());
      Halt(RunOutcome::kHalted, ErrorCode::kHardware, "start_state_mismatch", d.str(), pose);
      return report_;
    }
    Log("pose " + target.id + ": moving");
    double arrival = 0, settle = 0;
    robot::JointReading settled;
    step = Move(pose, before, target.joints_rad, &arrival);
    if (step == Step::kOk) {
      expected = target.joints_rad;  // R4: the next move must start from this move's target
      step = Settle(pose, arrival, &settle, &settled);
    }
    if (step == Step::kEnd) return report_;
    if (step == Step::kSkip) {
      if (is_return) {
        Halt(RunOutcome::kHalted, ErrorCode::kHardware, "return_failed", "could not return to the last sample's pose",
             pose);
        return report_;
      }
      continue;
    }
    capture::Frame frame;
    step = Grab(pose, settle + 1e-6, /*during_move=*/false, &frame);  // exposed strictly after settling
    if (step == Step::kEnd) return report_;
    robot::JointReading sample_joints;
    if (step == Step::kOk) step = ReadJoints(pose, settle, &sample_joints);
    if (step == Step::kEnd) return report_;
    if (step == Step::kSkip) {
      if (is_return) {
        Halt(RunOutcome::kHalted, ErrorCode::kHardware, "return_failed", "no frame or reading at the last sample's pose",
             pose);
        return report_;
      }
      Skip(pose, frame.image.getWidth() == 0 ? "bad_frame" : "bad_reading", "retries exhausted");
      continue;
    }
    step = Identify(pose, frame);
    if (step == Step::kEnd) return report_;
    if (step == Step::kSkip) continue;
    FindMarkedAgain(frame);
    if (tracked_.empty()) {
      Halt(RunOutcome::kHalted, ErrorCode::kDegenerateData, "lost_track", "no dot is tracked any more", pose);
      return report_;
    }
    if (is_return) continue;  // the dots are found again; nothing is recorded for the return
    if (static_cast<int>(tracked_.size()) < o_.min_dots) {
      Skip(pose, "too_few_dots",
           std::to_string(tracked_.size()) + " named dots, fewer than " + std::to_string(o_.min_dots));
      continue;
    }
    // The image first (atomic), then the records naming it (P1).
    Result<std::string> png = capture::EncodeGreyPng(frame.image, o_.png_compression);
    if (!png.ok()) {
      Halt(RunOutcome::kSessionError, png.status().code(), "image_encode", png.status().message(), pose);
      return report_;
    }
    const std::string name = target.id + "_" + std::to_string(frames_written_[pose]++) + ".png";
    if (Status s = c_.session->WriteImage(name, *png); !s.ok()) {
      Halt(RunOutcome::kSessionError, s.code(), "image_write", s.message(), pose);
      return report_;
    }
    const std::string image = std::string(session::kImagesDirName) + "/" + name;
    if (!Record({{"type", "frame_written"}, {"pose", pose}, {"image", image},
                 {"crc32", Crc32Hex(Crc32(*png))}, {"bytes", png->size()},
                 {"exposure_time_s", frame.exposure_time_s}, {"sequence", frame.sequence}})) {
      return report_;
    }
    json dots = json::array();
    for (const tracking::PreviousDot& d : tracked_) {
      dots.push_back({{"id", d.id}, {"u", d.centroid_px.x()}, {"v", d.centroid_px.y()}, {"area", d.area_px2},
                      {"w", d.width_px}, {"h", d.height_px}});
    }
    json sample = {{"type", "sample_accepted"}, {"pose", pose}, {"id", target.id}, {"role", RoleName(target.role)},
                   {"joints_rad", ToJson(sample_joints.position_rad)}, {"joint_time_s", sample_joints.time_s},
                   {"settle_time_s", settle}, {"arrival_time_s", arrival}, {"exposure_time_s", frame.exposure_time_s},
                   {"image", image}, {"dots", dots}};
    if (o_.journal_sim_clock) sample["sim_clock_s"] = Now();
    if (!Record(sample)) return report_;
    ++report_.accepted;
    Log("pose " + target.id + ": sample accepted, " + std::to_string(tracked_.size()) + " dots");
  }
  if (!Record({{"type", "finished"}, {"time_s", Now()}})) return report_;
  report_.outcome = RunOutcome::kCompleted;
  report_.error = ErrorCode::kOk;
  report_.message = "session complete: " + std::to_string(report_.accepted) + " samples accepted by this run";
  return report_;
}

}  // namespace

tracking::DotTrackerOptions DefaultSessionTracker() {
  tracking::DotTrackerOptions options;
  options.consistency_threshold_px = 4.0;
  return options;
}

std::string RunOptions::Validate() const {
  std::ostringstream out;
  out << safety.Validate();
  if (!(settle.velocity_threshold_rad_s > 0)) out << "settle velocity threshold must be > 0\n";
  if (settle.consecutive_readings < 1) out << "settle consecutive readings must be >= 1\n";
  if (!(settle.min_dwell_s >= 0) || !(settle.timeout_s > 0) || !(settle.reading_period_s > 0)) {
    out << "settle dwell, timeout and reading period must be >= 0, > 0, > 0\n";
  }
  if (!(watchdog_factor >= 1) || !(watchdog_slack_s >= 0)) out << "watchdog factor >= 1 and slack >= 0\n";
  if (reading_retries < 0 || frame_retries < 0) out << "retries must be >= 0\n";
  if (!(frame_timeout_s > 0)) out << "frame timeout must be > 0\n";
  if (!(tracking_interval_s >= 0)) out << "tracking interval must be >= 0\n";
  if (min_dots < 1) out << "min_dots must be >= 1\n";
  if (png_compression < 0 || png_compression > 9) out << "png_compression must lie in [0, 9]\n";
  return out.str();
}

const char* RunOutcomeName(RunOutcome outcome) {
  switch (outcome) {
    case RunOutcome::kCompleted: return "completed";
    case RunOutcome::kRefused: return "refused";
    case RunOutcome::kHalted: return "halted";
    case RunOutcome::kInterrupted: return "interrupted";
    case RunOutcome::kSessionError: return "session_error";
  }
  return "unknown";
}

Result<std::vector<tracking::PreviousDot>> DetectionOrderIdentifier::Identify(
    const capture::Frame& /*frame*/, const tracking::DetectionReport& detections) {
  if (detections.dots.empty()) return Status::Error(ErrorCode::kDegenerateData, "no dot detected in the first frame");
  std::vector<tracking::PreviousDot> named;
  for (size_t k = 0; k < detections.dots.size(); ++k) {
    named.push_back(tracking::MakePreviousDot(static_cast<int>(k), detections.dots[k]));
  }
  return named;
}

RunReport RunSession(const std::vector<PlannedPose>& plan, const RunContext& context, const RunOptions& options) {
  Runner runner(plan, context, options);
  return runner.Run();
}

}  // namespace selfcal::acquisition
