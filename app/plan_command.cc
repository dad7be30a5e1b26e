// selfcal plan: measurement configurations planned for the user (issue 4), or `--check PLAN` for a plan
// written by hand. Prints the constraints' figures, every criterion before and after, the observability
// indices and the predicted standard deviation of every identifiable parameter.
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include "app/cli_output.h"
#include "app/cli_util.h"
#include "app/output_options.h"
#include "app/run_configuration.h"
#include "app/commands.h"
#include "io/robot_config.h"
#include "io/trajectory_file.h"
#include "kinematics/joint_motion.h"
#include "planning/observability.h"
#include "planning/planner.h"
#include "report/plan_json.h"
#include "sim/sim_world.h"

namespace selfcal::app {

namespace {

struct PlanArgs {
  std::string robot = "config/robots/puma560.yaml";
  std::string configuration = "eye_in_hand";
  std::string start;  // default: config/trajectories/initial_<robot name>.yaml
  std::string out = "out/plan.yaml";
  std::string check;
  std::string criterion = "d-optimal";  // measured best end to end (docs/planning.md)
  double lambda = 1e-7;
  uint64_t seed = 1;
  int pool = 200;
  int identification_poses = 15;
  std::vector<double> box_center_mm, box_size_mm;
  int box_dots = 80;
  uint64_t sim_world_seed = 1;
  std::string scene_from;  // default: the start
  double fx_px = 1000, noise_px = 0.2;
  int width = 640, height = 480;
  double image_margin_px = 5, joint_margin_deg = 5, min_spread_mm = 20, min_axis_sine = 0, max_travel_deg = 90;
  double max_image_motion_px = planning::PlanConstraints().max_image_motion_px;
  double max_fx_stddev_rel = planning::PlanConstraints().max_fx_stddev_rel;
  double min_depth_mm = 250, max_depth_mm = 2000;
};

std::string Fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", digits, v);
  return buffer;
}

void PrintCheck(const planning::PlanCheck& check, std::ostream& out) {
  for (const BarelyMovingJoint& j : check.barely_moving) {
    out << "  warning: " << BarelyMovesSentence(j, "the identification poses")
        << ", and calibrate holds those the data determine worse than their tolerance at the robot description's "
           "value\n";
  }
  if (check.image_motion.empty()) {  // the robot-level checks only
    out << "  max joint travel " << Fixed(RadToDeg(check.max_joint_travel_rad), 1) << " deg\n";
    std::istringstream lines(check.Summary());
    for (std::string line; !check.ok && std::getline(lines, line);) out << "  PROBLEM " << line << "\n";
    return;
  }
  out << "  min camera spread " << Fixed(check.min_spread_m * 1e3, 1) << " mm, min axis sine "
      << Fixed(check.min_axis_sine, 4) << " (" << check.pairs_below_paper_axis_sine
      << " pairs (reference, i) below 0.08: the paper method's f_x), f_x std " << Fixed(check.predicted_fx_stddev_px, 3)
      << " px, min image margin " << Fixed(check.min_image_margin_px, 1) << " px, max joint travel "
      << Fixed(RadToDeg(check.max_joint_travel_rad), 1) << " deg, identifiable " << check.identifiable << "/"
      << check.generic_identifiable << "\n";
  if (!check.image_motion.empty()) {
    out << "  image motion per move (median px):";
    for (const planning::MoveImageMotion& m : check.image_motion) out << " " << Fixed(m.median_px, 0);
    out << "; largest " << Fixed(check.max_image_motion_px, 1) << " px\n";
  }
  if (!check.ok) {
    std::istringstream lines(check.Summary());
    for (std::string line; std::getline(lines, line);) out << "  PROBLEM " << line << "\n";
  }
}

void PrintObservability(const planning::ObservabilityReport& r, const RobotModel& robot, std::ostream& out) {
  if (!r.ok) {
    out << "observability: " << r.message << "\n";
    return;
  }
  out << "observability of the identification poses (" << r.rows << " x " << r.columns
      << " column-normalised Jacobian):\n  condition number " << Fixed(r.condition_number, 1)
      << ", min singular value " << r.min_singular_value << ", log10 product of singular values "
      << Fixed(r.log10_product_singular_values, 2) << ", observability index " << r.observability_index
      << ", noise amplification index " << r.noise_amplification_index << "\n";
  if (!r.prediction_ok) {
    out << "  predicted accuracy: " << r.message << "\n";
    return;
  }
  const KinematicParameters params(robot.num_joints());
  out << "  predicted std at " << r.pixel_noise_px << " px (kinematic bundle adjustment, Cramer-Rao):\n";
  for (size_t k = 0; k < r.free_indices.size(); ++k) {
    const bool length = params.kind(r.free_indices[k]) == ParameterKind::kLength;
    out << "    " << r.free_names[k] << " "
        << (length ? Fixed(r.predicted_stddev[k] * 1e3, 4) + " mm" : Fixed(RadToDeg(r.predicted_stddev[k]), 5) + " deg")
        << "\n";
  }
  out << "    f_x " << Fixed(r.predicted_fx_stddev_px, 3) << " px\n";
}

void AddPlanOptions(CLI::App* cmd, PlanArgs* args) {
  AddRobotOption(cmd, &args->robot);
  AddConfigurationOption(cmd, &args->configuration);
  cmd->add_option("--start", args->start,
                  "Start trajectory (offending poses are repaired from a pool); default: "
                  "config/trajectories/initial_<robot name>.yaml");
  AddOutputOption(cmd, "--out", &args->out, OutputKind::kFileAndParents, "Plan file to write (its directory created)");
  cmd->add_option("--check", args->check,
                  "Check this plan instead of planning (exit 3 when it has problems, 2 when it is for another robot)");
  cmd->add_option("--criterion", args->criterion,
                  "d-optimal (the default: the smallest held-out error end to end, docs/planning.md), a-optimal "
                  "or eq39 (the paper's)");
  cmd->add_option("--lambda", args->lambda, "Weight of Cond(J) in eq. (39) (the paper's 1e-7)")->check(CLI::Range(0.0, 1e6));
  cmd->add_option("--seed", args->seed, "Seed of the candidate pool");
  cmd->add_option("--pool", args->pool, "Candidate pool size")->check(CLI::Range(1, 100000));
  cmd->add_option("--identification-poses", args->identification_poses, "The first N poses identify")
      ->check(CLI::Range(3, 10000));
  cmd->add_option("--box-center-mm", args->box_center_mm, "Dot region: box centre in the base frame (mm)")
      ->delimiter(',')->expected(3);
  cmd->add_option("--box-size-mm", args->box_size_mm, "Dot region: box size (mm)")->delimiter(',')->expected(3);
  cmd->add_option("--box-dots", args->box_dots, "Stand-in dots spread in the box")->check(CLI::Range(8, 100000));
  cmd->add_option("--sim-world-seed", args->sim_world_seed,
                  "Without a box: the simulator's scene of this world seed (dry runs)");
  cmd->add_option("--scene-from", args->scene_from,
                  "Without a box: the trajectory the simulator's scene is placed for (default: the start)");
  cmd->add_option("--fx-px", args->fx_px, "Nominal focal length (px)")->check(CLI::Range(1.0, 1e6));
  cmd->add_option("--width", args->width, "Image width (px)")->check(CLI::Range(16, 100000));
  cmd->add_option("--height", args->height, "Image height (px)")->check(CLI::Range(16, 100000));
  cmd->add_option("--noise-px", args->noise_px, "Pixel noise for the predicted accuracy")->check(CLI::Range(1e-6, 100.0));
  cmd->add_option("--image-margin-px", args->image_margin_px, "Scene points this far inside every image");
  cmd->add_option("--joint-margin-deg", args->joint_margin_deg, "Inside the joint limits by this");
  cmd->add_option("--min-spread-mm", args->min_spread_mm, "Camera centres at least this far apart");
  cmd->add_option("--min-axis-sine", args->min_axis_sine,
                  "The paper method's f_x per pair: optical axes of (reference, i) apart (0: no constraint; 0.08 for "
                  "--method paper)");
  cmd->add_option("--max-image-motion-px", args->max_image_motion_px,
                  "Median image motion of the scene's dots per move (tracking keeps the dots' identities)");
  cmd->add_option("--max-fx-stddev-rel", args->max_fx_stddev_rel,
                  "f_x from the identification poses as a set: bundle Cramer-Rao std / f_x at --noise-px");
  cmd->add_option("--max-travel-deg", args->max_travel_deg, "Largest joint change between consecutive poses");
  cmd->add_option("--min-depth-mm", args->min_depth_mm, "Nearest scene depth");
  cmd->add_option("--max-depth-mm", args->max_depth_mm, "Farthest scene depth");
}

planning::PlanningProblem MakeProblem(const PlanArgs& args, const RobotModel& robot, const io::TrajectoryFile& file) {
  planning::PlanningProblem problem;
  problem.robot = robot;
  problem.camera.width_px = args.width;
  problem.camera.height_px = args.height;
  problem.camera.cx_px = 0.5 * (args.width - 1);
  problem.camera.cy_px = 0.5 * (args.height - 1);
  problem.camera.fx_px = args.fx_px;
  problem.num_identification_poses =
      file.num_identification_poses > 0 && !args.check.empty() ? file.num_identification_poses : args.identification_poses;
  planning::PlanConstraints& c = problem.constraints;
  c.image_margin_px = args.image_margin_px;
  c.joint_margin_rad = DegToRad(args.joint_margin_deg);
  c.min_spread_m = args.min_spread_mm * 1e-3;
  c.min_axis_sine = args.min_axis_sine;
  c.max_joint_travel_rad = DegToRad(args.max_travel_deg);
  c.min_depth_m = args.min_depth_mm * 1e-3;
  c.max_depth_m = args.max_depth_mm * 1e-3;
  c.max_image_motion_px = args.max_image_motion_px;
  c.max_fx_stddev_rel = args.max_fx_stddev_rel;
  c.pixel_noise_px = args.noise_px;
  return problem;
}

// The problem's scene: stand-in dots in the given box, or the simulator's dots. The exit code when the
// command ends here.
// Without a box, the simulator's scene is placed for `start` (the eye-to-hand start, which has no file) or
// for the poses of --scene-from.
std::optional<int> SetScene(const PlanArgs& args, const RobotModel& robot, const io::TrajectoryFile* start,
                            planning::PlanningProblem* problem) {
  if (args.box_center_mm.size() == 3 && args.box_size_mm.size() == 3) {
    const Eigen::Vector3d centre(args.box_center_mm[0], args.box_center_mm[1], args.box_center_mm[2]);
    const Eigen::Vector3d size(args.box_size_mm[0], args.box_size_mm[1], args.box_size_mm[2]);
    problem->scene = planning::Scene::FromBox(centre * 1e-3, size * 1e-3, args.box_dots, args.seed);
    std::cout << "scene: box centre " << centre.transpose() << " mm, size " << size.transpose() << " mm\n";
  } else if (!args.box_center_mm.empty() || !args.box_size_mm.empty()) {
    return Fail(Status::Error(ErrorCode::kInvalidInput, "--box-center-mm and --box-size-mm go together (3 values each)"));
  } else {
    sim::SimOptions sim_options;
    sim_options.world_seed = args.sim_world_seed;
    Result<io::TrajectoryFile> scene_poses = start != nullptr ? Result<io::TrajectoryFile>(*start)
                                                             : io::LoadTrajectoryFileForRobot(
                                                                   ResolveDataPath(args.scene_from), robot, args.robot);
    if (!scene_poses.ok()) return Fail(scene_poses.status());
    const sim::SimResult world = sim::Simulate(robot, scene_poses->poses, sim_options);
    if (!world.ok) {
      return Fail(Status::Error(ErrorCode::kDegenerateData, "no simulated scene for " + args.scene_from + ": " + world.message));
    }
    problem->scene = planning::Scene::FromDots(world.truth.dots_in_base);
    std::cout << "scene: the simulator's " << world.truth.dots_in_base.size()
              << (robot.mount == CameraMount::kEyeToHand ? " dots on the flange's plate" : " dots") << " (world seed "
              << args.sim_world_seed << ", placed for " << (args.scene_from.empty() ? "the start" : args.scene_from) << ")\n";
  }
  return std::nullopt;
}

// --check: the one check of the plan file against the robot config (planning::CheckPlanFor, the same as
// run's preflight) and the observability of its planned_for scene; exit 3 when it has problems.
int CheckOnly(const PlanArgs& args, const RobotModel& robot, const io::TrajectoryFile& file, const std::string& plan_path) {
  const planning::PlanSubject subject = io::PlanSubjectOf(file);
  std::cout << "plan " << plan_path << ": " << file.poses.size() << " poses, "
            << (file.num_identification_poses > 0 ? std::to_string(file.num_identification_poses) : "default")
            << " identify, robot " << (file.robot.empty() ? "not named" : file.robot) << "\n";
  const planning::PlanCheck check = planning::CheckPlanFor(&robot, subject, nullptr);
  for (const std::string& line : check.scope) std::cout << "  checked: " << line << "\n";
  PrintCheck(check, std::cout);
  if (file.planned_for && check.ok) {
    planning::PlanningProblem problem;
    problem.robot = robot;
    problem.robot.mount = file.planned_for->configuration;  // the configuration the plan was made for
    problem.robot.base_from_cam = file.planned_for->base_from_cam;
    std::cout << "  configuration " << CameraMountName(problem.robot.mount) << " (planned_for)\n";
    problem.camera = file.planned_for->camera;
    problem.scene = file.planned_for->scene;
    problem.constraints = file.planned_for->constraints;
    problem.num_identification_poses = file.num_identification_poses > 0 ? file.num_identification_poses
                                                                         : std::min<int>(15, file.poses.size());
    // The check's report is of the same poses, scene and identification poses, at the plan's recorded pixel
    // noise: used when that is --noise-px.
    const planning::ObservabilityReport observability =
        check.observability.ok && check.observability.pixel_noise_px == args.noise_px
            ? check.observability
            : planning::AnalyzeObservability(problem, file.poses, args.noise_px);
    PrintObservability(observability, robot, std::cout);
    OutputDocument()["observability"] = report::ObservabilityJson(observability, robot);
  }
  OutputDocument()["plan_check"] = report::PlanCheckJson(check);
  OutputDocument()["plan_check"]["plan"] = plan_path;
  SetOutcome(check.ok ? "plan_ok" : "plan_refused");
  std::cout << (check.ok ? "plan ok\n" : "plan refused: " + std::to_string(check.problems.size()) + " problems\n");
  return check.ok ? 0 : static_cast<int>(ExitCode::kDegenerateData);
}

void PrintPlanned(const PlanArgs& args, planning::Criterion criterion, const planning::PlanResult& r) {
  std::cout << "planned (" << planning::CriterionName(criterion) << ", " << Fixed(r.seconds * 1e3, 1) << " ms, "
            << r.iterations << " iterations, " << r.evaluations << " evaluations"
            << (r.solver_message.empty() ? "" : "; " + r.solver_message) << "):\n  " << r.stop_rule << "\n";
  PrintCheck(r.check_final, std::cout);
  std::cout << "criteria, start -> planned:\n  eq. (39) " << r.eq39_start.total << " -> " << r.eq39_final.total
            << " (ratio term " << r.eq39_start.ratio_term << " -> " << r.eq39_final.ratio_term << ", Cond(J) "
            << r.eq39_start.condition_number << " -> " << r.eq39_final.condition_number << ", lambda " << args.lambda
            << ")\n  D (log det information) " << r.fisher_start.log_det << " -> " << r.fisher_final.log_det
            << "\n  A (sum of variance / prior variance) " << r.fisher_start.a_value << " -> " << r.fisher_final.a_value
            << "\n";
}

// The planned poses as a plan file at --out, with their provenance.
int WritePlan(const PlanArgs& args, planning::Criterion criterion, const planning::PlanningProblem& problem,
              const std::string& plan_path, const planning::PlanResult& r) {
  io::TrajectoryFile plan;
  plan.poses = r.poses;
  plan.robot = problem.robot.name;
  plan.num_identification_poses = problem.num_identification_poses;
  const bool box = args.box_center_mm.size() == 3;
  plan.description = "planned from " + plan_path + " by `selfcal plan --robot " + args.robot + " --criterion " +
                     planning::CriterionName(criterion) + " --seed " + std::to_string(args.seed) +
                     (!box && args.sim_world_seed != 1 ? " --sim-world-seed " + std::to_string(args.sim_world_seed) : "") +
                     "` (docs/planning.md)";
  plan.planned_for = planning::PlannedFor{problem.camera, problem.scene, problem.constraints, problem.robot.mount,
                                          problem.robot.base_from_cam};
  std::ostringstream provenance;
  provenance << "criterion " << planning::CriterionName(criterion) << ", lambda " << args.lambda << ", seed " << args.seed
             << ", pool " << args.pool << "; eq39 " << r.eq39_start.total << " -> " << r.eq39_final.total
             << ", D " << r.fisher_start.log_det << " -> " << r.fisher_final.log_det << ", A " << r.fisher_start.a_value
             << " -> " << r.fisher_final.a_value;
  plan.planner = provenance.str();
  const size_t slash = args.out.find_last_of('/');
  if (slash != std::string::npos && slash > 0) {
    if (Status s = EnsureDirectory(args.out.substr(0, slash)); !s.ok()) return Fail(s);
  }
  if (Status s = io::SaveTrajectoryFile(plan, args.out); !s.ok()) return Fail(s);
  std::cout << "wrote " << args.out << "\n";
  AddOutputFile("plan", args.out);
  return 0;
}

// Plans from the start trajectory, prints the figures before and after, and writes the plan.
int PlanAndWrite(const PlanArgs& args, planning::Criterion criterion, const planning::PlanningProblem& problem,
                 const io::TrajectoryFile& file, const std::string& plan_path) {
  planning::PlannerOptions options;
  options.criterion = criterion;
  options.lambda = args.lambda;
  options.seed = args.seed;
  options.pool_size = args.pool;
  options.fisher.pixel_noise_px = args.noise_px;
  options.progress = Progress();
  const planning::PlanResult r = planning::PlanMeasurements(problem, file.poses, options);
  OutputDocument()["plan"] = report::PlanResultJson(r);
  std::cout << "start " << plan_path << ":\n";
  PrintCheck(r.check_start, std::cout);
  if (r.repaired_poses > 0) std::cout << "  repaired: " << r.repaired_poses << " poses replaced from the pool\n";
  if (!r.ok) return Fail(Status::Error(ErrorCode::kDegenerateData, r.message));
  PrintPlanned(args, criterion, r);
  // The final check's report is of these poses at the check's pixel noise, --noise-px (MakeProblem).
  const planning::ObservabilityReport observability =
      r.check_final.observability.ok && r.check_final.observability.pixel_noise_px == args.noise_px
          ? r.check_final.observability
          : planning::AnalyzeObservability(problem, r.poses, args.noise_px);
  PrintObservability(observability, problem.robot, std::cout);
  OutputDocument()["observability"] = report::ObservabilityJson(observability, problem.robot);
  return WritePlan(args, criterion, problem, plan_path, r);
}

// --configuration eye_to_hand: the robot in the simulated eye-to-hand cell (its fixed camera in front of the
// flange at home), from --start or the robot's eye-to-hand start; the scene the plate's dots.
int PlanEyeToHand(const PlanArgs& given, const RobotModel& config_robot, planning::Criterion criterion) {
  PlanArgs a = given;
  // The plate fills a small part of the fixed camera's image: f_x is determined less well than from a wrist
  // camera's scene, so the bound on its Cramer-Rao std is 1 % of f_x unless given.
  if (a.max_fx_stddev_rel == planning::PlanConstraints().max_fx_stddev_rel) a.max_fx_stddev_rel = 0.01;
  Result<RobotModel> robot = RobotInSimulatedCell(config_robot, a.robot, CameraMount::kEyeToHand);
  if (!robot.ok()) return Fail(robot.status());
  io::TrajectoryFile start;
  std::string start_name = a.start;
  if (a.start.empty()) {
    Result<std::vector<Eigen::VectorXd>> poses = EyeToHandStart(*robot, a.robot, 25);
    if (!poses.ok()) return Fail(poses.status());
    start.poses = *poses;
    start.robot = robot->name;
    start_name = "the eye-to-hand start of " + a.robot;
  } else {
    Result<io::TrajectoryFile> file = io::LoadTrajectoryFileForRobot(ResolveDataPath(a.start), *robot, a.robot);
    if (!file.ok()) return Fail(file.status());
    start = *file;
  }
  std::cout << "configuration eye_to_hand: fixed camera at " << robot->base_from_cam.translation.transpose() * 1e3
            << " mm in the base frame, dots on a plate carried by the flange\n";
  planning::PlanningProblem problem = MakeProblem(a, *robot, start);
  if (const std::optional<int> code = SetScene(a, *robot, a.scene_from.empty() ? &start : nullptr, &problem)) return *code;
  if (const std::string invalid = problem.Validate(); !invalid.empty()) {
    return Fail(Status::Error(ErrorCode::kInvalidInput, "plan options: " + invalid));
  }
  return PlanAndWrite(a, criterion, problem, start, start_name);
}

int RunPlanCommand(const PlanArgs& args) {
  Result<RobotModel> robot = io::LoadRobotModel(ResolveDataPath(args.robot));
  if (!robot.ok()) return Fail(robot.status());
  planning::Criterion criterion;
  if (!planning::ParseCriterion(args.criterion, &criterion)) {
    return Fail(Status::Error(ErrorCode::kInvalidInput, "--criterion `" + args.criterion + "`: expected eq39, d-optimal or a-optimal"));
  }
  PlanArgs a = args;  // the defaults follow the robot
  Result<CameraMount> mount = ParseConfiguration(a.configuration);
  if (!mount.ok()) return Fail(mount.status());
  if (*mount == CameraMount::kEyeToHand && a.check.empty()) return PlanEyeToHand(a, *robot, criterion);
  if (a.start.empty() && a.check.empty()) {
    Result<std::string> start = TrajectoryForRobot("", robot->name, a.robot);
    if (!start.ok()) return Fail(start.status());
    a.start = *start;
  }
  if (a.scene_from.empty()) a.scene_from = a.start;
  const std::string plan_path = a.check.empty() ? a.start : a.check;
  // A plan or start made for another robot is a usage error naming both robots (exit 2).
  Result<io::TrajectoryFile> file = io::LoadTrajectoryFileForRobot(ResolveDataPath(plan_path), *robot, a.robot);
  if (!file.ok()) return Fail(file.status());
  if (!a.check.empty()) return CheckOnly(a, *robot, *file, plan_path);
  planning::PlanningProblem problem = MakeProblem(a, *robot, *file);
  if (const std::optional<int> code = SetScene(a, *robot, nullptr, &problem)) return *code;
  if (const std::string invalid = problem.Validate(); !invalid.empty()) {
    return Fail(Status::Error(ErrorCode::kInvalidInput, "plan options: " + invalid));
  }
  return PlanAndWrite(a, criterion, problem, *file, plan_path);
}

}  // namespace

Command AddPlanCommand(CLI::App& app) {
  auto args = std::make_shared<PlanArgs>();
  CLI::App* cmd = app.add_subcommand("plan", "Plan measurement configurations (eq. 39, D- or A-optimal), or check a plan");
  AddPlanOptions(cmd, args.get());
  return [args]() { return RunPlanCommand(*args); };
}

}  // namespace selfcal::app
