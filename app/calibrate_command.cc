// selfcal calibrate INPUT --out DIR [--method bundle|paper]: parse, load, calibrate, write.
#include "app/calibrate_command.h"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <optional>

#include "app/cli_output.h"
#include "app/cli_util.h"
#include "app/commands.h"
#include "app/model_exports.h"
#include "app/output_options.h"
#include "app/report_command.h"
#include "bundle/bundle_adjustment.h"
#include "geometry/rigid3.h"
#include "io/camera_file.h"
#include "io/camera_info_file.h"
#include "io/hand_eye_file.h"
#include "io/observations_file.h"
#include "io/report_json.h"
#include "io/robot_config.h"
#include "observations/joint_limits.h"
#include "observations/pool_recordings.h"
#include "base/atomic_file.h"
#include "base/terminal_text.h"
#include "report/calibration_report.h"
#include "report/image_residuals.h"
#include "session/session_dir.h"
#include "session/session_observations.h"
#include "yaml/yaml_reader.h"

namespace selfcal::app {

namespace {

// The observations and what the report says of their origin.
struct LoadedInput {
  ObservationSet observations;
  report::ReportInput input;
  std::optional<report::SessionContext> session;  // for a session: its counts and findings
  // For an observations file: how its robot was entered, read from the document parsed for the
  // observations (the file is parsed once).
  std::optional<io::RobotOrigin> origin;
};

void PrintSummary(const session::JournalSummary& s) {
  std::cout << "session: " << s.samples_accepted << " of " << s.poses_planned << " poses accepted, " << s.resumes
            << " resumes";
  for (const auto& [name, n] : s.skips_by_reason) std::cout << ", skipped " << name << " x" << n;
  for (const auto& [name, n] : s.faults_by_kind) std::cout << ", fault " << name << " x" << n;
  for (const auto& [name, n] : s.halts_by_reason) std::cout << ", halted " << name << " x" << n;
  if (s.rejected_frames > 0) {
    std::cout << ", " << s.rejected_frames << " frames of skipped poses in images/rejected/ (not used)";
  }
  std::cout << "\n";
}

// --camera-file: the file's intrinsics replace the observations' camera; the image size must agree (the
// pixels were measured in that image). Says so on stdout.
Status ReplaceCamera(const CalibrateRequest& request, LoadedInput* loaded) {
  if (request.camera_file.empty()) {
    if (!request.camera_name.empty()) {
      return Status::Error(ErrorCode::kInvalidInput, "--camera-name " + request.camera_name +
                                                         " selects a camera of a --camera-file; none was given");
    }
    return Status::Ok();
  }
  Result<CameraIntrinsics> camera = io::LoadCameraFile(request.camera_file, request.camera_name);
  if (!camera.ok()) return camera.status();
  const CameraIntrinsics& old = loaded->observations.camera;
  if (camera->width_px != old.width_px || camera->height_px != old.height_px) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "camera file " + request.camera_file + " is for " + std::to_string(camera->width_px) + "x" +
                             std::to_string(camera->height_px) + " images, the observations of " + request.input +
                             " were measured in " + std::to_string(old.width_px) + "x" + std::to_string(old.height_px));
  }
  std::cout << "camera: the intrinsics of " << request.camera_file
            << (request.camera_name.empty() ? "" : " (camera " + request.camera_name + ")")
            << " replace the observations' camera (f_x " << old.fx_px << " -> " << camera->fx_px << " px)\n";
  loaded->observations.camera = *camera;
  loaded->input.camera_file = request.camera_file;
  loaded->input.camera_file_sha256 = FileSha256(request.camera_file);
  loaded->input.camera_name = request.camera_name;
  return Status::Ok();
}

