#include "app/cli_util.h"

#include "app/cli_output.h"

#include <filesystem>
#include <iostream>

#include "io/robot_config.h"
#include "io/trajectory_file.h"

#include "base/install_layout.h"
#include "base/sha256.h"
#include "base/terminal_text.h"

namespace selfcal::app {

std::string ResolveDataPath(const std::string& path) { return FindDataFile(path); }

int Fail(const Status& status) {
  std::cerr << "selfcal: " << TerminalSafe(status.ToString()) << "\n";
  RecordError(status.ToString());
  return static_cast<int>(ExitCodeFor(status.code()));
}

ExitCode ExitCodeFor(calibration::Verdict verdict) {
  switch (verdict) {
    case calibration::Verdict::kAccepted: return ExitCode::kOk;
    case calibration::Verdict::kInvalidInput: return ExitCode::kUsage;
    case calibration::Verdict::kDegenerate:
    case calibration::Verdict::kScaleUnresolved: return ExitCode::kDegenerateData;
    case calibration::Verdict::kUnconverged:
    case calibration::Verdict::kSolverFailure: return ExitCode::kSolverFailure;
    case calibration::Verdict::kRejected: return ExitCode::kModelRejected;
    case calibration::Verdict::kUntested: return ExitCode::kUntested;
  }
  return ExitCode::kSolverFailure;
}

std::string FileSha256(const std::string& path) {
  Result<std::string> digest = Sha256OfFile(path);
  return digest.ok() ? *digest : std::string();
}

void AddRobotOption(CLI::App* cmd, std::string* robot_path) {
  cmd->add_option("--robot", *robot_path, "Nominal robot config");
}

Result<std::string> TrajectoryForRobot(const std::string& given, const std::string& robot_name, const std::string& robot_path) {
  if (!given.empty()) return given;
  const std::string shipped = io::InitialTrajectoryPath(robot_name);
  std::error_code ec;
  if (std::filesystem::exists(ResolveDataPath(shipped), ec)) return shipped;
  return Status::Error(ErrorCode::kInvalidInput, "no trajectory given and none shipped for robot `" + robot_name + "` (" +
                                                     shipped + " does not exist): give one, or make one with "
                                                     "`selfcal make-trajectory --robot " + robot_path + " --out FILE`");
}

Result<RobotAndTrajectory> LoadRobotAndTrajectory(const std::string& robot_path, const std::string& trajectory_path) {
  Result<RobotModel> robot = io::LoadRobotModel(ResolveDataPath(robot_path));
  if (!robot.ok()) return robot.status();
  Result<std::string> path = TrajectoryForRobot(trajectory_path, robot->name, robot_path);
  if (!path.ok()) return path.status();
  Result<io::TrajectoryFile> file = io::LoadTrajectoryFileForRobot(ResolveDataPath(*path), *robot, robot_path);
  if (!file.ok()) return file.status();
  return RobotAndTrajectory{std::move(robot).value(), std::move(file).value().poses, *path};
}

Status EnsureDirectory(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(path, ec) && !fs::is_directory(path, ec)) {
    return Status::Error(ErrorCode::kInvalidInput, "output `" + path + "` exists and is not a directory");
  }
  fs::create_directories(path, ec);
  if (ec) return Status::Error(ErrorCode::kInvalidInput, "cannot create output directory `" + path + "`: " + ec.message());
  return Status::Ok();
}

}  // namespace selfcal::app
