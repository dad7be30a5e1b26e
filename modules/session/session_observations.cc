#include "session/session_observations.h"

#include "io/robot_config.h"
#include "session/file_util.h"
#include "session/samples.h"
#include "session/session_snapshot.h"
#include "session/setup_file.h"

namespace selfcal::session {

namespace {

constexpr const char* kRobotInputName = "robot.yaml";

JournalSummary Summarize(const SessionLog& log, const std::string& session_id) {
  JournalSummary summary;
  summary.session_id = session_id;
  summary.poses_planned = log.num_poses;
  summary.samples_accepted = log.NumAccepted();
  summary.resumes = log.resumes;
  summary.finished = log.finished;
  summary.skips_by_reason = log.skips_by_reason;
  summary.faults_by_kind = log.faults_by_kind;
  summary.halts_by_reason = log.halts_by_reason;
  summary.rejected_frames = static_cast<int>(log.rejected.size());
  return summary;
}

PoseObservation ObservationOf(const AcceptedSample& sample) {
  PoseObservation pose;
  pose.id = sample.id;
  pose.role = sample.role;
  pose.joints_rad =
      Eigen::Map<const Eigen::VectorXd>(sample.joints_rad.data(), static_cast<Eigen::Index>(sample.joints_rad.size()));
  for (const SampleDot& d : sample.dots) pose.dots_px[d.id] = {d.u_px, d.v_px};
  return pose;
}

std::string InputPath(const std::string& session_path, const std::string& name) {
  return internal::Join(internal::Join(session_path, kInputsDirName), name);
}

}  // namespace

Result<SessionObservations> LoadSessionObservations(const std::string& session_path) {
  Result<SessionSnapshot> snapshot = ReadSession(session_path);
  if (!snapshot.ok()) return snapshot.status();
  Result<SessionLog> log = ReadSessionLog(snapshot->records);
  if (!log.ok()) return log.status();
  SessionObservations result;
  result.summary = Summarize(*log, snapshot->manifest.session_id);
  result.manifest_sha256 = snapshot->manifest_sha256;
  result.torn_tail = snapshot->journal;
  result.unrecorded_images = snapshot->unrecorded_images;
  result.findings = snapshot->Findings();
  if (Status v = VerifySampleImages(session_path, *log); !v.ok()) return v;

  ObservationSet& set = result.observations;
  Result<std::string> setup_text = snapshot->Input(kSetupFileName);
  if (!setup_text.ok()) return setup_text.status();
  if (Status p = ParseSetupFile(*setup_text, InputPath(session_path, kSetupFileName), &set); !p.ok()) return p;
  Result<std::string> robot_text = snapshot->Input(kRobotInputName);
  if (!robot_text.ok()) return robot_text.status();
  Result<RobotModel> robot = io::ParseRobotModelText(*robot_text, InputPath(session_path, kRobotInputName));
  if (!robot.ok()) return robot.status();
  // The robot of robot.yaml in the configuration of setup.json (its mount and nominal fixed camera).
  const CameraMount mount = set.robot.mount;
  const Rigid3 base_from_cam = set.robot.base_from_cam;
  set.robot = *robot;
  set.robot.mount = mount;
  set.robot.base_from_cam = base_from_cam;
  if (snapshot->manifest.configuration != mount) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "session " + session_path + ": session.json records configuration " +
                             CameraMountName(snapshot->manifest.configuration) + " but inputs/setup.json " +
                             CameraMountName(mount));
  }
  const std::string journal_path = internal::Join(session_path, kJournalFileName);
  if (Status c = CheckSampleContents(*log, journal_path, set.camera, set.robot); !c.ok()) return c;
  for (const std::optional<AcceptedSample>& sample : log->accepted) {
    if (sample) set.poses.push_back(ObservationOf(*sample));
  }
  if (set.PosesWithRole(PoseRole::kIdentification).size() < 2) {
    return Status::Error(ErrorCode::kDegenerateData, "session " + session_path + " has " +
                                                        std::to_string(set.poses.size()) +
                                                        " accepted samples: too few to calibrate");
  }
  if (const std::string problems = set.Validate(); !problems.empty()) {
    return Status::Error(ErrorCode::kDegenerateData, "session " + session_path + ": " + problems);
  }
  return result;
}

}  // namespace selfcal::session