// An observations file, its notes on stderr; *origin: the robot config it names (empty when none).
Result<ObservationSet> LoadObservationsFile(const std::string& path, std::optional<io::RobotOrigin>* origin) {
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(path);
  if (!doc.ok()) return doc.status();
  std::vector<std::string> notes;
  Result<ObservationSet> obs = io::ParseObservations(*doc, &notes);
  if (!obs.ok()) return obs.status();
  for (const std::string& note : notes) std::cerr << "selfcal: note: " << TerminalSafe(note) << "\n";
  Result<io::RobotOrigin> found = io::RobotOriginOfObservations(*doc);
  *origin = found.ok() ? *found : io::RobotOrigin{};
  return obs;
}

// `first` (the input) pooled with the --also files, each a scene named by its file name without extension.
Result<ObservationSet> PoolWithRecordings(const CalibrateRequest& request, ObservationSet first) {
  if (session::IsSessionDirectory(request.input)) {
    return Status::Error(ErrorCode::kInvalidInput, "--also pools observations files; " + request.input +
                                                       " is a session directory (calibrate it alone, or pool its "
                                                       "observations.yaml from an earlier calibrate)");
  }
  std::vector<Recording> recordings{{std::filesystem::path(request.input).stem().string(), std::move(first)}};
  for (const std::string& path : request.also) {
    std::optional<io::RobotOrigin> ignored;
    Result<ObservationSet> obs = LoadObservationsFile(path, &ignored);
    if (!obs.ok()) return obs.status();
    const std::string label = std::filesystem::path(path).stem().string();
    for (const Recording& r : recordings) {
      if (r.label == label) {
        return Status::Error(ErrorCode::kInvalidInput, "--also " + path + ": another recording is named `" + label +
                                                           "` already (each file's name names its scene)");
      }
    }
    recordings.push_back({label, std::move(obs).value()});
  }
  return PoolRecordings(recordings);
}

Result<LoadedInput> LoadInput(const CalibrateRequest& request) {
  LoadedInput loaded;
  // The camera files asked for are written last: what writes them must be there before anything is solved.
  if (!request.write_camera_opencv.empty() || !request.write_camera_visp.empty()) {
    if (Status s = io::CheckCameraFileSupport(); !s.ok()) return s;
  }
  if (session::IsSessionDirectory(request.input)) {
    Result<session::SessionObservations> session = session::LoadSessionObservations(request.input);
    if (!session.ok()) return session.status();
    for (const std::string& finding : session->findings) {
      std::cerr << "selfcal: warning: " << TerminalSafe(finding) << "\n";
    }
    if (!session->findings.empty()) {
      std::cerr << "selfcal: warning: calibrate changed nothing in session " << request.input
                << " (a resume would repair it)\n";
    }
    loaded.session = report::SessionContext{session->summary, session->findings};
    loaded.input = {"session", request.input, session->manifest_sha256};
    loaded.observations = std::move(session).value().observations;
  } else {
    Result<ObservationSet> obs = LoadObservationsFile(request.input, &loaded.origin);
    if (!obs.ok()) return obs.status();
    loaded.observations = std::move(obs).value();
    loaded.input = {"observations", request.input, FileSha256(request.input)};
  }
  if (!request.also.empty()) {
    Result<ObservationSet> pooled = PoolWithRecordings(request, std::move(loaded.observations));
    if (!pooled.ok()) return pooled.status();
    loaded.observations = std::move(pooled).value();
  }
  if (Status s = ReplaceCamera(request, &loaded); !s.ok()) return s;
  return loaded;
}

// --write-camera-visp of an accepted model whose lens ViSP cannot hold: refused before anything is written.
Status CheckCameraOutputs(const CalibrateRequest& request, const calibration::CalibrationReport& report) {
  if (request.write_camera_visp.empty() || !report.model) return Status::Ok();
  const std::string problems = io::VispCameraProblems(report.model->camera);
  if (problems.empty()) return Status::Ok();
  return Status::Error(ErrorCode::kInvalidInput, "--write-camera-visp " + request.write_camera_visp +
                                                     ": the calibrated camera cannot be written as a ViSP file:\n" +
                                                     problems + "nothing was written");
}

