// selfcal compensate MODEL --targets FILE --out JOINTS [--robot NOMINAL]: target flange or camera poses ->
// the joint angles that reach them on the calibrated arm (compensation/compensation.h, docs/compensation.md),
// written as a trajectory file `selfcal run` takes. Exit 0 with the file, 5 when a target does not converge,
// 7 when a solution lies outside the joint limits (nothing written then).
#include <iomanip>
#include <iostream>
#include <vector>

#include "app/cli_output.h"
#include "app/cli_util.h"
#include "app/output_options.h"
#include "app/commands.h"
#include "compensation/compensation.h"
#include "io/robot_config.h"
#include "io/targets_file.h"
#include "io/trajectory_file.h"

namespace selfcal::app {
namespace {

struct CompensateArgs {
  std::string model, targets, out, robot;
};

std::vector<double> Degrees(const Eigen::VectorXd& q) {
  std::vector<double> out;
  for (int j = 0; j < q.size(); ++j) out.push_back(RadToDeg(q[j]));
  return out;
}

// One line per target on stdout, and the --json figures.
void PrintReport(const compensation::CompensationReport& report, const RobotModel& calibrated) {
  nlohmann::json targets = nlohmann::json::array();
  for (size_t k = 0; k < report.targets.size(); ++k) {
    const compensation::TargetSolution& s = report.targets[k];
    const double change = (s.compensated.q - s.nominal.q).cwiseAbs().maxCoeff();
    std::cout << "target " << k << ": residual " << std::setprecision(3) << s.compensated.position_residual_m * 1e3
              << " mm / " << RadToDeg(s.compensated.rotation_residual_rad) << " deg, joints moved up to "
              << RadToDeg(change) << " deg from the nominal solution";
    if (!s.compensated.converged) std::cout << ", NOT CONVERGED";
    for (int j : s.joints_outside_limits) {
      const JointLimits& l = calibrated.limits[j - 1];
      std::cout << ", joint " << j << " at " << RadToDeg(s.compensated.q[j - 1]) << " deg outside its limits ["
                << RadToDeg(l.min_rad) << ", " << RadToDeg(l.max_rad) << "] deg";
    }
    std::cout << "\n";
    targets.push_back({{"converged", s.compensated.converged},
                       {"position_residual_mm", s.compensated.position_residual_m * 1e3},
                       {"rotation_residual_deg", RadToDeg(s.compensated.rotation_residual_rad)},
                       {"nominal_converged", s.nominal.converged},
                       {"max_joint_change_deg", RadToDeg(change)},
                       {"joints_outside_limits", s.joints_outside_limits},
                       {"joints_deg", Degrees(s.compensated.q)}});
  }
  OutputDocument()["compensation"] = {{"targets", targets},
                                      {"not_converged", report.not_converged},
                                      {"outside_limits", report.outside_limits}};
}

int RunCompensate(const CompensateArgs& args) {
  Result<io::CalibratedModel> calibrated = io::LoadCalibratedModel(args.model);
  if (!calibrated.ok()) return Fail(calibrated.status());
  const RobotModel& model = calibrated->model;
  RobotModel nominal = model;  // without --robot: the seeds are refined on the calibrated model directly
  if (!args.robot.empty()) {
    Result<RobotModel> loaded = io::LoadRobotModel(args.robot);
    if (!loaded.ok()) return Fail(loaded.status());
    if (loaded->num_joints() != model.num_joints()) {
      return Fail(Status::Error(ErrorCode::kInvalidInput, "--robot " + args.robot + " has " +
                                                              std::to_string(loaded->num_joints()) + " joints, " +
                                                              args.model + " " + std::to_string(model.num_joints())));
    }
    nominal = *loaded;
  }
  Result<io::TargetsFile> targets = io::LoadTargetsFile(args.targets, model.num_joints());
  if (!targets.ok()) return Fail(targets.status());
  if (!targets->robot.empty() && targets->robot != model.name) {
    return Fail(Status::Error(ErrorCode::kInvalidInput, args.targets + ":" + std::to_string(targets->robot_line) + ": `robot` = `" + targets->robot +
                                                            "`, but the calibrated model is `" + model.name + "`"));
  }
  std::vector<compensation::Target> list;
  for (const io::PoseTarget& t : targets->targets) list.push_back({t.base_from_target, t.seed});
  const compensation::TargetFrame frame =
      targets->camera_frame ? compensation::TargetFrame::kCamera : compensation::TargetFrame::kFlange;
  const compensation::CompensationReport report = compensation::Compensate(nominal, model, frame, list);
  PrintReport(report, model);
  if (report.not_converged > 0) {
    std::cerr << "selfcal: compensate: " << report.not_converged << " target(s) not reached (residual above 1e-9 m / "
              << "1e-9 rad); " << args.out << " not written\n";
    return static_cast<int>(ExitCode::kSolverFailure);
  }
  if (report.outside_limits > 0) {
    std::cerr << "selfcal: compensate: " << report.outside_limits
              << " target(s) reachable only outside the joint limits; " << args.out << " not written\n";
    return static_cast<int>(ExitCode::kOutsideLimits);
  }
  std::vector<Eigen::VectorXd> joints;
  for (const compensation::TargetSolution& s : report.targets) joints.push_back(s.compensated.q);
  const std::string description = "compensated joints for the " + std::to_string(joints.size()) + " " +
                                  (targets->camera_frame ? "camera" : "flange") + " targets of " + args.targets +
                                  " on " + args.model + " (selfcal compensate)";
  if (Status s = io::SaveTrajectory(joints, args.out, model.name, description); !s.ok()) return Fail(s);
  std::cout << "compensated joints: " << args.out << "\n";
  AddOutputFile("joints", args.out);
  return 0;
}

}  // namespace

Command AddCompensateCommand(CLI::App& app) {
  auto args = std::make_shared<CompensateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compensate",
      "Target flange or camera poses -> the joint angles that reach them on the calibrated arm (a trajectory file "
      "for a controller that takes no model)");
  cmd->add_option("model", args->model, "Calibrated model (calibrated_model.yaml of calibrate)")->required();
  cmd->add_option("--targets", args->targets, "Target poses in the base frame (docs/compensation.md)")->required();
  AddOutputOption(cmd, "--out", &args->out, OutputKind::kFile, "Joint file to write (docs/trajectory-format.md)")->required();
  cmd->add_option("--robot", args->robot,
                  "The nominal robot config: each target is first solved on it (what the controller's own model "
                  "would command), from the target's seed or the previous solution; without it the seeds are used");
  return [args]() { return RunCompensate(*args); };
}

}  // namespace selfcal::app
