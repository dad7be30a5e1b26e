// One pose of a session: the stages of Runner::VisitPose (check before the move, move with the watchdog
// while tracking, settle, capture, name the dots, record) and the steps they are made of.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "acquisition/session_runner_internal.h"
#include "base/crc32.h"
#include "capture/png_codec.h"

namespace selfcal::acquisition::internal {

using nlohmann::json;

json DotsJson(const std::vector<tracking::PreviousDot>& named) {
  json dots = json::array();
  for (const tracking::PreviousDot& d : named) {
    dots.push_back({{"id", d.id}, {"u", d.centroid_px.x()}, {"v", d.centroid_px.y()}, {"area", d.area_px2},
                    {"w", d.width_px}, {"h", d.height_px}});
  }
  return dots;
}

Runner::Step Runner::VisitPose(const PlannedPose& target, int pose, bool is_return, Eigen::VectorXd* expected) {
  StartPoseView();
  robot::JointReading before;
  if (CheckBeforeMove(pose, *expected, &before) == Step::kEnd) return Step::kEnd;
  Log("pose " + target.id + ": moving");
  Arrival arrival;
  Step step = MoveAndSettle(pose, before, target, expected, &arrival);
  if (step == Step::kEnd) return step;
  if (step == Step::kSkip) {
    if (is_return) {
      return Halt(RunOutcome::kHalted, ErrorCode::kHardware, "return_failed", "could not return to the last sample's pose",
                  pose);
    }
    return Step::kSkip;
  }
  Capture capture;
  step = CaptureAtPose(pose, arrival.settle_s, &capture);
  if (step == Step::kEnd) return step;
  if (step == Step::kSkip) {
    if (is_return) {
      return Halt(RunOutcome::kHalted, ErrorCode::kHardware, "return_failed",
                  "no frame or reading at the last sample's pose", pose);
    }
    Skip(pose, capture.frame.image.getWidth() == 0 ? "bad_frame" : "bad_reading", "retries exhausted");
    return Step::kSkip;
  }
  // R4 between settle and capture: the frame may show the arm in motion, or elsewhere than the reading.
  const double moved = (capture.joints.position_rad - arrival.settled.position_rad).cwiseAbs().maxCoeff();
  if (!is_return && moved > o_.safety.start_tolerance_rad) {
    std::ostringstream d;
    d << "the arm moved by " << moved << " rad after it settled (tolerance " << o_.safety.start_tolerance_rad
      << " rad): the frame is not trusted";
    if (Fault("moved_after_settle", pose, d.str()) == Step::kEnd) return Step::kEnd;
    Skip(pose, "moved_after_settle", d.str());
    return Step::kSkip;
  }
  step = NameDots(pose, capture);
  if (step != Step::kOk) return step;
  if (is_return) return Step::kOk;  // the dots are found again; nothing is recorded for the return
  return RecordSample(pose, target, arrival, capture);
}

Runner::Step Runner::CheckBeforeMove(int pose, const Eigen::VectorXd& expected, robot::JointReading* before) {
  if (StopRequested()) {
    return Halt(RunOutcome::kInterrupted, ErrorCode::kInterrupted, "interrupted", "stop requested between poses", pose);
  }
  if (Status s = c_.session->CheckFreeSpace(o_.frame_bytes_estimate * 4); !s.ok()) {
    return Halt(RunOutcome::kHalted, s.code(), "disk_space", s.message(), pose);
  }
  const Step step = ReadJoints(pose, -std::numeric_limits<double>::infinity(), before);
  if (step == Step::kEnd) return Step::kEnd;
  if (step == Step::kSkip) {
    return Halt(RunOutcome::kHalted, ErrorCode::kHardware, "bad_reading", "no valid joint reading before the move", pose);
  }
  const double deviation = (before->position_rad - expected).cwiseAbs().maxCoeff();
  if (deviation > o_.safety.start_tolerance_rad) {  // R4: someone moved the arm
    std::ostringstream d;
    d << "the arm is " << deviation << " rad away from where it should be (tolerance "
      << o_.safety.start_tolerance_rad << " rad): check the cell, then resume";
    Fault("start_state_mismatch", pose, d.str());
    return Halt(RunOutcome::kHalted, ErrorCode::kHardware, "start_state_mismatch", d.str(), pose);
  }
  return Step::kOk;
}

Runner::Step Runner::MoveAndSettle(int pose, const robot::JointReading& before, const PlannedPose& target,
                                   Eigen::VectorXd* expected, Arrival* arrival) {
  const Step step = Move(pose, before, target.joints_rad, &arrival->arrival_s);
  if (step != Step::kOk) return step;
  *expected = target.joints_rad;  // R4: the next move must start from this move's target
  return Settle(pose, arrival->arrival_s, &arrival->settle_s, &arrival->settled);
}

Runner::Step Runner::CaptureAtPose(int pose, double settle_s, Capture* capture) {
  const Step step = Grab(pose, settle_s + 1e-6, /*during_move=*/false, &capture->frame);  // strictly after settling
  if (step != Step::kOk) return step;
  return ReadJoints(pose, settle_s, &capture->joints);
}

Runner::Step Runner::NameDots(int pose, const Capture& capture) {
  std::set<int> carried;  // by tracking from the move; the others are named here
  for (const tracking::PreviousDot& d : tracked_) carried.insert(d.id);
  const Step step = Identify(pose, capture.frame);
  if (step != Step::kOk) return step;
  if (c_.prediction != nullptr) NameByPrediction(capture);
  FindMarkedAgain(capture.frame);
  for (const tracking::PreviousDot& d : tracked_) {
    if (carried.count(d.id) == 0) named_ids_.insert(d.id);
  }
  if (!tracked_.empty()) Observe(capture.frame, FramePhase::kSettled, pose);
  if (tracked_.empty()) {
    return Halt(RunOutcome::kHalted, ErrorCode::kDegenerateData, "lost_track",
                c_.prediction != nullptr ? "no dot is tracked or can be named by prediction"
                                         : "no dot is tracked any more",
                pose);
  }
  return Step::kOk;
}

Runner::Step Runner::RecordSample(int pose, const PlannedPose& target, const Arrival& arrival, const Capture& capture) {
  if (static_cast<int>(tracked_.size()) < o_.min_dots) {
    Skip(pose, "too_few_dots",
         std::to_string(tracked_.size()) + " named dots, fewer than " + std::to_string(o_.min_dots));
    return Step::kSkip;
  }
  const capture::Frame& frame = capture.frame;
  // The image first (atomic), then the records naming it (P1).
  Result<std::string> png = capture::EncodeGreyPng(frame.image, o_.png_compression);
  if (!png.ok()) return Halt(RunOutcome::kSessionError, png.status().code(), "image_encode", png.status().message(), pose);
  const std::string name = target.id + "_" + std::to_string(frames_written_[pose]++) + ".png";
  if (Status s = c_.session->WriteImage(name, *png); !s.ok()) {
    return Halt(RunOutcome::kSessionError, s.code(), "image_write", s.message(), pose);
  }
  const std::string image = std::string(session::kImagesDirName) + "/" + name;
  if (!Record({{"type", "frame_written"}, {"pose", pose}, {"image", image},
               {"crc32", Crc32Hex(Crc32(*png))}, {"bytes", png->size()},
               {"exposure_time_s", frame.exposure_time_s}, {"sequence", frame.sequence}})) {
    return Step::kEnd;
  }
  const json dots = DotsJson(tracked_);
  json sample = {{"type", "sample_accepted"}, {"pose", pose}, {"id", target.id}, {"role", RoleName(target.role)},
                 {"joints_rad", ToJson(capture.joints.position_rad)}, {"joint_time_s", capture.joints.time_s},
                 {"settle_time_s", arrival.settle_s}, {"arrival_time_s", arrival.arrival_s},
                 {"exposure_time_s", frame.exposure_time_s}, {"image", image}, {"dots", dots}};
  std::vector<tracking::PreviousDot> candidates;  // never beside a dot of the same id
  for (const tracking::PreviousDot& c : candidates_) {
    bool named = false;
    for (const tracking::PreviousDot& d : tracked_) named = named || d.id == c.id;
    if (!named) candidates.push_back(c);
  }
  if (!candidates.empty()) sample["candidates"] = DotsJson(candidates);
  if (o_.journal_sim_clock) sample["sim_clock_s"] = Now();
  if (!Record(sample)) return Step::kEnd;
  RememberSample(pose, capture.joints.position_rad, tracked_, candidates);
  ++report_.accepted;
  Observe(frame, FramePhase::kAccepted, pose);
  Log("pose " + target.id + ": sample accepted, " + std::to_string(tracked_.size()) + " dots");
  return Step::kOk;
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
      if (!during_move) pose_frames_.push_back({*f, ""});  // rejected with the pose if it is skipped
      if (!(f->exposure_time_s >= not_before - 1e-9)) {
        if (!during_move) pose_frames_.back().reason = "stale_frame";
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
    // Lost during the move: prediction names the dots again (NameByPrediction), not the identifier.
    if (c_.prediction != nullptr && !AcceptedSamples().empty()) return Step::kOk;
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
      for (const tracking::PreviousDot& p : tracked_) {
        if (p.id == d.id) lost_[d.id] = p.centroid_px;  // shown where it was last seen
      }
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
      Observe(frame, FramePhase::kMoving, pose);
      if (tracked_.empty() && c_.prediction == nullptr) {  // with prediction: named again once settled
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
        << o_.settle.timeout_s << " s (largest " << reading->velocity_rad_s.cwiseAbs().maxCoeff()
        << " rad/s): the arm does not come to rest; check the cell, then resume";
      // R7: an arm that keeps moving is not driven on to the next pose (a skip would send the next move).
      if (Fault("not_settled", pose, d.str()) == Step::kEnd) return Step::kEnd;
      return Halt(RunOutcome::kHalted, ErrorCode::kHardware, "not_settled", d.str(), pose);
    }
    c_.clock->SleepFor(o_.settle.reading_period_s);
  }
}

}  // namespace selfcal::acquisition::internal