// The calibrated intrinsics as OpenCV and ViSP camera files, when asked and accepted.
Status WriteCameraFiles(const CalibrateRequest& request, const calibration::CalibrationReport& report) {
  if (request.write_camera_opencv.empty() && request.write_camera_visp.empty()) return Status::Ok();
  if (!report.model) {
    std::cout << "camera files: not written (no calibrated model)\n";
    return Status::Ok();
  }
  for (const std::string& path : {request.write_camera_opencv, request.write_camera_visp}) {
    const std::string directory = std::filesystem::path(path).parent_path().string();
    if (!directory.empty()) {  // checked before the solve (output_options.h): e.g. inside --out
      if (Status s = EnsureDirectory(directory); !s.ok()) return s;
    }
  }
  if (!request.write_camera_opencv.empty()) {
    if (Status s = io::SaveCameraOpenCv(report.model->camera, request.write_camera_opencv); !s.ok()) return s;
    std::cout << "camera (OpenCV): " << request.write_camera_opencv << "\n";
    AddOutputFile("camera_opencv", request.write_camera_opencv);
  }
  if (!request.write_camera_visp.empty()) {
    const std::string name = request.camera_name.empty() ? "Camera" : request.camera_name;
    if (Status s = io::SaveCameraVisp(report.model->camera, request.write_camera_visp, name); !s.ok()) return s;
    std::cout << "camera (ViSP, camera " << name << "): " << request.write_camera_visp << "\n";
    AddOutputFile("camera_visp", request.write_camera_visp);
  }
  return Status::Ok();
}

// camera_info.yaml in `out_dir`: the calibrated camera in the format ROS's camera_calibration_parsers reads
// (io/camera_info_file.h; the OpenCV file is not that format), named `camera_name` (default "camera").
Status WriteCameraInfo(const CameraIntrinsics& camera, const std::string& camera_name, const std::string& out_dir) {
  const std::string path = (std::filesystem::path(out_dir) / "camera_info.yaml").string();
  if (Status s = io::SaveCameraInfo(camera, camera_name.empty() ? "camera" : camera_name, path); !s.ok()) return s;
  std::cout << "camera (ROS camera_info): " << path << "\n";
  AddOutputFile("camera_info", path);
  return Status::Ok();
}

// A flange-pose set's result: the hand-eye transform and f_x with their standard deviations.
Status WriteHandEye(const LoadedInput& loaded, const calibration::CalibrationReport& report, const std::string& out_dir,
                    const io::RobotOrigin& origin) {
  io::HandEyeResult result;
  result.mount = report.model->robot.mount;
  result.flange_from_cam = report.model->robot.flange_from_cam;
  result.base_from_cam = report.model->robot.base_from_cam;
  result.fx_px = report.model->camera.fx_px;
  result.stddev = result.mount == CameraMount::kEyeToHand ? report.model->base_from_cam_stddev
                                                          : report.model->flange_from_cam_stddev;
  result.fx_stddev_px = report.model->intrinsics_stddev[kFx];
  result.camera = report.model->camera;
  result.intrinsics_stddev = report.model->intrinsics_stddev;
  result.source = "selfcal calibrate " + loaded.input.path;
  result.provenance = {{"software_version", SELFCAL_VERSION},
                       {"input_sha256", loaded.input.sha256},
                       {"method", report.model->method_description},
                       {"verdict", calibration::VerdictName(report.verdict)}};
  const std::string path = (std::filesystem::path(out_dir) / "hand_eye.yaml").string();
  if (Status s = io::SaveHandEye(result, path); !s.ok()) return s;
  std::cout << "hand-eye result: " << path << "\n";
  AddOutputFile("hand_eye", path);
  return WriteCameraStaticTransform(result.mount,
                                    result.mount == CameraMount::kEyeToHand ? result.base_from_cam : result.flange_from_cam,
                                    origin, out_dir);
}

