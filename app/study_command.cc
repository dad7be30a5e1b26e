// selfcal study: Monte Carlo reproduction of the paper's Table 2 and Fig. 6, and the kinematic bundle
// adjustment beyond it (simulation/study.h).
#include <iostream>

#include "app/cli_output.h"
#include "app/cli_util.h"
#include "app/output_options.h"
#include "app/commands.h"
#include "app/run_configuration.h"
#include "report/study_report.h"
#include "io/report_json.h"
#include "io/robot_config.h"
#include "io/trajectory_file.h"

namespace selfcal::app {

namespace {
struct StudyArgs {
  std::string robot = "config/robots/puma560.yaml";
  std::vector<std::string> trajectories;  // default: initial=<the robot's shipped trajectory>
  int runs = 200;
  std::vector<double> noise = {0.0, 0.2, 0.5};
  uint64_t seed = 1;
  std::string out = "out/study.json";
  bool no_opencv = false;
  bool no_bound = false;
  bool bound_sweep = false;
  bool no_bundle = false;
  bool flat_sheet = false;
  bool rendered = false;
  int jobs = 0;
  std::string configuration = "eye_in_hand";
};

// The robot (in the simulated cell of --configuration) and the trajectories of a study, or why not.
Status LoadStudyInputs(const StudyArgs& args, RobotModel* robot, std::vector<simulation::TrajectorySpec>* trajectories) {
  Result<CameraMount> mount = ParseConfiguration(args.configuration);
  if (!mount.ok()) return mount.status();
  if (*mount == CameraMount::kEyeToHand && (args.flat_sheet || args.rendered)) {
    return Status::Error(ErrorCode::kInvalidInput,
                         std::string("--configuration eye_to_hand: ") + (args.flat_sheet ? "--flat-sheet" : "--rendered") +
                             " is not available there (the simulated eye-to-hand cell is a plate of point dots on the flange)");
  }
  Result<RobotModel> config = io::LoadRobotModel(ResolveDataPath(args.robot));
  if (!config.ok()) return config.status();
  Result<RobotModel> cell = RobotInSimulatedCell(*config, args.robot, *mount);
  if (!cell.ok()) return cell.status();
  *robot = *cell;
  std::vector<std::string> specs = args.trajectories;
  if (specs.empty() && *mount == CameraMount::kEyeToHand) {
    // No eye-to-hand trajectory is shipped: the start `simulate` and `plan` take (EyeToHandStart).
    Result<std::vector<Eigen::VectorXd>> start = EyeToHandStart(*robot, args.robot, 25);
    if (!start.ok()) return start.status();
    trajectories->push_back({"e2h-start", *start});
    return Status::Ok();
  }
  if (specs.empty()) {
    Result<std::string> shipped = TrajectoryForRobot("", robot->name, args.robot);
    if (!shipped.ok()) return shipped.status();
    specs.push_back("initial=" + *shipped);
  }
  for (const std::string& spec : specs) {
    const size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0) {
      return Status::Error(ErrorCode::kInvalidInput, "--trajectory `" + spec + "`: expected NAME=FILE");
    }
    const std::string path = spec.substr(eq + 1);
    Result<io::TrajectoryFile> file = io::LoadTrajectoryFileForRobot(ResolveDataPath(path), *robot, args.robot);
    if (!file.ok()) return file.status();
    if (file->planned_for && file->planned_for->configuration != *mount) {
      return Status::Error(ErrorCode::kInvalidInput, "--trajectory " + path + " was planned for configuration " +
                                                         CameraMountName(file->planned_for->configuration) +
                                                         ", this study is " + args.configuration + " (--configuration)");
    }
    trajectories->push_back({spec.substr(0, eq), file->poses});
  }
  return Status::Ok();
}
}  // namespace

