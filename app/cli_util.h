// Small helpers shared by the subcommands: default file lookup, exit-code mapping, printing.
#pragma once

#include <string>

#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Core>

#include "app/exit_codes.h"
#include "kinematics/robot_model.h"
#include "base/status.h"
#include "calibration/calibrate.h"

namespace selfcal::app {

// `path` as given if it exists, else in the data directories of the installed program (share/selfcal; for
// a program run from its build tree also the source tree's root): base/install_layout.h's FindDataFile, so
// that the shipped defaults under config/ work from any directory.
std::string ResolveDataPath(const std::string& path);

// Prints "selfcal: <code name>: message" to stderr and returns the exit code.
int Fail(const Status& status);

// The exit code of a calibration verdict: accepted 0; invalid input 2; degenerate, no scale 3; unconverged,
// solver failure 5.
ExitCode ExitCodeFor(calibration::Verdict verdict);

// SHA-256 of a file's bytes as 64 hex digits (base/sha256.h): provenance in reports (P7). "" when the path
// is not a readable regular file (e.g. a session directory, whose provenance is its session.json).
std::string FileSha256(const std::string& path);

// `--robot PATH`: the nominal robot config (docs/frames-and-units.md), as every simulation command takes it.
void AddRobotOption(CLI::App* cmd, std::string* robot_path);

// The trajectory a command takes for a robot: `given` when set, else the robot's shipped trajectory
// (io::InitialTrajectoryPath of its name). Refused (kInvalidInput, exit 2) when none is given and none is
// shipped for that robot, saying how to make one.
Result<std::string> TrajectoryForRobot(const std::string& given, const std::string& robot_name, const std::string& robot_path);

// The nominal robot of a config and a trajectory file for it (`trajectory_path` empty: TrajectoryForRobot),
// both paths resolved by ResolveDataPath; a trajectory for another robot is refused with both names
// (io::LoadTrajectoryFileForRobot, exit 2).
struct RobotAndTrajectory {
  RobotModel robot;
  std::vector<Eigen::VectorXd> joints;
  std::string trajectory_path;  // the one used
};
Result<RobotAndTrajectory> LoadRobotAndTrajectory(const std::string& robot_path, const std::string& trajectory_path);

// Creates the directory (and parents). Refuses an existing non-directory.
Status EnsureDirectory(const std::string& path);

}  // namespace selfcal::app