// --json: the answer at report.json's top level (docs/report-format.md), without its per-method sections.
void RecordCalibrationFigures(const nlohmann::json& report) {
  nlohmann::json figures = nlohmann::json::object();
  for (const char* key : {"method", "verdict", "accepted", "message", "reasons", "acceptance", "pixel_noise_px", "fx_px",
                          "heldout_reprojection", "verification", "predicted_3d_error", "session"}) {
    if (report.contains(key)) figures[key] = report[key];
  }
  OutputDocument()["calibration"] = figures;
  SetOutcome(report.value("verdict", std::string()));
}

// Writes report.json, and calibrated_model.yaml and calibrated.urdf (hand_eye.yaml for flange poses) when the verdict is
// "accepted" (K4).
Status WriteOutputs(const LoadedInput& loaded, const calibration::CalibrationReport& report, ExitCode code,
                    const CalibrateRequest& request) {
  const std::string& out_dir = request.out_dir;
  const std::filesystem::path out(out_dir);
  const report::ReportContext context{loaded.input, static_cast<int>(code), loaded.session};
  const std::string report_path = (out / "report.json").string();
  const nlohmann::json document = report::CalibrationReportJson(loaded.observations, report, context);
  if (Status s = io::WriteJsonFile(document, report_path); !s.ok()) return s;
  std::cout << "report: " << report_path << "\n";
  AddOutputFile("report", report_path);
  const std::string residuals_path = (out / "image_residuals.csv").string();
  if (Status s = WriteFileAtomically(residuals_path, report::ImageResidualsCsv(loaded.observations, report)); !s.ok()) {
    return s;
  }
  std::cout << "per-image residuals: " << residuals_path << "\n";
  AddOutputFile("image_residuals", residuals_path);
  RecordCalibrationFigures(document);
  const std::string html_path = (out / "report.html").string();
  if (request.html) {
    WriteHtmlBeside(document, html_path);
    if (std::filesystem::exists(html_path)) AddOutputFile("report_html", html_path);
  }
  // An earlier run's model files in this directory (there only with --force, output_options.h) would sit
  // beside a report of this run: gone before this run writes its own, or none.
  for (const char* name : {"calibrated_model.yaml", "calibrated.urdf", "calibrated_robot.yaml",
                           "camera_static_transform.yaml", "camera_static_transform.launch.py", "hand_eye.yaml",
                           "camera_info.yaml", "ur_calibrated_kinematics.yaml"}) {
    std::error_code error;
    if (std::filesystem::remove(out / name, error)) {
      std::cout << "removed the earlier run's " << (out / name).string() << (report.model ? "" : " (this run wrote no model)")
                << "\n";
    }
  }
  if (!report.model) return Status::Ok();
  if (Status s = WriteCameraInfo(report.model->camera, request.camera_name, out_dir); !s.ok()) return s;
  const io::RobotOrigin origin = request.robot_config.empty() && loaded.origin
                                     ? *loaded.origin
                                     : OriginOfInput(request.robot_config, request.input, loaded.session.has_value());
  if (loaded.observations.UsesFlangePoses()) return WriteHandEye(loaded, report, out_dir, origin);
  io::CalibratedModel model;
  model.model = report.model->robot;
  model.fx_px = report.model->camera.fx_px;
  model.camera = report.model->camera;
  model.intrinsics_stddev = report.model->intrinsics_stddev;
  model.parameters = report.model->parameters;
  model.source = "selfcal calibrate " + loaded.input.path;
  model.provenance = {{"software_version", SELFCAL_VERSION},
                      {"input_sha256", loaded.input.sha256},
                      {"method", report.model->method_description},
                      {"verdict", calibration::VerdictName(report.verdict)}};
  const std::string model_path = (out / "calibrated_model.yaml").string();
  if (Status s = io::SaveCalibratedModel(model, model_path); !s.ok()) return s;
  std::cout << "calibrated model (" << calibration::MethodName(report.method) << "): " << model_path << "\n";
  AddOutputFile("calibrated_model", model_path);
  return WriteModelExports(model.model, origin, model.source, out_dir);
}

