// selfcal identifiability --robot FILE --trajectory FILE: which parameters the relative camera poses of
// a trajectory can identify (../shared/DESIGN.md section 4), with metric and with up-to-scale translations.
#include <iostream>

#include "app/cli_util.h"
#include "app/commands.h"
#include "geometry/rigid3.h"
#include "identification/identifiability.h"
#include "kinematics/joint_motion.h"
#include "io/robot_config.h"
#include "io/trajectory_file.h"

namespace selfcal::app {

namespace {
struct IdentifiabilityArgs {
  std::string robot = "config/robots/puma560.yaml";
  std::string trajectory;  // default: the robot's shipped trajectory (TrajectoryForRobot)
  int identification_poses = 15;
};

void Print(const char* title, const identification::IdentifiabilityReport& r) {
  std::cout << title << ": " << r.rank << " of " << r.num_parameters << " parameters identifiable (condition number "
            << r.condition_number << ")\n  fixed:";
  for (const std::string& n : r.fixed_names) std::cout << " " << n;
  std::cout << "\n  unidentifiable directions:\n";
  for (const std::string& c : r.null_combinations) std::cout << "    " << c << "\n";
}
}  // namespace

Command AddIdentifiabilityCommand(CLI::App& app) {
  auto args = std::make_shared<IdentifiabilityArgs>();
  CLI::App* cmd = app.add_subcommand("identifiability", "Rank analysis of the identification Jacobian");
  AddRobotOption(cmd, &args->robot);
  cmd->add_option("--trajectory", args->trajectory,
                  "Trajectory file (for the robot); default: config/trajectories/initial_<robot name>.yaml");
  cmd->add_option("--identification-poses", args->identification_poses, "Use the first N poses")->check(CLI::Range(2, 10000));
  return [args]() {
    Result<RobotAndTrajectory> loaded = LoadRobotAndTrajectory(args->robot, args->trajectory);
    if (!loaded.ok()) return Fail(loaded.status());
    const RobotModel* robot = &loaded->robot;
    std::vector<Eigen::VectorXd> poses = loaded->joints;
    if (static_cast<int>(poses.size()) > args->identification_poses) poses.resize(args->identification_poses);
    const Eigen::VectorXd rho = KinematicParameters::Nominal(*robot);
    std::cout << "robot " << robot->name << ", " << poses.size() << " poses, measurements cam_1_from_cam_i\n";
    for (const BarelyMovingJoint& j : BarelyMovingJoints(poses)) {
      std::cout << "warning: " << BarelyMovesSentence(j, "these poses")
                << ", and calibrate holds those the data determine worse than their tolerance at the robot "
                   "description's value\n";
    }
    identification::IdentifiabilityOptions options;
    Print("metric relative poses", identification::AnalyzeIdentifiability(*robot, rho, poses, 0, options));
    options.scale_known = false;
    Print("relative poses up to one scale", identification::AnalyzeIdentifiability(*robot, rho, poses, 0, options));
    return 0;
  };
}

}  // namespace selfcal::app
