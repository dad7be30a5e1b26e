// selfcal simulate: a seeded simulated robot with hidden errors, its observations written to a file, the
// calibration run from that file, and the result compared with the hidden truth.
// selfcal make-trajectory: writes the smooth "initial" trajectory around the simulated scene.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include <nlohmann/json.hpp>

#include "app/calibrate_command.h"
#include "app/session_command.h"
#include "app/cli_output.h"
#include "app/cli_util.h"
#include "app/output_options.h"
#include "app/run_configuration.h"
#include "app/commands.h"
#include "io/report_json.h"
#include "io/observations_file.h"
#include "io/robot_config.h"
#include "io/trajectory_file.h"
#include "sim/sim_world.h"
#include "sim/trajectory_generator.h"
#include "simulation/session_audit.h"

namespace selfcal::app {

namespace {

struct SimulateArgs {
  std::string robot = "config/robots/puma560.yaml";
  std::string configuration = "eye_in_hand";
  std::string trajectory;  // eye_to_hand: default the robot's eye-to-hand start (EyeToHandStart)  // default: the robot's shipped trajectory (TrajectoryForRobot)
  std::string out = "out/simulate";
  double noise_px = 0.2;
  double joint_noise_deg = 0;
  uint64_t seed = 1;
  bool perturb_gauge = false;
  std::string method = "bundle";
  bool flat_sheet = false;
  bool points = false;      // the fast point-projection mode (no images, no session)
  double grey_noise = 2.0;  // image mode
  double blur_px = 0.0;
  int supersampling = 4;
  bool no_html = false;     // --no-html: report.html not written
  std::string live_view = "auto";  // image mode: --live-view of `selfcal run`
};

nlohmann::json TruthJson(const sim::SimResult& world) {
  const KinematicParameters params(world.truth.nominal.num_joints());
  nlohmann::json rho = nlohmann::json::object();
  for (int i = 0; i < params.size(); ++i) {
    const double v = world.truth.rho_true[i];
    rho[params.name(i) + (params.kind(i) == ParameterKind::kLength ? "_mm" : "_deg")] =
        params.kind(i) == ParameterKind::kLength ? v * 1e3 : RadToDeg(v);
  }
  nlohmann::json dots = nlohmann::json::array();
  for (const Eigen::Vector3d& p : world.truth.dots_in_base) dots.push_back({p.x() * 1e3, p.y() * 1e3, p.z() * 1e3});
  const bool e2h = world.truth.nominal.mount == CameraMount::kEyeToHand;
  nlohmann::json truth = {
      {"format", "selfcal-sim-truth"},
      {"version", 1},
      {"note", "hidden from the solver; rho in the nominal model's parameterisation (corrections for base and cam)"},
      {"configuration", CameraMountName(world.truth.nominal.mount)},
      {"fx_px", world.truth.camera_true.fx_px},
      {"rho", rho},
      {e2h ? "dots_in_flange_mm" : "dots_in_base_mm", dots}};
  if (e2h) {
    const Rigid3 c = sim::FixedCameraTruth(world.truth);
    nlohmann::json rows = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) rows.push_back({c.rotation(r, 0), c.rotation(r, 1), c.rotation(r, 2)});
    truth["base_from_cam"] = {{"xyz_mm", {c.translation.x() * 1e3, c.translation.y() * 1e3, c.translation.z() * 1e3}},
                              {"rotation", rows}};
  }
  return truth;
}

// Mean error of the relative poses reference -> each verification pose predicted by a model against the
// truth (gauge-free). position in m, rotation in rad.
PoseDifference MeanVerificationPoseError(const sim::SimResult& world, const ObservationSet& obs, int ref,
                                         const RobotModel& model, const Eigen::VectorXd& rho) {
  PoseDifference mean;
  int n = 0;
  for (int v : obs.PosesWithRole(PoseRole::kVerification)) {
    const Rigid3 truth_rel = world.truth.base_from_cam[ref].Inverse() * world.truth.base_from_cam[v];
    const Rigid3 model_rel =
        PointsFromCam(model, rho, obs.poses[ref].joints_rad).Inverse() * PointsFromCam(model, rho, obs.poses[v].joints_rad);
    const PoseDifference d = ComparePoses(truth_rel, model_rel);
    mean.position_m += d.position_m;
    mean.rotation_rad += d.rotation_rad;
    ++n;
  }
  if (n > 0) {
    mean.position_m /= n;
    mean.rotation_rad /= n;
  }
  return mean;
}

void PrintVerificationPoseErrors(const PoseDifference& nominal, const PoseDifference& calibrated, const char* label,
                                 std::ostream& out) {
  out << "verification relative poses, mean error: nominal " << nominal.position_m * 1e3 << " mm / "
      << RadToDeg(nominal.rotation_rad) << " deg; " << label << " " << calibrated.position_m * 1e3 << " mm / "
      << RadToDeg(calibrated.rotation_rad) << " deg\n";
}

// Calibrated vs true, in the quantities that do not depend on the gauge.
nlohmann::json CompareWithTruth(const sim::SimResult& world, const ObservationSet& obs,
                                const calibration::PaperPipelineReport& report, std::ostream& out) {
  const RobotModel true_robot = ApplyParameters(world.truth.nominal, world.truth.rho_true);
  const RobotModel& nominal = world.truth.nominal;
  const RobotModel& calibrated = report.calibrated_robot;
  nlohmann::json links = nlohmann::json::array();
  out << "\nkinematic parameters (free ones), nominal / true / calibrated, error of calibrated:\n";
  const KinematicParameters params(nominal.num_joints());
  for (int i = 0; i < nominal.num_joints(); ++i) {
    const LinkParameters* ls[3] = {&nominal.links[i], &true_robot.links[i], &calibrated.links[i]};
    for (int k = 0; k < 5; ++k) {
      const int index = KinematicParameters::JointOffset(i) + k;
      if (std::count(report.identifiability.free_indices.begin(), report.identifiability.free_indices.end(), index) == 0) {
        continue;
      }
      double v[3];
      for (int m = 0; m < 3; ++m) {
        const double raw[5] = {ls[m]->alpha, ls[m]->a, ls[m]->beta, ls[m]->theta, ls[m]->d};
        v[m] = (k == 1 || k == 4) ? raw[k] * 1e3 : RadToDeg(raw[k]);
      }
      out << "  " << std::left << std::setw(10) << params.name(index) << std::right << std::fixed << std::setprecision(4)
          << std::setw(12) << v[0] << std::setw(12) << v[1] << std::setw(12) << v[2] << "   error " << std::setw(9)
          << v[2] - v[1] << " " << (k == 1 || k == 4 ? "mm" : "deg") << "\n";
      links.push_back({{"name", params.name(index)}, {"unit", k == 1 || k == 4 ? "mm" : "deg"}, {"nominal", v[0]},
                       {"true", v[1]}, {"calibrated", v[2]}, {"error", v[2] - v[1]}});
    }
  }
  const bool e2h = nominal.mount == CameraMount::kEyeToHand;
  const char* cam_name = e2h ? "base_from_cam" : "flange_from_cam";
  const PoseDifference cam_error = e2h ? ComparePoses(true_robot.base_from_cam, calibrated.base_from_cam)
                                       : ComparePoses(true_robot.flange_from_cam, calibrated.flange_from_cam);
  const PoseDifference cam_nominal = e2h ? ComparePoses(true_robot.base_from_cam, nominal.base_from_cam)
                                         : ComparePoses(true_robot.flange_from_cam, nominal.flange_from_cam);
  out << cam_name << " error: nominal " << cam_nominal.position_m * 1e3 << " mm / " << RadToDeg(cam_nominal.rotation_rad)
      << " deg, calibrated " << cam_error.position_m * 1e3 << " mm / " << RadToDeg(cam_error.rotation_rad)
      << (e2h ? " deg (includes what the base offsets absorb)\n" : " deg (includes what the fixed joint-6 offsets absorb)\n");
  out << "f_x: nominal " << obs.camera.fx_px << ", true " << world.truth.camera_true.fx_px << ", calibrated "
      << report.fx_px << " px\n";
  const Eigen::VectorXd rho0 = KinematicParameters::Nominal(nominal);
  const PoseDifference before = MeanVerificationPoseError(world, obs, report.reference_pose, nominal, rho0);
  const PoseDifference after =
      MeanVerificationPoseError(world, obs, report.reference_pose, calibrated, report.calibrated_rho);
  PrintVerificationPoseErrors(before, after, "calibrated", out);
  out.unsetf(std::ios::floatfield);
  return {{"links", links},
          {std::string(cam_name) + "_error_mm", cam_error.position_m * 1e3},
          {std::string(cam_name) + "_error_deg", RadToDeg(cam_error.rotation_rad)},
          {"fx_true_px", world.truth.camera_true.fx_px},
          {"fx_calibrated_px", report.fx_px},
          {"verification_pose_error_mean_mm", {{"nominal", before.position_m * 1e3}, {"calibrated", after.position_m * 1e3}}},
          {"verification_pose_error_mean_deg",
           {{"nominal", RadToDeg(before.rotation_rad)}, {"calibrated", RadToDeg(after.rotation_rad)}}}};
}

// The bundle adjustment's result against the truth: every free parameter with its reported sigma (the
// bundle's gauge is the nominal model's, as the simulator's truth is unless --perturb-gauge), f_x, the
// verification relative poses and the held-out 3-D errors before and after.
nlohmann::json CompareBundleWithTruth(const sim::SimResult& world, const ObservationSet& obs,
                                      const calibration::BundleStageReport& stage, bool gauge_perturbed, std::ostream& out) {
  const bundle::BundleReport& b = stage.bundle;
  const RobotModel& nominal = world.truth.nominal;
  const KinematicParameters params(nominal.num_joints());
  const Eigen::VectorXd rho0 = KinematicParameters::Nominal(nominal);
  auto unit = [&](int i) { return params.kind(i) == ParameterKind::kLength ? "mm" : "deg"; };
  auto report_units = [&](int i, double v) { return params.kind(i) == ParameterKind::kLength ? v * 1e3 : RadToDeg(v); };
  out << "\nkinematic bundle adjustment vs truth: free parameters, nominal / true / bundle, error +- sigma (reported)";
  if (gauge_perturbed) out << "\n  (--perturb-gauge: the truth is in another gauge, parameter errors are not comparable)";
  out << ":\n";
  nlohmann::json parameters = nlohmann::json::array();
  int within_2_sigma = 0, count = 0;
  for (int i : b.free_indices) {
    const double error = b.rho[i] - world.truth.rho_true[i];
    const double sigma = b.stddev.size() > i ? b.stddev[i] : NAN;
    const double z = std::abs(error) / sigma;
    ++count;
    within_2_sigma += z <= 2 ? 1 : 0;
    out << "  " << std::left << std::setw(10) << params.name(i) << std::right << std::fixed << std::setprecision(4)
        << std::setw(12) << report_units(i, rho0[i]) << std::setw(12) << report_units(i, world.truth.rho_true[i])
        << std::setw(12) << report_units(i, b.rho[i]) << "   error " << std::setw(9) << report_units(i, error) << " +- "
        << std::setw(7) << report_units(i, sigma) << " " << unit(i) << std::setprecision(1) << "  (" << z << " sigma)\n";
    const std::string u = std::string("_") + unit(i);
    parameters.push_back({{"name", params.name(i)},
                          {"nominal" + u, report_units(i, rho0[i])},
                          {"true" + u, report_units(i, world.truth.rho_true[i])},
                          {"bundle" + u, report_units(i, b.rho[i])},
                          {"error" + u, report_units(i, error)},
                          {"stddev" + u, std::isfinite(sigma) ? nlohmann::json(report_units(i, sigma)) : nlohmann::json()}});
  }
  const double fx_true = world.truth.camera_true.fx_px;
  out << std::setprecision(4) << "f_x: nominal " << obs.camera.fx_px << ", true " << fx_true << ", bundle " << b.fx_px
      << " +- " << b.fx_stddev << " px (error " << b.fx_px - fx_true << " px)\n";
  out << within_2_sigma << " of " << count << " free parameters within 2 sigma of the truth\n";
  const int ref = obs.PosesWithRole(PoseRole::kIdentification).front();
  const PoseDifference before = MeanVerificationPoseError(world, obs, ref, nominal, rho0);
  const PoseDifference after = MeanVerificationPoseError(world, obs, ref, nominal, b.rho);
  PrintVerificationPoseErrors(before, after, "bundle", out);
  out << "3-D error of the held-out distances, RMS: nominal " << stage.verification_nominal.rms_error_m * 1e3
      << " mm, bundle " << stage.verification.rms_error_m * 1e3 << " mm (max " << stage.verification.max_error_m * 1e3
      << " mm)\n";
  nlohmann::json fixed_camera;  // eye-to-hand: the fixed camera against the hidden one
  if (nominal.mount == CameraMount::kEyeToHand) {
    const PoseDifference d = ComparePoses(sim::FixedCameraTruth(world.truth),
                                          BaseFromCam(nominal, b.rho, Eigen::VectorXd::Zero(nominal.num_joints())));
    out << "base_from_cam error (the fixed camera): " << d.position_m * 1e3 << " mm / " << RadToDeg(d.rotation_rad)
        << " deg\n";
    fixed_camera = {{"error_mm", d.position_m * 1e3}, {"error_deg", RadToDeg(d.rotation_rad)}};
  }
  out.unsetf(std::ios::floatfield);
  return {{"parameters", parameters},
          {"base_from_cam", fixed_camera},
          {"gauge_perturbed", gauge_perturbed},
          {"free_within_2_sigma", within_2_sigma},
          {"free_count", count},
          {"fx_true_px", fx_true},
          {"fx_bundle_px", b.fx_px},
          {"fx_stddev_px", std::isfinite(b.fx_stddev) ? nlohmann::json(b.fx_stddev) : nlohmann::json()},
          {"verification_pose_error_mean_mm", {{"nominal", before.position_m * 1e3}, {"bundle", after.position_m * 1e3}}},
          {"verification_pose_error_mean_deg",
           {{"nominal", RadToDeg(before.rotation_rad)}, {"bundle", RadToDeg(after.rotation_rad)}}},
          {"error3d_rms_mm", {{"nominal", stage.verification_nominal.rms_error_m * 1e3}, {"bundle", stage.verification.rms_error_m * 1e3}}}};
}

}  // namespace