// Recorded joints outside the config's limits: the controller's reading is what happened, so they are
// calibrated as recorded; each such pose is named on stderr and in --json (docs/observations-format.md).
void WarnOfJointsOutsideLimits(const ObservationSet& observations) {
  const std::vector<std::string> poses = PosesOutsideJointLimits(observations);
  for (const std::string& pose : poses) {
    std::cerr << "selfcal: warning: " << TerminalSafe(pose)
              << ": calibrated as recorded (the controller's reading); run never commands beyond the limits\n";
  }
  if (!poses.empty()) OutputDocument()["joints_outside_limits"] = poses;
}

}  // namespace

void AddMethodOption(CLI::App* cmd, std::string* method) {
  cmd->add_option("--method", *method,
                  "bundle: the paper's pipeline, then the kinematic bundle adjustment started from it (the product); "
                  "paper: the paper's pipeline alone (the baseline)")
      ->check(CLI::IsMember({"bundle", "paper"}));
}

void AddParameterMaskOptions(CLI::App* cmd, std::vector<std::string>* fix, std::vector<std::string>* free) {
  const std::string names =
      "a parameter (j2.beta, cam.tx), a joint (j3), base, camera (or hand_eye), kinematics (base and every joint), an "
      "intrinsic (fx, mu or fy, cx, cy, k1, k2, p1, p2, k3), lens (k1, k2, p1, p2, k3), intrinsics (all nine)";
  cmd->add_option("--fix", *fix,
                  "Hold these at their nominal values, comma separated: " + names +
                      ". --fix kinematics is the hand-eye-only solve (kinematics trusted)")
      ->delimiter(',');
  cmd->add_option("--free", *free,
                  "Estimate only these (everything else held), comma separated, same names; naming an intrinsic "
                  "estimates it (fx must be named to stay estimated)")
      ->delimiter(',');
}

std::vector<std::string> CalibrationOutputFiles() {
  return {"observations.yaml", "report.json",           "report.html",           "image_residuals.csv",
          "calibrated_model.yaml", "calibrated.urdf", "calibrated_robot.yaml", "camera_static_transform.yaml",
          "camera_static_transform.launch.py", "hand_eye.yaml", "camera_info.yaml", "ur_calibrated_kinematics.yaml"};
}

