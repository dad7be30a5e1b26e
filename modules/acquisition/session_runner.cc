#include "acquisition/session_runner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "acquisition/session_runner_internal.h"
#include "geometry/rigid3.h"
#include "session/samples.h"

namespace selfcal::acquisition {

namespace internal {

using nlohmann::json;

json ToJson(const Eigen::VectorXd& v) {
  json a = json::array();
  for (int i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

const char* RoleName(PoseRole role) { return role == PoseRole::kVerification ? "verification" : "identification"; }

namespace {

Eigen::VectorXd FromVector(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

}  // namespace

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
  report_.stop_sent = stop.ok();
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
  const std::vector<std::string> rejected = SaveRejectedFrames(pose, reason);  // their records first (P1)
  json record = {{"type", "sample_skipped"}, {"pose", pose}, {"reason", reason}, {"detail", detail}};
  if (!rejected.empty()) {
    record["rejected_images"] = rejected;
    Log("pose " + plan_[pose].id + ": " + std::to_string(rejected.size()) + " rejected frame(s) kept, first " +
        rejected.front());
  }
  Record(record);
  if (!pose_frames_.empty()) Observe(pose_frames_.back().frame, FramePhase::kSkipped, pose, reason);
  pose_frames_.clear();
}

Runner::Step Runner::HaltOnRobotError(const Status& status, int pose, const std::string& what) {
  const robot::RobotError e = robot::RobotErrorOf(status);
  return Halt(RunOutcome::kHalted, ErrorCode::kHardware, std::string("robot_") + robot::RobotErrorName(e),
              what + ": " + status.message(), pose);
}

const std::vector<json>& Runner::Records() const {
  return c_.dry_run_of != nullptr ? c_.dry_run_of->records : c_.session->journal().records();
}

const std::string& Runner::SessionPath() const {
  return c_.dry_run_of != nullptr ? c_.dry_run_of->path : c_.session->path();
}

void Runner::Conclude(const std::string& message) {
  int identification = 0;
  if (Result<session::SessionLog> log = session::ReadSessionLog(Records()); log.ok()) {
    for (const std::optional<session::AcceptedSample>& sample : log->accepted) {
      identification += sample && sample->role == PoseRole::kIdentification ? 1 : 0;
    }
  }
  if (identification < o_.min_identification_samples) {
    report_.outcome = RunOutcome::kTooFewSamples;
    report_.error = ErrorCode::kDegenerateData;
    report_.message = "every pose was visited, but the session holds " + std::to_string(identification) +
                      " accepted identification samples and the calibration needs at least " +
                      std::to_string(o_.min_identification_samples) +
                      ": the session is not complete; resume it to visit the skipped poses again";
    return;
  }
  report_.outcome = RunOutcome::kCompleted;
  report_.error = ErrorCode::kOk;
  report_.message = message;
}

namespace {

std::string DegreesText(const Eigen::VectorXd& joints_rad) {
  std::ostringstream out;
  out << "[";
  for (int j = 0; j < joints_rad.size(); ++j) out << (j > 0 ? ", " : "") << RadToDeg(joints_rad[j]);
  out << "] deg";
  return out.str();
}

// Where the plan the journal recorded (a prefix of it if a crash came while it was being journaled)
// first differs from `plan`: empty when it is the same plan.
std::string FirstPlanDifference(const session::SessionLog& log, const std::vector<PlannedPose>& plan) {
  const int given = static_cast<int>(plan.size());
  if (log.num_poses != given || static_cast<int>(log.plan.size()) > given) {
    return "the session recorded a plan of " + std::to_string(log.num_poses) + " poses, the plan given has " +
           std::to_string(given);
  }
  for (int i = 0; i < static_cast<int>(log.plan.size()); ++i) {
    const PlannedPose& recorded = log.plan[i];
    if (recorded.id == plan[i].id && recorded.joints_rad.size() == plan[i].joints_rad.size() &&
        recorded.joints_rad == plan[i].joints_rad) {
      continue;
    }
    return "the first pose that differs is pose " + std::to_string(i) + " (" + recorded.id +
           (recorded.id == plan[i].id ? "" : ", given as " + plan[i].id) + "): recorded " +
           DegreesText(recorded.joints_rad) + ", given " + DegreesText(plan[i].joints_rad);
  }
  return "";
}

}  // namespace

bool Runner::StartFromJournal(const session::SessionLog& log, std::vector<int>* todo) {
  const int num_poses = static_cast<int>(plan_.size());
  if (log.started) {
    if (const std::string difference = FirstPlanDifference(log, plan_); !difference.empty()) {
      report_.message = "session " + SessionPath() + " recorded another plan than the one given: " + difference;
      return false;
    }
    *todo = log.PosesToVisit(o_.revisit_skipped);
  } else {
    for (int i = 0; i < num_poses; ++i) todo->push_back(i);
  }
  report_.first_pose = todo->empty() ? num_poses : todo->front();
  if (!todo->empty()) return true;
  if (!Resuming()) {
    report_.message = "the plan has no pose: nothing to record";
    return false;
  }
  if (!log.finished && c_.dry_run_of != nullptr) {  // a dry run writes nothing
    Conclude("every pose of the session is visited; a real resume would name dots later in the recorded frames "
             "and mark the session finished (dry run: nothing written)");
    return false;
  }
  // Every pose visited, but stopped before `finished`: the end of the session (naming later in the
  // recorded frames) is done now, as an uninterrupted run does it.
  if (!log.finished && (!NameLater() || !Record({{"type", "finished"}, {"time_s", Now()}}))) return false;
  Conclude("every pose of the session is done");
  return false;
}

bool Runner::ConnectRobot(const session::SessionLog& log, RobotAtStart* robot) {
  if (Status s = c_.robot->Connect(); !s.ok()) {
    report_.outcome = RunOutcome::kHalted;
    report_.error = ErrorCode::kHardware;
    report_.message = "connecting to the robot: " + s.message();
    return false;
  }
  Result<robot::RobotIdentity> identity = c_.robot->Identity();
  Result<robot::JointLimits> limits = identity.ok() ? c_.robot->Limits() : Result<robot::JointLimits>(identity.status());
  if (!limits.ok()) {
    report_.outcome = RunOutcome::kHalted;
    report_.error = ErrorCode::kHardware;
    report_.message = "asking the robot for its identity and limits: " + limits.status().message();
    return false;
  }
  limits_ = *limits;
  if (log.started) {  // R13: the same robot as when the session started
    const json& started = Records().front();
    if (started.value("robot_model", "") != identity->model || started.value("robot_serial", "") != identity->serial ||
        started.value("robot_calibration", identity->calibration_id) != identity->calibration_id) {
      report_.message = "session " + SessionPath() + " was recorded with robot " +
                        started.value("robot_model", "?") + " serial " + started.value("robot_serial", "?") +
                        "; this robot is " + identity->model + " serial " + identity->serial + "";
      return false;
    }
    // The limits the session was recorded under (the controller's, narrowed to the config's); not the
    // address, a transport detail that may change when the controller restarts.
    if (started.contains("robot_limits") &&
        started["robot_limits"] != json{{"lower_rad", ToJson(limits_.lower_rad)}, {"upper_rad", ToJson(limits_.upper_rad)}}) {
      report_.message = "session " + SessionPath() + " was recorded under the joint limits " +
                        started["robot_limits"].dump() + "; this robot reports lower " +
                        ToJson(limits_.lower_rad).dump() + ", upper " + ToJson(limits_.upper_rad).dump() + " rad";
      return false;
    }
  }
  Result<robot::JointReading> now_joints = c_.robot->ReadJoints();
  if (!now_joints.ok()) {
    report_.outcome = RunOutcome::kHalted;
    report_.error = ErrorCode::kHardware;
    report_.message = "reading the robot's joints: " + now_joints.status().message();
    return false;
  }
  robot->identity = std::move(identity).value();
  robot->joints = std::move(now_joints).value();
  return true;
}

Route Runner::PlanRoute(const session::SessionLog& log, const std::vector<int>& todo, const Eigen::VectorXd& now_rad) {
  // The route starts from the accepted sample closest before the first pose to visit: the last one
  // accepted when nothing is revisited (every accepted pose lies before the resume point).
  const session::AcceptedSample* last = nullptr;
  for (int p = todo.front() - 1; log.started && p >= 0 && last == nullptr; --p) {
    if (p < static_cast<int>(log.accepted.size()) && log.accepted[p]) last = &*log.accepted[p];
  }
  Route route;
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
    last_frame_s_ = std::max(last_frame_s_, log.LastAcceptedSample()->exposure_time_s);
    const Eigen::VectorXd there = FromVector(last->joints_rad);
    if (now_rad.size() != there.size() || (now_rad - there).cwiseAbs().maxCoeff() > o_.safety.start_tolerance_rad) {
      route.returning = true;
      route.poses.push_back({plan_[last->pose].id + "-return", plan_[last->pose].role, there});
      route.plan_index.push_back(last->pose);
      route.pass.push_back(true);
    }
  }
  // The plan from there: the poses to visit, and the accepted ones between them passed without recording.
  for (int i = last != nullptr ? last->pose + 1 : todo.front(); i <= todo.back(); ++i) {
    const bool visit = std::binary_search(todo.begin(), todo.end(), i);
    if (!visit && !(i < static_cast<int>(log.accepted.size()) && log.accepted[i])) continue;
    route.poses.push_back(plan_[i]);
    route.plan_index.push_back(i);
    route.pass.push_back(!visit);
  }
  return route;
}

bool Runner::Arm(const Route& route, const RobotAtStart& robot) {
  // V1: the camera must work before anything moves (its Open grabs a test frame where it can). A dry run
  // moves nothing and needs no camera.
  if (Status s = o_.dry_run ? Status::Ok() : c_.camera->Open(); !s.ok()) {
    report_.outcome = RunOutcome::kHalted;
    report_.error = ErrorCode::kHardware;
    report_.message = "opening the camera " + c_.camera->Describe() + ": " + s.message();
    return false;
  }
  const robot::RobotIdentity& identity = robot.identity;
  const PreflightReport preflight = Preflight(route.poses, limits_, robot.joints.position_rad, o_.safety, 0,
                                              o_.plan_check ? &*o_.plan_check : nullptr);
  report_.preview = "robot " + identity.backend + " " + identity.model + " serial " + identity.serial +
                    (identity.real_hardware ? " (REAL HARDWARE)" : " (no hardware)") + "\n" +
                    (route.returning ? "first returning to the pose of the last accepted sample, then\n" : "") +
                    preflight.Preview(route.poses, o_.safety.velocity_scaling);
  if (!preflight.ok()) {
    report_.message = PreflightRefusal(preflight.problems);
    return false;
  }
  // A dry run (and a dry run of a resume, which holds no session to write) is never armed, whatever the
  // callback answers.
  if (!c_.confirm(report_.preview, identity) || c_.dry_run_of != nullptr || o_.dry_run) {
    report_.message = "not confirmed: nothing was sent to the arm";
    return false;
  }
  return true;
}

bool Runner::CreateSession() {
  Result<session::Session*> created = c_.create_session();
  if (!created.ok() || *created == nullptr) {
    report_.outcome = RunOutcome::kSessionError;
    report_.error = created.ok() ? ErrorCode::kInternal : created.status().code();
    report_.message = "creating the session (nothing moved): " +
                      (created.ok() ? std::string("no session") : created.status().message());
    return false;
  }
  c_.session = *created;
  return true;
}

bool Runner::JournalStart(const session::SessionLog& log, const std::vector<int>& todo,
                          const robot::RobotIdentity& identity) {
  const int num_poses = static_cast<int>(plan_.size());
  if (!log.started) {
    if (!Record({{"type", "session_started"}, {"time_s", Now()}, {"num_poses", num_poses}, {"mode", o_.mode},
                 {"robot_backend", identity.backend}, {"robot_model", identity.model},
                 {"robot_serial", identity.serial}, {"robot_calibration", identity.calibration_id},
                 {"robot_limits", {{"lower_rad", ToJson(limits_.lower_rad)}, {"upper_rad", ToJson(limits_.upper_rad)}}},
                 {"camera", c_.camera->Describe()}})) {
      return false;
    }
  } else {
    json revisit = json::array();  // poses skipped before that this run visits again
    for (int p : todo) {
      if (p < static_cast<int>(log.skips.size()) && !log.skips[p].empty()) revisit.push_back(p);
    }
    json resumed = {{"type", "resumed"}, {"time_s", Now()}, {"first_pose", todo.front()}};
    if (!revisit.empty()) {
      resumed["revisit"] = revisit;
      resumed["revisit_skipped"] = o_.revisit_skipped;
      Log("revisiting " + std::to_string(revisit.size()) + " skipped poses (at most " +
          std::to_string(o_.revisit_skipped) + " further attempts each)");
    }
    if (!Record(resumed)) return false;
  }
  for (int i = log.started ? static_cast<int>(log.plan.size()) : 0; i < num_poses; ++i) {
    if (!Record({{"type", "pose_planned"}, {"pose", i}, {"id", plan_[i].id}, {"role", RoleName(plan_[i].role)},
                 {"joints_rad", ToJson(plan_[i].joints_rad)}})) {
      return false;
    }
  }
  for (const auto& [image, frame] : log.frames) ++frames_written_[frame.pose];
  for (const auto& [image, frame] : log.rejected) ++rejected_written_[frame.pose];
  return true;
}

Runner::Step Runner::ReturnTo(const PlannedPose& target, int pose, Eigen::VectorXd* expected) {
  // The dots of the sample are those of a frame at its joints: they are found again there, not tracked
  // through a move that starts wherever the arm was left (a jog, a restart).
  std::vector<tracking::PreviousDot> at_sample;
  at_sample.swap(tracked_);
  StartPoseView();
  robot::JointReading before;
  if (CheckBeforeMove(pose, *expected, &before) == Step::kEnd) return Step::kEnd;
  Log("pose " + target.id + ": moving");
  Arrival arrival;
  Capture capture;
  Step step = MoveAndSettle(pose, before, target, expected, &arrival);
  if (step == Step::kOk) step = CaptureAtPose(pose, arrival.settle_s, &capture);
  if (step == Step::kEnd) return step;
  if (step == Step::kSkip) {
    return Halt(RunOutcome::kHalted, ErrorCode::kHardware, "return_failed",
                "could not return to the last sample's pose, or no frame or reading there", pose);
  }
  tracked_ = std::move(at_sample);
  return NameDots(pose, capture);
}

RunReport Runner::Run() {
  SELFCAL_CHECK(c_.robot && c_.camera && c_.clock && (c_.session || c_.create_session || c_.dry_run_of) &&
                    !(c_.session && c_.dry_run_of) && c_.identifier && c_.confirm,
                "RunContext needs a robot, camera, clock, session (or create_session, or a dry run's snapshot), "
                "identifier and confirm callback");
  report_.outcome = RunOutcome::kRefused;
  report_.error = ErrorCode::kInvalidInput;
  if (const std::string bad = o_.Validate(); !bad.empty()) {
    report_.message = "run options: " + bad;
    return report_;
  }
  // The journal of a session to continue decides where this invocation starts; a new one starts at 0.
  session::SessionLog log;
  if (Resuming()) {
    Result<session::SessionLog> read = session::ReadSessionLog(Records());
    if (!read.ok()) {
      report_.outcome = RunOutcome::kSessionError;
      report_.error = read.status().code();
      report_.message = read.status().message();
      return report_;
    }
    log = std::move(read).value();
  }
  std::vector<int> todo;
  if (!StartFromJournal(log, &todo)) return report_;
  // The robot: identity, limits, where it is; the route; armed; only then a new session is created.
  RobotAtStart robot;
  if (!ConnectRobot(log, &robot)) return report_;
  const Route route = PlanRoute(log, todo, robot.joints.position_rad);
  if (!Arm(route, robot)) return report_;
  if (c_.session == nullptr && (c_.dry_run_of != nullptr || !CreateSession())) return report_;
  if (!JournalStart(log, todo, robot.identity)) return report_;

  // R4: where the arm should be before each move: the previous move's target (the reading at the start).
  Eigen::VectorXd expected = robot.joints.position_rad;
  ProgressScope progress(c_.progress, static_cast<int64_t>(route.poses.size()), "session poses");
  for (size_t r = 0; r < route.poses.size(); ++r, progress.Advance()) {
    const bool is_return = route.returning && r == 0;
    const Step step = is_return ? ReturnTo(route.poses[r], route.plan_index[r], &expected)
                                : VisitPose(route.poses[r], route.plan_index[r], route.pass[r], &expected);
    if (step == Step::kEnd) return report_;
  }
  if (!NameLater()) return report_;
  if (!Record({{"type", "finished"}, {"time_s", Now()}})) return report_;
  Conclude("session complete: " + std::to_string(report_.accepted) + " samples accepted by this run");
  return report_;
}

}  // namespace internal

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
  if (revisit_skipped < 0) out << "revisit_skipped must be >= 0\n";
  if (min_identification_samples < 0) out << "min_identification_samples must be >= 0\n";
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
    case RunOutcome::kTooFewSamples: return "too_few_samples";
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
  internal::Runner runner(plan, context, options);
  return runner.Run();
}

}  // namespace selfcal::acquisition