namespace {

// What simulate writes into --out beside its sessions (which are never overwritten: FreshSessionPath).
std::vector<std::string> SimulateOutputFiles() {
  std::vector<std::string> files = CalibrationOutputFiles();
  files.push_back("truth.json");
  files.push_back("comparison_with_truth.json");
  return files;
}

// The first free "<out>/session", "<out>/session-2", ...: sessions are never overwritten (C10).
std::string FreshSessionPath(const std::string& out) {
  for (int k = 1;; ++k) {
    const std::filesystem::path p = std::filesystem::path(out) / (k == 1 ? "session" : "session-" + std::to_string(k));
    if (!std::filesystem::exists(p)) return p.string();
  }
}

// The session's dot identities against the world it ran in, and what the calibration kept of the plan's
// observations (poses x dots) and check distances: printed and added to the comparison.
Status AddIdentityAudit(const sim::SimResult& world, const std::string& session, const CalibrationRun& calibrated,
                        nlohmann::json* comparison) {
  Result<simulation::IdentityAudit> audit = simulation::AuditRecordedIdentities(world, session);
  if (!audit.ok()) return audit.status();
  int observations = 0;
  for (const PoseObservation& pose : calibrated.observations.poses) observations += static_cast<int>(pose.dots_px.size());
  const int possible = audit->poses_planned * static_cast<int>(world.truth.dots_in_base.size());
  const calibration::VerificationSummary& checks = calibrated.report.verification_calibrated();
  std::cout << "dot identities: " << simulation::IdentityAuditSummary(*audit) << "\nkept " << observations << " of "
            << possible << " observations, " << checks.num_ok << " of " << checks.checks.size() << " check distances\n";
  (*comparison)["identities"] = simulation::IdentityAuditJson(*audit);
  (*comparison)["identities"]["observations_kept"] = {{"kept", observations}, {"of", possible}};
  (*comparison)["identities"]["check_distances_kept"] = {{"kept", checks.num_ok}, {"of", checks.checks.size()}};
  return Status::Ok();
}

// Eye-to-hand without --trajectory: the robot's eye-to-hand start (run_configuration.h) written to
// <out>/eye_to_hand_trajectory.yaml (not overwritten: an earlier one of the same robot is the same file).
Result<std::string> WriteEyeToHandStart(const SimulateArgs& args) {
  Result<io::CalibratedModel> config = io::LoadRobotConfig(ResolveDataPath(args.robot));
  if (!config.ok()) return config.status();
  Result<RobotModel> robot = RobotInSimulatedCell(config->model, args.robot, CameraMount::kEyeToHand);
  if (!robot.ok()) return robot.status();
  Result<std::vector<Eigen::VectorXd>> joints = EyeToHandStart(*robot, args.robot, 25);
  if (!joints.ok()) return joints.status();
  if (Status s = EnsureDirectory(args.out); !s.ok()) return s;
  const std::string path = (std::filesystem::path(args.out) / "eye_to_hand_trajectory.yaml").string();
  if (std::filesystem::exists(path)) return path;
  const std::string description = "the eye-to-hand start of selfcal simulate (sim::MakeEyeToHandTrajectory at home)";
  if (Status s = io::SaveTrajectory(*joints, path, robot->name, description); !s.ok()) return s;
  std::cout << "eye-to-hand trajectory (" << joints->size() << " poses): " << path << "\n";
  return path;
}

// selfcal simulate (default): the simulated arm and rendered camera through a real session directory, the
// offline calibration of that session, and the comparison with the hidden truth.
int SimulateSession(const SimulateArgs& args) {
  // No EnsureDirectory(args.out) here: the run creates the session's parent once it can start, and the
  // calibration its output, so a refused input leaves no empty output folder.
  RunSettings run;
  run.session = FreshSessionPath(args.out);
  run.robot_config = args.robot;
  run.configuration = args.configuration;
  run.plan = args.trajectory;
  if (run.plan.empty() && args.configuration == CameraMountName(CameraMount::kEyeToHand)) {
    Result<std::string> plan = WriteEyeToHandStart(args);  // no eye-to-hand trajectory is shipped
    if (!plan.ok()) return Fail(plan.status());
    run.plan = *plan;
  }
  run.seed = args.seed;
  run.grey_noise = args.grey_noise;
  run.blur_px = args.blur_px;
  run.supersampling = args.supersampling;
  run.live_view = args.live_view;
  const auto start = std::chrono::steady_clock::now();
  std::cout << "session " << run.session << ": simulated robot and rendered camera (grey noise " << args.grey_noise
            << ", blur " << args.blur_px << " px)\n";
  std::unique_ptr<sim::SimResult> hidden;  // the session never saw it
  const int run_code = RunFromSettings(run, &hidden);
  const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (run_code != 0) return run_code;
  CalibrationRun calibrated;
  CalibrateRequest request{run.session, args.out, args.seed, MethodFromName(args.method)};
  request.html = !args.no_html;
  const int code = CalibrateAndWrite(request, &calibrated);
  const ObservationSet& obs = calibrated.observations;
  const calibration::CalibrationReport& result = calibrated.report;
  const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const sim::SimResult& world = *hidden;
  const std::string truth_path = (std::filesystem::path(args.out) / "truth.json").string();
  if (Status s = io::WriteJsonFile(TruthJson(world), truth_path); !s.ok()) return Fail(s);
  AddOutputFile("truth", truth_path);
  nlohmann::json comparison = nlohmann::json::object();
  if (result.paper.calibrated_rho.size() > 0) {
    std::cout << "\npaper pipeline vs truth:";
    comparison = CompareWithTruth(world, obs, result.paper, std::cout);
  }
  if (result.bundle && result.bundle->bundle.rho.size() == obs.robot.num_parameters()) {
    comparison["bundle"] = CompareBundleWithTruth(world, obs, *result.bundle, false, std::cout);
  }
  comparison["seconds"] = {{"session", run_s}, {"session_and_calibration", total_s}};
  if (Status s = AddIdentityAudit(world, run.session, calibrated, &comparison); !s.ok()) return Fail(s);
  const std::string comparison_path = (std::filesystem::path(args.out) / "comparison_with_truth.json").string();
  if (Status s = io::WriteJsonFile(comparison, comparison_path); !s.ok()) return Fail(s);
  AddOutputFile("comparison_with_truth", comparison_path);
  OutputDocument()["comparison_with_truth"] = comparison;
  std::cout << "\nsimulated session " << run_s << " s, with the calibration " << total_s << " s\n";
  PrintFinalLine(CalibrationFinalLine(calibrated, code));
  return code;
}

}  // namespace

