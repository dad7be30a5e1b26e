#include "calibration/calibrate.h"

#include <chrono>
#include <iomanip>
#include <sstream>

#include "base/numbers.h"
#include "calibration/scene_shift.h"

namespace selfcal::calibration {

const char* MethodName(Method method) { return method == Method::kPaper ? "paper" : "bundle"; }

std::optional<Method> ParseMethod(std::string_view name) {
  if (name == "bundle") return Method::kBundle;
  if (name == "paper") return Method::kPaper;
  return std::nullopt;
}

const char* VerdictName(Verdict verdict) {
  switch (verdict) {
    case Verdict::kAccepted: return "accepted";
    case Verdict::kInvalidInput: return "invalid_input";
    case Verdict::kDegenerate: return "degenerate";
    case Verdict::kScaleUnresolved: return "scale_unresolved";
    case Verdict::kUnconverged: return "unconverged";
    case Verdict::kSolverFailure: return "solver_failure";
    case Verdict::kRejected: return "rejected";
    case Verdict::kUntested: return "untested";
  }
  return "solver_failure";
}

Verdict VerdictFor(Outcome outcome) {
  switch (outcome) {
    case Outcome::kSuccess: return Verdict::kAccepted;
    case Outcome::kInvalidInput: return Verdict::kInvalidInput;
    case Outcome::kDegenerate: return Verdict::kDegenerate;
    case Outcome::kScaleUnresolved: return Verdict::kScaleUnresolved;
    case Outcome::kUnconverged: return Verdict::kUnconverged;
    case Outcome::kSolverFailure:
    case Outcome::kNotRun: return Verdict::kSolverFailure;
  }
  return Verdict::kSolverFailure;
}

Verdict VerdictFor(bundle::Outcome outcome) {
  switch (outcome) {
    case bundle::Outcome::kConverged: return Verdict::kAccepted;
    case bundle::Outcome::kInvalidInput: return Verdict::kInvalidInput;
    case bundle::Outcome::kDegenerate: return Verdict::kDegenerate;
    case bundle::Outcome::kScaleUnresolved: return Verdict::kScaleUnresolved;
    case bundle::Outcome::kNoConvergence: return Verdict::kUnconverged;
    case bundle::Outcome::kFailure:
    case bundle::Outcome::kNotRun: return Verdict::kSolverFailure;
  }
  return Verdict::kSolverFailure;
}

const VerificationSummary& CalibrationReport::verification_calibrated() const {
  return bundle ? bundle->verification : paper.verification_calibrated;
}

const VerificationSummary& CalibrationReport::verification_nominal() const {
  return bundle ? bundle->verification_nominal : paper.verification_nominal;
}

namespace {

// A flange-pose set, ready for the bundle stage: its yardsticks become checks (the flange translations
// are metric; exact flange poses leave them nothing to constrain; with a stated pose noise they can be
// imposed in the pose-noise bundle), and without a nominal hand-eye transform the start from the images becomes the nominal.
ObservationSet PrepareFlangePoseSet(const ObservationSet& observations, const CalibrateOptions& options,
                                    CalibrationReport* report) {
  ObservationSet prepared = observations;
  for (const KnownDistance& y : observations.yardsticks) prepared.check_distances.push_back(y);
  prepared.yardsticks.clear();
  report->paper.outcome = Outcome::kNotRun;
  report->paper.message = "not run: the paper's method identifies kinematics from joint angles, and these poses are "
                          "flange poses";
  HandEyeStartOptions start_options = options.hand_eye;
  start_options.two_view.seed = options.paper.two_view.seed;
  report->hand_eye_start = StartHandEye(observations, start_options);
  if (!observations.flange_from_cam_known && report->hand_eye_start->ok) {
    if (observations.robot.mount == CameraMount::kEyeToHand) {
      prepared.robot.base_from_cam = report->hand_eye_start->base_from_cam;
    } else {
      prepared.robot.flange_from_cam = report->hand_eye_start->flange_from_cam;
    }
    // A held f_x is the stated one (a camera file's, to the bit), in this bundle and every solve after it.
    if (bundle::EstimatedIntrinsicsOf(options.bundle.bundle, prepared.robot.num_joints())[kFx]) {
      prepared.camera.fx_px = report->hand_eye_start->fx_px;
    }
    prepared.flange_from_cam_known = true;
  }
  return prepared;
}

// The flange pose noise the pose-noise bundle models: the set's stated one, else the bundle's error model's
// camera pose error per image when it found one (a component it found absent is held nearly exact); none
// when neither is there (exact flange poses).
bool FlangePoseNoiseOf(const ObservationSet& observations, const bundle::BundleReport& b, double* translation_m,
                       double* rotation_rad, bool* estimated) {
  *estimated = !(observations.flange_translation_sigma_m > 0);
  if (!*estimated) {
    *translation_m = observations.flange_translation_sigma_m;
    *rotation_rad = observations.flange_rotation_sigma_rad;
    return true;
  }
  const bundle::ErrorModel& e = b.error_model;
  if (!e.estimated || !(e.pose_translation_m > 0 || e.pose_rotation_rad > 0)) return false;
  constexpr double kAbsent = 1e-6;  // 1 um, 1 urad: a component the residuals show none of
  *translation_m = e.pose_translation_m > 0 ? e.pose_translation_m : kAbsent;
  *rotation_rad = e.pose_rotation_rad > 0 ? e.pose_rotation_rad : kAbsent;
  return true;
}

// A flange-pose set after its bundle: the images' own camera motions against the flange motions, and with a
// flange pose noise (stated, or estimated from the residuals) the pose-noise bundle; both start from the
// bundle's hand-eye transform, dots and calibrated camera, and estimate the intrinsics the bundle estimated.
// The yardsticks constrain the scale there as options.flange_scale says.
// When the pose-noise solve succeeded, its held-out reprojection of the verification poses and its fit geometry
// (pose_noise_result.h); *calibrated and *noise: the set it solved and its options, for the cross-validation.
void CheckFlangePoses(const ObservationSet& observations, const ObservationSet& prepared, const CalibrateOptions& options,
                      CalibrationReport* report, ObservationSet* calibrated_out, bundle::PoseNoiseOptions* noise_out) {
  const BundleStageReport& stage = *report->bundle;
  const bundle::BundleReport& b = stage.bundle;
  // The hand-eye transform: flange_from_cam, or the fixed camera base_from_cam eye-to-hand.
  const Rigid3& hand_eye = stage.calibrated_robot.mount == CameraMount::kEyeToHand ? stage.calibrated_robot.base_from_cam
                                                                                  : stage.calibrated_robot.flange_from_cam;
  if (!hand_eye.rotation.allFinite() || b.dots_in_base.empty()) return;
  ObservationSet calibrated = prepared;
  calibrated.camera = stage.calibrated_camera;
  bundle::FreeCameraOptions check_options = options.motion_check;
  check_options.intrinsics = b.intrinsics_estimated;
  report->motion_check = CheckImageMotions(calibrated, hand_eye, b.dots_in_base, check_options);
  bundle::PoseNoiseOptions noise;
  if (!FlangePoseNoiseOf(observations, b, &noise.translation_sigma_m, &noise.rotation_sigma_rad,
                         &report->pose_noise_estimated)) {
    return;
  }
  noise.intrinsics = b.intrinsics_estimated;
  noise.yardstick_sigma_m = options.bundle.bundle.yardstick_sigma_m;
  if (options.flange_scale != FlangeScale::kFlange) {
    calibrated.yardsticks = observations.yardsticks;
    calibrated.check_distances = observations.check_distances;
  }
  report->pose_noise = bundle::RunPoseNoiseBundle(calibrated, hand_eye, b.dots_in_base, noise);
  report->pose_noise_translation_m = noise.translation_sigma_m;
  report->pose_noise_rotation_rad = noise.rotation_sigma_rad;
  report->flange_scale_yardsticks = static_cast<int>(report->pose_noise->yardstick_lengths_m.size());
  if (!report->PoseNoiseIsTheResult()) return;
  const bundle::PoseNoiseReport& solve = *report->pose_noise;
  report->pose_noise_fit_geometry = PoseNoiseFitGeometry(calibrated, solve);
  if (!calibrated.PosesWithRole(PoseRole::kVerification).empty() && calibrated.Validate().empty()) {
    report->pose_noise_heldout = PoseNoiseHeldOut(calibrated, solve, noise);
    HeldOutReprojection& h = *report->pose_noise_heldout;
    const double depth = MedianCameraToDotDistance(calibrated, report->pose_noise_fit_geometry, solve.dots);
    if (h.ok && std::isfinite(depth) && solve.intrinsics[kFx] > 0) {
      h.mm_per_px = depth * 1e3 / solve.intrinsics[kFx];
      h.rms_mm = h.overall.rms_px * h.mm_per_px;
    }
  }
  *calibrated_out = std::move(calibrated);
  *noise_out = noise;
}

// A failed held-out test of a joint set's bundle model whose verification images one move of the scene explains
// (scene_shift.h): its sentence says so. Sets that name their scenes already have theirs.
void NameAMovedScene(const ObservationSet& obs, CalibrationReport* report) {
  if (!report->bundle || obs.UsesFlangePoses() || report->bundle->calibrated_rho.size() == 0) return;
  for (const PoseObservation& pose : obs.poses) {
    if (!pose.scene.empty()) return;
  }
  for (AcceptanceCheck& check : report->acceptance.checks) {
    if (check.name != "heldout_test" || check.status != CheckStatus::kFailed) continue;
    const BundleStageReport& stage = *report->bundle;
    const SceneShift shift = SceneShiftOfVerification(obs, stage.calibrated_robot, stage.calibrated_rho,
                                                      stage.calibrated_camera, stage.bundle.dots_in_base);
    const HeldOutFigure& test = stage.heldout_at_stated_noise;
    if (!VerificationSceneMoved(shift, test.chi_square, test.chi_square_limit)) return;
    std::ostringstream s;
    s << std::fixed << std::setprecision(2) << "; one move of the scene would explain the verification images ("
      << shift.rms_before_px << " px RMS -> " << shift.rms_after_px << " px): its points "
      << shift.translation_m * 1e3 << " mm and " << std::setprecision(3) << shift.rotation_rad * 180 / kPi
      << " deg from where the identification images put them. If the scene moved between them (a board bumped, "
         "another day's recording), give those poses a scene of their own (`scene:` per pose, detect --scene, "
         "calibrate --also); if it did not, the model is wrong";
    check.sentence += s.str();
  }
}

// The acceptance checks of the chosen method's converged model; a failed one turns the verdict to
// kRejected, its sentences the message.
void CheckAcceptance(const ObservationSet& obs, const ObservationSet& original, CalibrationReport* report) {
  AcceptanceInputs in;
  YardstickScale yardstick_scale;
  in.stated_noise_px = obs.pixel_noise_px;
  if (report->bundle) {
    const BundleStageReport& stage = *report->bundle;
    in.calibrated = &stage.heldout;
    in.nominal = &stage.heldout_nominal;
    in.test_at_stated_noise = &stage.heldout_at_stated_noise;
    if (original.UsesFlangePoses() && !original.flange_from_cam_known) {
      in.no_nominal_reason = "the set names no hand-eye transform, and the start the solver found from the images is "
                             "not a nominal model (give one with detect --hand-eye to compare with it)";
    }
    if (report->pose_noise_heldout) {
      // The pose-noise solve is the result: its prediction, at the stated pixel noise and the flange pose noise.
      in.calibrated = &*report->pose_noise_heldout;
      in.test_at_stated_noise = &report->pose_noise_heldout->overall;
    } else if (original.flange_translation_sigma_m > 0) {
      in.test_at_stated_noise = nullptr;
      in.no_test_reason = "the flange poses have a stated noise, and the solve that models it did not succeed";
    }
    in.held_values = &stage.bundle.held_values;
    if (!original.UsesFlangePoses()) {
      yardstick_scale = YardstickScaleOf(obs.robot, stage.bundle, static_cast<int>(obs.yardsticks.size()));
      in.yardstick_scale = &yardstick_scale;
    }
    if (report->cross_validation) in.cross_validation = &*report->cross_validation;
    if (!obs.PosesWithRole(PoseRole::kVerification).empty()) {
      in.no_cross_validation_reason = "not run: the set has verification poses";
    }
    in.distances_calibrated = &stage.verification;
    in.distances_nominal = &stage.verification_nominal;
    in.distances_decisive = false;
    if (!obs.check_distances.empty() && obs.PosesWithRole(PoseRole::kVerification).empty()) {
      in.no_distances_reason = "the set's " + std::to_string(obs.check_distances.size()) +
                               " check distance(s) are measured on verification poses, and it names none (a pose's "
                               "role: verification)";
    }
    if (stage.bundle.rho.size() == obs.robot.num_parameters()) {
      in.robot = &obs.robot;
      in.corrections = stage.bundle.rho - KinematicParameters::Nominal(obs.robot);
      // A flange-pose set's nominal hand-eye transform is a guess (or the start from the images): a large
      // correction of it is the calibration's answer, not a wrong description.
      if (original.UsesFlangePoses() || stage.camera_from_images) {
        in.corrections.segment<6>(KinematicParameters(obs.robot.num_joints()).CamOffset()).setZero();
      }
    }
  } else {
    report->paper_heldout = PaperHeldOutOf(obs, report->paper);
    in.calibrated = &report->paper_heldout->calibrated;
    in.nominal = &report->paper_heldout->nominal;
    in.no_test_reason = "the paper's method gives no parameter covariance to predict with (its model is compared "
                        "with the nominal one only)";
    in.no_cross_validation_reason = "the paper's method is not cross-validated (the bundle method is)";
    in.distances_calibrated = &report->paper.verification_calibrated;
    in.distances_nominal = &report->paper.verification_nominal;
  }
  report->acceptance = AcceptanceOf(in);
  NameAMovedScene(obs, report);
  if (in.calibrated != nullptr && !in.calibrated->unused_poses.empty()) {
    // Held out to verify, it verifies nothing: an error, not a silent drop (its joints or image are not
    // the pose's, e.g. radians under a degree key that a reader could not tell).
    const std::vector<std::string>& unused = in.calibrated->unused_poses;
    report->verdict = Verdict::kInvalidInput;
    report->message = std::string(unused.size() == 1 ? "verification pose " : "verification poses ");
    for (std::size_t i = 0; i < unused.size(); ++i) report->message += (i ? ", " : "") + unused[i];
    report->message += " cannot be used: none of " + std::string(unused.size() == 1 ? "its" : "their") +
                       " dots is predicted by the calibrated model (no dot is placed by the identification images, or "
                       "every one lies behind the camera at the recorded joint angles): fix the pose's joint angles "
                       "(their unit?) or dots, or remove the pose";
    return;
  }
  if (report->acceptance.Passed() && !report->acceptance.HeldOutTested()) {
    report->verdict = Verdict::kUntested;
    report->message = "the model passed every check that could be made, but none of them held images out";
    for (const AcceptanceCheck& c : report->acceptance.checks) {
      if (c.name == "heldout_test" || c.name == "cross_validation_test") report->message += "; " + c.sentence;
    }
    report->message += ": name verification poses, or record enough poses for the cross-validation's folds (two a fold)";
    return;
  }
  if (report->acceptance.Passed()) return;
  report->verdict = Verdict::kRejected;
  report->message = "the calibrated model is refused";
  for (const std::string& reason : report->acceptance.Reasons()) report->message += "; " + reason;
}

// The chosen method's model of a report whose verdict gives one: the bundle's (with the pose-noise bundle's
// hand-eye transform and camera when it ran) or the paper pipeline's. `obs`: the set the bundle solved.
CalibratedModel ModelOf(const CalibrationReport& report, const ObservationSet& obs, const CameraIntrinsics& observed) {
  const bool flange_poses = obs.UsesFlangePoses();
  const bool eye_to_hand = obs.robot.mount == CameraMount::kEyeToHand;
  CalibratedModel model;
  if (report.bundle) {
    const bundle::BundleReport& b = report.bundle->bundle;
    model.robot = report.bundle->calibrated_robot;
    model.camera = report.bundle->calibrated_camera;
    model.intrinsics_estimated = b.intrinsics_estimated;
    if (b.covariance_available) model.intrinsics_stddev = b.intrinsics_stddev;
    model.parameters = b.rho;
    model.method_description = flange_poses ? "hand-eye bundle adjustment on recorded flange poses"
                                            : "kinematic bundle adjustment";
    if (eye_to_hand) model.method_description += " (eye-to-hand: a fixed camera, the points on the flange)";
    const int cam = KinematicParameters(obs.robot.num_joints()).CamOffset();
    if (eye_to_hand && b.covariance_available && b.stddev.size() >= cam + 6) {
      model.base_from_cam_stddev = b.stddev.segment<6>(cam);
    } else if (flange_poses && b.covariance_available && b.stddev.size() >= cam + 6) {
      model.flange_from_cam_stddev = b.stddev.segment<6>(cam);
    }
  } else {
    model.robot = report.paper.calibrated_robot;
    model.camera = observed;
    model.camera.fx_px = report.paper.fx_px;
    model.intrinsics_estimated = kFocalLengthOnly;
    model.method_description = "paper pipeline";
  }
  if (report.PoseNoiseIsTheResult()) {
    if (eye_to_hand) {
      model.robot.base_from_cam = report.pose_noise->base_from_cam;
      model.base_from_cam_stddev = report.pose_noise->stddev;
    } else {
      model.robot.flange_from_cam = report.pose_noise->flange_from_cam;
      model.flange_from_cam_stddev = report.pose_noise->stddev;
    }
    model.camera = WithIntrinsics(model.camera, report.pose_noise->intrinsics);
    model.intrinsics_stddev = report.pose_noise->intrinsics_stddev;
    // The camera correction of the parameter vector: the pose-noise hand-eye transform on the set's nominal one.
    const int cam = KinematicParameters(obs.robot.num_joints()).CamOffset();
    if (model.parameters.size() >= cam + 6) {
      const Rigid3 c = (eye_to_hand ? obs.robot.base_from_cam : obs.robot.flange_from_cam).Inverse() *
                       (eye_to_hand ? report.pose_noise->base_from_cam : report.pose_noise->flange_from_cam);
      model.parameters.segment<3>(cam) = c.translation;
      model.parameters.segment<3>(cam + 3) = LogSO3(c.rotation);
    }
    model.method_description += report.pose_noise_estimated ? ", flange poses with their noise estimated from the residuals"
                                                            : ", flange poses with their stated noise";
  } else if (report.model_choice && report.model_choice->made) {
    model.method_description += ", flange poses as recorded (cross-validated better than with a per-image flange noise)";
  }
  return model;
}

// Calibrate without its total time.
CalibrationReport CalibrateSteps(const ObservationSet& observations, const CalibrateOptions& options) {
  CalibrationReport report;
  report.method = options.method;
  const bool flange_poses = observations.UsesFlangePoses();
  const bool eye_to_hand = observations.robot.mount == CameraMount::kEyeToHand;
  if (flange_poses && options.method == Method::kPaper) {
    report.verdict = Verdict::kInvalidInput;
    report.message = "the paper's method needs joint angles; these poses are flange poses (use the bundle method)";
    return report;
  }
  if (eye_to_hand && options.method == Method::kPaper) {
    report.verdict = Verdict::kInvalidInput;
    report.message = "the paper's method needs a camera on the flange; this camera is fixed (eye_to_hand: use the "
                     "bundle method)";
    return report;
  }
  // Flange poses: the start from the images, the bundle, its checks, the acceptance; joints: the paper's
  // pipeline, the bundle (when chosen), the acceptance.
  ProgressScope progress(options.progress, (flange_poses ? 2 : 1) + (options.method == Method::kBundle ? 1 : 0) + 1,
                         "calibrate");
  ObservationSet prepared;
  if (flange_poses) {
    prepared = PrepareFlangePoseSet(observations, options, &report);
    progress.Advance();
    if (options.flange_scale == FlangeScale::kYardstick && observations.yardsticks.empty()) {
      report.verdict = Verdict::kInvalidInput;
      report.message = "the scale from yardsticks needs a yardstick in the observations";
      return report;
    }
    if (!observations.flange_from_cam_known && !report.hand_eye_start->ok) {
      report.verdict = Verdict::kDegenerate;
      report.message = "no hand-eye start: " + report.hand_eye_start->message;
      return report;
    }
  } else {
    PaperPipelineOptions paper = options.paper;
    paper.progress = progress.sink();
    report.paper = RunPaperPipeline(observations, paper);
    progress.Advance();
  }
  const ObservationSet& obs = flange_poses ? prepared : observations;
  report.verdict = VerdictFor(report.paper.outcome);
  report.message = report.paper.message;
  if (options.method == Method::kBundle) {
    BundleStageOptions stage_options = options.bundle;
    stage_options.hand_eye = options.hand_eye;
    stage_options.hand_eye.two_view.seed = options.paper.two_view.seed;
    report.bundle = RunBundleStage(obs, report.paper, stage_options);
    if (flange_poses) {
      report.bundle->start_note = observations.flange_from_cam_known
                                      ? "the set's nominal hand-eye transform and prior f_x"
                                      : "the hand-eye transform and f_x of the start from the images";
    }
    report.verdict = VerdictFor(report.bundle->bundle.outcome);
    report.message = report.bundle->bundle.message;
    if (report.bundle->bundle.outcome == bundle::Outcome::kConverged) {
      report.scene_moves = SceneMovesOf(obs, report.bundle->bundle.dots_in_base);
    }
    ObservationSet noise_set;
    bundle::PoseNoiseOptions noise;
    if (flange_poses) CheckFlangePoses(observations, obs, options, &report, &noise_set, &noise);
    const bool converged = report.bundle->bundle.outcome == bundle::Outcome::kConverged;
    const bool verification = !obs.PosesWithRole(PoseRole::kVerification).empty();
    const int folds = options.cross_validation_folds;
    const std::uint64_t seed = options.paper.two_view.seed;
    if (converged && report.PoseNoiseIsTheResult() && report.pose_noise_estimated &&
        report.flange_scale_yardsticks == 0 && folds >= 2) {
      CrossValidationReport exact_cv, noise_cv;
      report.model_choice = ChooseFlangeModel(obs, *report.bundle, stage_options, noise_set, *report.pose_noise, noise,
                                              folds, seed, &exact_cv, &noise_cv);
      if (!report.PoseNoiseIsTheResult()) {  // the exact-pose solve predicts better: it is the result
        report.pose_noise_heldout.reset();
        report.pose_noise_fit_geometry = FitGeometry();
      }
      if (!verification) report.cross_validation = report.PoseNoiseIsTheResult() ? noise_cv : exact_cv;
    } else if (converged && !verification) {
      report.cross_validation =
          report.PoseNoiseIsTheResult()
              ? CrossValidatePoseNoise(noise_set, *report.pose_noise, noise, folds, seed)
              : CrossValidate(obs, *report.bundle, stage_options, folds, seed);
    }
    progress.Advance();
  }
  if (flange_poses && options.flange_scale == FlangeScale::kYardstick && report.bundle &&
      report.bundle->bundle.outcome == bundle::Outcome::kConverged && !report.pose_noise) {
    report.verdict = Verdict::kInvalidInput;
    report.message = "the scale from yardsticks needs a flange pose noise, and none was stated (detect "
                     "--flange-pose-noise-mm/-deg) or found in the residuals: exact flange poses fix the scale "
                     "themselves";
    return report;
  }
  if (flange_poses) progress.Advance();
  if (report.accepted()) {
    const auto start = std::chrono::steady_clock::now();
    CheckAcceptance(obs, observations, &report);
    report.seconds_acceptance = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  progress.Advance();
  if (!report.has_model_verdict()) return report;  // no model for a result that is not to be applied
  report.model = ModelOf(report, obs, observations.camera);
  return report;
}

// The held-out RMS (px per coordinate) of a report: its cross-validation's, else its verification poses'; 0: none.
double HeldOutRmsOf(const CalibrationReport& report) {
  if (report.cross_validation && report.cross_validation->folds_tested > 0) return report.cross_validation->pooled.rms_px;
  if (report.bundle && report.bundle->heldout.ok) return report.bundle->heldout.overall.rms_px;
  return 0;
}

// A joint set of one scene whose images see the solved points in two places (scene_split.h): solved again with a
// scene each, and that solve is the result when its scenes' points lie apart and it predicts held-out poses better.
void SplitAMovedScene(const ObservationSet& obs, const CalibrateOptions& options, CalibrationReport* report) {
  if (obs.UsesFlangePoses() || options.method != Method::kBundle || !report->bundle) return;
  if (SceneNames(obs).size() > 1) return;
  const BundleStageReport& stage = *report->bundle;
  if (stage.calibrated_rho.size() == 0 || stage.bundle.dots_in_base.empty()) return;
  SceneSplit split = FindSceneSplit(obs, stage.calibrated_robot, stage.calibrated_rho, stage.calibrated_camera,
                                    stage.bundle.dots_in_base);
  if (!split.checked) return;
  if (!split.found) {
    report->scene_split = split;
    return;
  }
  split.one_scene_heldout_px = HeldOutRmsOf(*report);
  ObservationSet separated = WithSplitScenes(obs, split);
  CalibrationReport again = CalibrateSteps(separated, options);
  split.split_heldout_px = HeldOutRmsOf(again);
  const bool converged = again.bundle && again.bundle->bundle.outcome == bundle::Outcome::kConverged;
  const bool moved = !again.scene_moves.empty() && again.scene_moves.front().moved;
  const bool better = split.split_heldout_px > 0 && (split.one_scene_heldout_px == 0 ||
                                                     split.split_heldout_px * kSplitHeldOutGain <= split.one_scene_heldout_px);
  if (split.split_heldout_px == 0) {
    split.decision = "no held-out figure compares the two solves (no verification pose, no cross-validation): the "
                     "result is the one-scene solve; if the scene moved, name each pose's `scene:`";
  } else if (!converged) {
    split.decision = "the solve with a scene each did not converge (" + again.message + "): the result is the one-scene solve";
  } else if (!moved) {
    split.decision = "solved with a scene each, the two scenes' points lie no further apart than their scatter: the "
                     "result is the one-scene solve";
  } else if (!better) {
    split.decision = "solved with a scene each, it predicts held-out poses less than " +
                     std::to_string(static_cast<int>(kSplitHeldOutGain)) +
                     " times better (a model error, not a move?): the result is the one-scene solve";
  } else {
    split.applied = true;
    split.decision = "the result is the solve with a scene each";
    again.scene_split = split;
    again.solved_observations = std::move(separated);
    *report = std::move(again);
    return;
  }
  report->scene_split = split;
}

}  // namespace

CalibrationReport Calibrate(const ObservationSet& observations, const CalibrateOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CalibrationReport report = CalibrateSteps(observations, options);
  SplitAMovedScene(observations, options, &report);
  report.seconds_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace selfcal::calibration