Command AddStudyCommand(CLI::App& app) {
  auto args = std::make_shared<StudyArgs>();
  CLI::App* cmd = app.add_subcommand("study", "Monte Carlo: the paper's Table 2 and Fig. 6 on the simulator");
  AddRobotOption(cmd, &args->robot);
  AddConfigurationOption(cmd, &args->configuration);
  cmd->add_option("--trajectory", args->trajectories,
                  "NAME=FILE, repeatable (each for the robot); default: initial=config/trajectories/initial_<robot name>.yaml "
                  "(eye_to_hand: e2h-start=the 25-pose eye-to-hand start of plan and simulate)");
  cmd->add_option("--runs", args->runs, "Runs per cell")->check(CLI::Range(1, 100000));
  cmd->add_option("--noise-px", args->noise, "Pixel noise levels (std, px)")->delimiter(',');
  cmd->add_option("--seed", args->seed, "Base seed");
  AddOutputOption(cmd, "--out", &args->out, OutputKind::kFile, "JSON output file");
  cmd->add_flag("--no-opencv", args->no_opencv, "Skip the OpenCV comparison row");
  cmd->add_flag("--no-bound", args->no_bound, "Skip the Cramer-Rao rows");
  cmd->add_flag("--no-bundle", args->no_bundle, "Skip the kinematic bundle adjustment rows");
  cmd->add_flag("--flat-sheet", args->flat_sheet,
                "Dots on one plane: the paper pipeline is degenerate there (its rows count failures), the BA is not");
  cmd->add_flag("--rendered", args->rendered,
                "Also run on rendered images (detector centroids) at grey-level noise 0 / 2 / 5 and blur 1 px; "
                "dots spaced so that none touch in any view, for every row");
  cmd->add_option("--jobs", args->jobs,
                  "Runs computed at once (threads); default 0: every core. The results do not depend on it")
      ->check(CLI::Range(0, 1024));
  cmd->add_flag("--bound-sweep", args->bound_sweep,
                "Also sweep the two-view Cramer-Rao bound over field of view, depth spread and baseline");
  return [args]() {
    RobotModel robot;
    std::vector<simulation::TrajectorySpec> trajectories;
    if (Status s = LoadStudyInputs(*args, &robot, &trajectories); !s.ok()) return Fail(s);
    for (double n : args->noise) {
      if (!(n >= 0 && n < 10)) return Fail(Status::Error(ErrorCode::kInvalidInput, "--noise-px: " + std::to_string(n) + " is not in [0, 10)"));
    }
    simulation::StudyOptions options;
    options.runs = args->runs;
    options.noise_levels_px = args->noise;
    options.seed = args->seed;
    options.with_opencv = !args->no_opencv;
    options.with_bound = !args->no_bound;
    options.with_bundle = !args->no_bundle;
    options.sim.flat_sheet = args->flat_sheet;
    options.progress = Progress();
    options.jobs = args->jobs;
    if (args->rendered) {
      options.sim.separation_dot_radius_m = options.rendered.dot_radius_m;
      // Image noise levels (grey levels on a 200/40 paper/ink contrast) and the centroid noise the solvers
      // are told, from the centroid table of a 20-run study (docs/paper-reproduction.md).
      options.rendered_levels = {{"img-0", 0, 0, 0.01}, {"img-I", 2, 0, 0.01}, {"img-II", 5, 0, 0.02},
                                 {"img-II-blur", 5, 1.0, 0.02}};
    }
    const simulation::StudyReport study = simulation::RunStudy(robot, trajectories, options);
    report::PrintStudyTables(study, std::cout);
    nlohmann::json json = report::StudyJson(study, options);
    if (args->bound_sweep) {
      for (double noise : args->noise) {
        if (noise <= 0) continue;
        const std::vector<simulation::BoundPoint> sweep =
            simulation::SweepTwoViewBound(simulation::DefaultBoundGrid(noise), args->seed, Progress());
        report::PrintBoundSweep(sweep, std::cout);
        json["bound_sweep"].push_back(report::BoundSweepJson(sweep));
      }
    }
    if (Status s = io::WriteJsonFile(json, args->out); !s.ok()) return Fail(s);
    std::cout << "JSON: " << args->out << "\n";
    AddOutputFile("study", args->out);
    OutputDocument()["study"] = json;  // the tables' figures, as in the file
    return 0;
  };
}

}  // namespace selfcal::app