Command AddSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand("simulate", "Simulated robot with hidden errors: observe, calibrate, compare");
  AddRobotOption(cmd, &args->robot);
  AddConfigurationOption(cmd, &args->configuration);
  cmd->add_option("--trajectory", args->trajectory,
                  "Trajectory file (for the robot); default: config/trajectories/initial_<robot name>.yaml (eye_to_hand: "
                  "a smooth path of the plate in front of the fixed camera, written to <out>)");
  AddOutputOption(cmd, "--out", &args->out, OutputKind::kDirectory, "Output directory (created if missing; outside any session)",
                  SimulateOutputFiles());
  CLI::Option* noise = cmd->add_option("--noise-px", args->noise_px,
                  "--points: pixel noise std (px); a dot the noise moves out of the image is not detected")
      ->check(CLI::Range(0.0, 10.0));
  CLI::Option* joint_noise = cmd->add_option("--joint-noise-deg", args->joint_noise_deg,
                  "--points: joint reading noise std (deg): the recorded joint angles are the true ones plus this "
                  "noise, the images are taken at the true ones")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--seed", args->seed, "World and noise seed");
  cmd->add_flag("--perturb-gauge", args->perturb_gauge, "Also perturb the parameters the measurements cannot see");
  cmd->add_flag("--flat-sheet", args->flat_sheet,
                "Put every dot on one plane (the paper's factor method is degenerate there, the bundle is not)");
  cmd->add_flag("--no-html", args->no_html, "Do not write report.html (report.json is written as always)");
  cmd->add_flag("--points", args->points,
                "Fast mode: project the dots with Gaussian pixel noise (--noise-px), no images, no session");
  cmd->add_option("--grey-noise", args->grey_noise, "Image mode: pixel noise std, grey levels")
      ->check(CLI::Range(0.0, 50.0));
  cmd->add_option("--blur-px", args->blur_px, "Image mode: Gaussian blur sigma, px")->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--supersampling", args->supersampling, "Image mode: samples per pixel side")
      ->check(CLI::Range(1, 8));
  cmd->add_option("--live-view", args->live_view,
                  "Image mode: show the camera image with the tracked dots, their ids and the pose in an X11 window: "
                  "auto (when $DISPLAY can be opened), on (refused without a display), off")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  AddMethodOption(cmd, &args->method);
  return [args, noise, joint_noise]() {
    if (!args->points) {
      if (args->flat_sheet || args->perturb_gauge || joint_noise->count() > 0) {
        return Fail(Status::Error(ErrorCode::kInvalidInput,
                                  "--flat-sheet, --perturb-gauge and --joint-noise-deg need --points"));
      }
      if (noise->count() > 0) {  // image mode renders its noise in grey levels
        return Fail(Status::Error(ErrorCode::kInvalidInput, "--noise-px needs --points (image mode: --grey-noise)"));
      }
      return SimulateSession(*args);
    }
    if (args->live_view == "on") {
      return Fail(Status::Error(ErrorCode::kInvalidInput, "--live-view on needs image mode: the fast --points mode "
                                                          "renders no image"));
    }
    const bool e2h = args->configuration == CameraMountName(CameraMount::kEyeToHand);
    if (e2h && args->trajectory.empty()) {
      Result<std::string> start = WriteEyeToHandStart(*args);
      if (!start.ok()) return Fail(start.status());
      args->trajectory = *start;
    }
    Result<RobotAndTrajectory> loaded = LoadRobotAndTrajectory(args->robot, args->trajectory);
    if (!loaded.ok()) return Fail(loaded.status());
    if (e2h) {
      Result<RobotModel> cell = RobotInSimulatedCell(loaded->robot, args->robot, CameraMount::kEyeToHand);
      if (!cell.ok()) return Fail(cell.status());
      loaded.value().robot = *cell;
    }
    const RobotModel* robot = &loaded->robot;
    const std::vector<Eigen::VectorXd>* joints = &loaded->joints;
    std::cout << "robot " << robot->name << " (" << args->robot << "), trajectory " << loaded->trajectory_path << "\n";
    if (Status s = EnsureDirectory(args->out); !s.ok()) return Fail(s);
    sim::SimOptions options;
    options.world_seed = options.noise_seed = args->seed;
    options.pixel_noise_px = args->noise_px;
    options.joint_noise_rad = DegToRad(args->joint_noise_deg);
    options.perturb_gauge_parameters = args->perturb_gauge;
    options.flat_sheet = args->flat_sheet;
    const sim::SimResult world = sim::Simulate(*robot, *joints, options);
    if (!world.ok) return Fail(Status::Error(ErrorCode::kDegenerateData, "simulation: " + world.message));
    std::cout << "simulated " << world.observations.poses.size() << " poses x " << world.truth.dots_in_base.size()
              << " dots, pixel noise " << args->noise_px << " px (std), hidden errors: lengths N(0, "
              << options.length_error_std_m * 1e3 << " mm), angles N(0, " << RadToDeg(options.angle_error_std_rad)
              << " deg), hand-eye N(0, " << options.cam_length_error_std_m * 1e3 << " mm / "
              << RadToDeg(options.cam_angle_error_std_rad) << " deg), f_x " << world.truth.camera_true.fx_px
              << " px (nominal " << options.fx_nominal_px << ")\n";
    const std::filesystem::path out(args->out);
    const std::string obs_path = (out / "observations.yaml").string();
    if (Status s = io::SaveObservations(world.observations, obs_path); !s.ok()) return Fail(s);
    AddOutputFile("observations", obs_path);
    if (Status s = io::WriteJsonFile(TruthJson(world), (out / "truth.json").string()); !s.ok()) return Fail(s);
    AddOutputFile("truth", (out / "truth.json").string());
    // Calibrate from the file, as any user's data would be.
    CalibrationRun calibrated;
    CalibrateRequest request{obs_path, args->out, args->seed, MethodFromName(args->method)};
    request.html = !args->no_html;
    request.robot_config = ResolveDataPath(args->robot);  // the exports in its convention and names
    const int code = CalibrateAndWrite(request, &calibrated);
    const calibration::CalibrationReport& result = calibrated.report;
    const ObservationSet* obs = &calibrated.observations;
    nlohmann::json comparison = nlohmann::json::object();
    if (result.paper.calibrated_rho.size() > 0) {
      std::cout << "\npaper pipeline vs truth:";
      comparison = CompareWithTruth(world, *obs, result.paper, std::cout);
    }
    if (result.bundle && result.bundle->bundle.rho.size() == obs->robot.num_parameters()) {
      comparison["bundle"] = CompareBundleWithTruth(world, *obs, *result.bundle, args->perturb_gauge, std::cout);
    }
    if (!comparison.empty()) {
      if (Status s = io::WriteJsonFile(comparison, (out / "comparison_with_truth.json").string()); !s.ok()) return Fail(s);
      AddOutputFile("comparison_with_truth", (out / "comparison_with_truth.json").string());
      OutputDocument()["comparison_with_truth"] = comparison;
    }
    PrintFinalLine(CalibrationFinalLine(calibrated, code));
    return code;
  };
}

