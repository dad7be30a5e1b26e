#include "app/run_configuration.h"

#include "app/cli_util.h"
#include "io/robot_config.h"
#include "session/session_dir.h"
#include "sim/sim_world.h"
#include "sim/trajectory_generator.h"

namespace selfcal::app {

void AddConfigurationOption(CLI::App* cmd, std::string* configuration) {
  cmd->add_option("--configuration", *configuration,
                  "eye_in_hand (default: camera on the flange, dots fixed in the base frame) or eye_to_hand (camera "
                  "fixed in the base frame, dots carried by the flange: a plate, a tag)")
      ->check(CLI::IsMember({CameraMountName(CameraMount::kEyeInHand), CameraMountName(CameraMount::kEyeToHand)}));
}

Result<CameraMount> ParseConfiguration(const std::string& name) {
  CameraMount mount = CameraMount::kEyeInHand;
  if (!ParseCameraMount(name, &mount)) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "--configuration \"" + name + "\" is neither eye_in_hand nor eye_to_hand");
  }
  return mount;
}

namespace {

Result<Eigen::VectorXd> HomeOf(const std::string& robot_path) {
  Result<io::CalibratedModel> config = io::LoadRobotConfig(ResolveDataPath(robot_path));
  if (!config.ok()) return config.status();
  if (config->home_rad.empty()) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "robot config " + robot_path + " has no home_deg: the simulated eye-to-hand cell puts its "
                         "fixed camera in front of the flange at home (docs/robots.md)");
  }
  return Eigen::VectorXd(
      Eigen::Map<const Eigen::VectorXd>(config->home_rad.data(), static_cast<Eigen::Index>(config->home_rad.size())));
}

}  // namespace

Result<RobotModel> RobotInSimulatedCell(const RobotModel& robot, const std::string& robot_path, CameraMount mount) {
  RobotModel out = robot;
  if (mount == CameraMount::kEyeInHand) return out;
  Result<Eigen::VectorXd> home = HomeOf(robot_path);
  if (!home.ok()) return home.status();
  out.mount = CameraMount::kEyeToHand;
  out.base_from_cam = sim::DefaultFixedCamera(robot, *home);
  return out;
}

Result<std::vector<Eigen::VectorXd>> EyeToHandStart(const RobotModel& robot, const std::string& robot_path, int poses) {
  Result<Eigen::VectorXd> home = HomeOf(robot_path);
  if (!home.ok()) return home.status();
  sim::EyeToHandTrajectoryOptions options;
  options.num_poses = poses;
  for (Eigen::Index j = 0; j < home->size(); ++j) options.home_joints_deg.push_back(RadToDeg((*home)[j]));
  sim::GeneratedTrajectory t = sim::MakeEyeToHandTrajectory(robot, options);
  if (!t.ok) return Status::Error(ErrorCode::kDegenerateData, "eye-to-hand start for " + robot_path + ": " + t.message);
  return t.joints;
}

Status CheckResumeConfiguration(const std::string& session, CameraMount requested) {
  Result<session::SessionManifest> manifest = session::ReadManifest(session);
  if (!manifest.ok() || manifest->configuration == requested) return Status::Ok();
  return Status::Error(ErrorCode::kInvalidInput,
                       "session " + session + " was recorded in configuration " +
                           CameraMountName(manifest->configuration) + ", and this run asks for " +
                           CameraMountName(requested) + " (--configuration): a session keeps its configuration; "
                           "resume it with --configuration " + CameraMountName(manifest->configuration) +
                           ", or record the other configuration in a new session. Nothing was changed");
}

}  // namespace selfcal::app