int CalibrateAndWrite(const CalibrateRequest& request, CalibrationRun* run) {
  Result<LoadedInput> loaded = LoadInput(request);
  if (!loaded.ok()) return Fail(loaded.status());
  const bool from_session = loaded->session.has_value();
  WarnOfJointsOutsideLimits(loaded->observations);
  // The set as read, for observations.yaml: re-solving it repeats the scenes' separation (and a split the
  // solve finds) instead of separating ids already separated.
  const ObservationSet as_read = loaded->observations;
  std::vector<std::string> scenes;
  loaded.value().observations = SeparateScenes(loaded->observations, &scenes);
  if (scenes.size() > 1) {
    std::cout << "scenes: " << scenes.size() << ", each its own points (scene k's dot n is dot k x "
              << kSceneDotStride << " + n):";
    for (size_t k = 0; k < scenes.size(); ++k) std::cout << (k ? ", " : " ") << k << " `" << scenes[k] << "`";
    std::cout << "\n";
  }
  if (from_session) {
    std::cout << "session " << request.input << ": " << loaded->observations.poses.size() << " accepted samples\n";
  }
  // The parameter names against this model before any work: a wrong name writes nothing.
  bundle::BundleOptions names;
  names.held_parameters = request.fix;
  names.free_parameters = request.free;
  std::string unknown;
  bundle::HeldParameterIndices(names, loaded->observations.robot.num_joints(), &unknown);
  if (!unknown.empty()) return Fail(Status::Error(ErrorCode::kInvalidInput, "--fix/--free: " + unknown));
  const int identification = static_cast<int>(loaded->observations.PosesWithRole(PoseRole::kIdentification).size());
  if (request.folds_given && request.folds > 0 && identification < 2 * request.folds) {
    return Fail(Status::Error(ErrorCode::kInvalidInput,
                              "--folds " + std::to_string(request.folds) + ": " + request.input + " has " +
                                  std::to_string(identification) + " identification poses, and " +
                                  std::to_string(request.folds) + " folds need at least " +
                                  std::to_string(2 * request.folds) + " (two a fold); nothing was written"));
  }
  calibration::CalibrateOptions options;
  options.method = request.method;
  options.cross_validation_folds = request.folds;
  options.paper.two_view.seed = request.seed;
  options.bundle.bundle.held_parameters = request.fix;
  options.bundle.bundle.free_parameters = request.free;
  options.bundle.bundle.weak_length_tolerance_m = request.weak_tolerance_mm * 1e-3;
  options.bundle.bundle.estimate_pose_error = !request.pixel_noise_only;
  options.bundle.bundle.weak_angle_tolerance_rad = DegToRad(request.weak_tolerance_deg);
  options.flange_scale = request.scale_from == "yardstick" ? calibration::FlangeScale::kYardstick
                         : request.scale_from == "flange" ? calibration::FlangeScale::kFlange
                                                          : calibration::FlangeScale::kAuto;
  options.progress = Progress();
  calibration::CalibrationReport report = calibration::Calibrate(loaded->observations, options);
  // The solve found the scene moved between poses and took a scene each: its outputs are of that set.
  if (report.solved_observations) loaded.value().observations = *report.solved_observations;
  report::PrintCalibrationSummary(loaded->observations, report, std::cout);
  // Inconsistent observations or options found during the solve (a verification pose no identification pose
  // can predict, a scale asked of yardsticks the set lacks): exit 2 like any bad input, and nothing written.
  if (report.verdict == calibration::Verdict::kInvalidInput) {
    return Fail(Status::Error(ErrorCode::kInvalidInput, report.message));
  }
  if (Status s = CheckCameraOutputs(request, report); !s.ok()) return Fail(s);
  if (Status s = EnsureDirectory(request.out_dir); !s.ok()) return Fail(s);
  if (from_session) {
    // The session's observations as a file, for other tools and for re-solving without the images.
    const std::string derived = (std::filesystem::path(request.out_dir) / "observations.yaml").string();
    if (Status s = io::SaveObservations(as_read, derived); !s.ok()) return Fail(s);
    AddOutputFile("observations", derived);
  }
  const ExitCode code = ExitCodeFor(report.verdict);
  if (Status s = WriteOutputs(*loaded, report, code, request); !s.ok()) return Fail(s);
  if (Status s = WriteCameraFiles(request, report); !s.ok()) return Fail(s);
  if (!report.accepted()) {
    std::cerr << "selfcal: " << ExitCodeName(code) << ": " << TerminalSafe(report.message)
              << (report.model ? " (the calibrated model is written, marked untested)\n" : " (no calibrated model written)\n");
  }
  if (from_session) PrintSummary(loaded->session->summary);
  if (run != nullptr) *run = {std::move(loaded).value().observations, std::move(report), true};
  return static_cast<int>(code);
}

std::string CalibrationFinalLine(const CalibrationRun& run, int exit_code) {
  if (run.solved) return report::VerdictHeadline(run.report);
  return std::string(ExitCodeName(static_cast<ExitCode>(exit_code))) + " (exit " + std::to_string(exit_code) +
         ", the reason above on stderr)";
}