namespace {

// make-trajectory's home: --home-deg, else the config's home_deg; one value per joint (exit 2 otherwise).
Result<std::vector<double>> HomeDeg(const std::vector<double>& given, const io::CalibratedModel& config,
                                    const std::string& robot_path) {
  const RobotModel& robot = config.model;
  std::vector<double> home = given;
  if (home.empty()) {
    for (double q : config.home_rad) home.push_back(RadToDeg(q));
  }
  if (home.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "robot `" + robot.name + "` (" + robot_path +
                                                       ") has no home_deg and no --home-deg was given: give the joint "
                                                       "angles (deg) where the camera looks at the scene");
  }
  if (static_cast<int>(home.size()) != robot.num_joints()) {
    return Status::Error(ErrorCode::kInvalidInput, "--home-deg has " + std::to_string(home.size()) + " values, robot `" +
                                                       robot.name + "` has " + std::to_string(robot.num_joints()) +
                                                       " joints");
  }
  return home;
}

}  // namespace

Command AddMakeTrajectoryCommand(CLI::App& app) {
  auto robot_path = std::make_shared<std::string>("config/robots/puma560.yaml");
  auto out_path = std::make_shared<std::string>();
  auto poses = std::make_shared<int>(25);
  auto home_deg = std::make_shared<std::vector<double>>();
  CLI::App* cmd = app.add_subcommand("make-trajectory", "Write the smooth initial trajectory around the simulated scene");
  cmd->add_option("--robot", *robot_path, "Robot config");
  AddOutputOption(cmd, "--out", out_path.get(), OutputKind::kFile, "Trajectory file to write")->required();
  cmd->add_option("--poses", *poses, "Number of poses")->check(CLI::Range(3, 1000));
  cmd->add_option("--home-deg", *home_deg,
                  "Joint angles (deg, comma-separated) where the camera looks at the scene; default: the config's "
                  "home_deg")
      ->delimiter(',');
  return [robot_path, out_path, poses, home_deg]() {
    Result<io::CalibratedModel> config = io::LoadRobotConfig(ResolveDataPath(*robot_path));
    if (!config.ok()) return Fail(config.status());
    const RobotModel* robot = &config->model;
    sim::ArcTrajectoryOptions options;
    options.num_poses = *poses;
    Result<std::vector<double>> home = HomeDeg(*home_deg, *config, *robot_path);
    if (!home.ok()) return Fail(home.status());
    options.home_joints_deg = *home;
    const sim::GeneratedTrajectory t = sim::MakeArcTrajectory(*robot, options);
    if (!t.ok) return Fail(Status::Error(ErrorCode::kDegenerateData, t.message));
    const std::string description =
        "smooth arc around the simulated scene (sim::MakeArcTrajectory defaults): the paper's 'initial' trajectory";
    if (Status s = io::SaveTrajectory(t.joints, *out_path, robot->name, description); !s.ok()) return Fail(s);
    std::cout << "wrote " << t.joints.size() << " poses to " << *out_path << "\n";
    return 0;
  };
}

}  // namespace selfcal::app