Command AddCalibrateCommand(CLI::App& app) {
  auto request = std::make_shared<CalibrateRequest>();
  request->out_dir = "out/calibration";
  auto method = std::make_shared<std::string>("bundle");
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Calibrate from an observations file or a recorded session directory (offline: never touches a robot): the "
      "paper's pipeline, then the kinematic bundle adjustment");
  cmd->add_option("observations", request->input,
                  "Observations file (docs/observations-format.md) or session directory (docs/session-format.md)")
      ->required();
  AddOutputOption(cmd, "--out", &request->out_dir, OutputKind::kDirectory,
                  "Output directory (created if missing; outside any session)", CalibrationOutputFiles());
  cmd->add_option("--seed", request->seed, "Seed of the RANSAC sampling (results are deterministic per seed)");
  AddMethodOption(cmd, method.get());
  AddParameterMaskOptions(cmd, &request->fix, &request->free);
  cmd->add_option("--also", request->also,
                  "Another observations file of the same arm, calibrated together with the first, its poses a scene "
                  "of their own named by the file's name (a board that moved between recordings); repeatable")
      ->check(CLI::ExistingFile);
  AddInputPaths(cmd, [request] { return request->also; });
  cmd->add_option("--weak-tolerance-mm", request->weak_tolerance_mm,
                  "Hold a joint length the poses determine worse than this at the robot description's value, named "
                  "in the output (0: never)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--weak-tolerance-deg", request->weak_tolerance_deg,
                  "The same for a joint angle, deg (0: never)")
      ->check(CLI::Range(0.0, 180.0));
  cmd->add_flag("--pixel-noise-only", request->pixel_noise_only,
               "Sigmas from the pixel noise alone, without the pose error estimated from the residuals (the model of "
               "a simulation without pose error)");
  CLI::Option* folds = cmd->add_option("--folds", request->folds,
                                       "Without verification poses: hold out each of K folds of the poses in turn "
                                       "and predict them (the held-out figure of report.json's cross_validation; 0: "
                                       "not run)")
                           ->check(CLI::Range(0, 1000));
  cmd->add_option("--scale-from", request->scale_from,
                  "Flange poses: what fixes the metric scale. flange: the flange translations (yardsticks are checks); "
                  "yardstick: the yardsticks as length constraints beside them, under the flange pose noise stated "
                  "or estimated; auto (default): yardstick when the set has one and a pose noise is stated or "
                  "estimated, else flange")
      ->check(CLI::IsMember({"auto", "flange", "yardstick"}));
  cmd->add_option("--camera-file", request->camera_file,
                  "Camera intrinsics file (OpenCV FileStorage YAML/XML or ViSP XML, docs/camera-files.md) replacing the "
                  "observations' camera; same image size");
  cmd->add_option("--camera-name", request->camera_name,
                  "The camera of a ViSP --camera-file holding several; also the name --write-camera-visp writes "
                  "(default Camera)");
  AddOutputOption(cmd, "--write-camera-opencv", &request->write_camera_opencv, OutputKind::kFileAndParents,
                  "Also write the calibrated intrinsics as an OpenCV FileStorage YAML file (when accepted)");
  AddOutputOption(cmd, "--write-camera-visp", &request->write_camera_visp, OutputKind::kFileAndParents,
                  "Also write the calibrated intrinsics as a ViSP XML file (when accepted; refused, before anything is "
                  "written, for a lens with k2, p1, p2 or k3)");
  auto no_html = std::make_shared<bool>(false);
  cmd->add_flag("--no-html", *no_html, "Do not write report.html (report.json and the model are written as always)");
  return [request, method, no_html, folds]() {
    request->folds_given = folds->count() > 0;
    request->method = MethodFromName(*method);
    request->html = !*no_html;
    CalibrationRun run;
    const int code = CalibrateAndWrite(*request, &run);
    PrintFinalLine(CalibrationFinalLine(run, code));
    return code;
  };
}

}  // namespace selfcal::app
