// Module calibration (ARCHITECTURE.md): the solve; no files, no hardware, no simulator. This facade and:
//   paper_pipeline.h        RunPaperPipeline, section 4.1 steps 2-5
//   bundle_stage.h          RunBundleStage: the bundle from the paper's model (or the nominal one when it
//                           failed) and its held-out verification
//   heldout_reprojection.h  the identification images' dots projected into the verification images with the
//                           calibrated and the nominal model, a chi-square/F test with the prediction's covariance
//   acceptance.h            the checks that turn a verdict to kRejected (see Calibrate below)
//   cross_validation.h      CrossValidate: without verification poses, the bundle re-run without each fold and
//                           the fold predicted
//   pose_noise_result.h     a flange-pose set's pose-noise solve as the result: its prediction model, held-out
//                           reprojection, cross-validation folds and fit geometry
//   hand_eye_start.h        StartHandEye (flange poses: Procrustes rotation, a linear translation with one length
//                           per pair; on a flat target twoview/planar_views.h) and StartCameraFromImages
//   motion_check.h          CheckImageMotions: the free-camera bundle's camera motions against the flange
//                           motions, pair by pair, and each image's pose against the model's
//   fit_geometry.h          camera poses and residuals at the bundle's solution, for the report's plots
//   predicted_error.h       PredictDistanceErrors: first-order 3-D error of held-out distances
//   scene_moves.h           SceneMovesOf: where each scene's points lie against the first's (a board that moved)
//   scene_split.h           FindSceneSplit: one set's images that see the scene in two places (a scene that
//                           moved between poses), solved again with a scene each
//   scene_shift.h           SceneShiftOfVerification: the move of the scene that would explain refused
//                           verification images
// Uses bundle, identification, twoview, observations, kinematics, geometry, camera, base.
//
// The calibration facade: one entry point from an observation set to a report that carries the verdict
// and, when the verdict is "accepted", the model to write.
//
//   Calibrate(observations, options)
//     -> RunPaperPipeline                 (joint angles: the baseline, and the bundle adjustment's start)
//        or StartHandEye                  (flange poses: the hand-eye transform from the images; the
//                                          yardsticks become checks, the flange translations are metric)
//     -> RunBundleStage                   (Method::kBundle, the default: the product's answer)
//     -> verdict of the chosen method     (one vocabulary for every method: Verdict)
//     -> acceptance checks                (acceptance.h: a converged model that fails its held-out test
//                                          or predicts worse than the nominal model is kRejected)
//     -> the chosen method's model        (only when accepted)
//
// Commands call this and nothing below it: they parse, load, call Calibrate, and write what it returns
// (report/ turns the report into JSON and text). Works on an ObservationSet only: no files, no hardware,
// no truth, no exit codes (the application maps the verdict to those).
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "calibration/acceptance.h"
#include "calibration/bundle_stage.h"
#include "calibration/cross_validation.h"
#include "calibration/hand_eye_start.h"
#include "bundle/pose_noise_bundle.h"
#include "calibration/model_choice.h"
#include "calibration/motion_check.h"
#include "calibration/paper_pipeline.h"
#include "calibration/pose_noise_result.h"
#include "calibration/scene_moves.h"
#include "calibration/scene_split.h"
#include "kinematics/robot_model.h"
#include "observations/observation_set.h"

namespace selfcal::calibration {

enum class Method {
  kBundle,  // the paper's pipeline, then the kinematic bundle adjustment started from it (the product)
  kPaper,   // the paper's pipeline alone (Meng & Zhuang 2001, section 4.1; the baseline)
};
const char* MethodName(Method method);  // "bundle", "paper"
std::optional<Method> ParseMethod(std::string_view name);

// The verdict on a calibration, whatever method produced it.
enum class Verdict {
  kAccepted,         // converged, metric: the model may be applied
  kInvalidInput,     // the observations or options fail validation (the message names pose and dot)
  kDegenerate,       // too few usable poses, insufficient excitation, nothing identifiable
  kScaleUnresolved,  // no usable yardstick: no metric scale
  kUnconverged,      // the solver stopped without converging: the result is not to be applied
  kSolverFailure,    // the solver failed (non-finite start, internal failure)
  kRejected,         // converged, but refused by its acceptance checks (acceptance.h): not to be applied
  // Converged and passed every check that could be made, but no held-out test could be made (no
  // verification pose, no cross-validation): the model is written, and says it was not verified.
  kUntested,
};
const char* VerdictName(Verdict verdict);  // "accepted", "invalid_input", ...

enum class FlangeScale { kAuto, kFlange, kYardstick };

struct CalibrateOptions {
  Method method = Method::kBundle;
  PaperPipelineOptions paper;  // paper.two_view.seed seeds the RANSAC sampling
  BundleStageOptions bundle;
  // Without verification poses: k-fold cross-validation of the bundle's model over the identification poses
  // (cross_validation.h; seeded by paper.two_view.seed). 0: not run.
  int cross_validation_folds = 4;
  HandEyeStartOptions hand_eye;  // flange-pose sets (its two-view seed is paper.two_view.seed)
  bundle::FreeCameraOptions motion_check;  // flange-pose sets: the images' own camera motions
  // Flange-pose sets: what fixes the metric scale. kFlange: the flange translations alone, the yardsticks
  // are checks; kYardstick: the yardsticks are length constraints (the paper's scale) beside the flange
  // translations in the pose-noise bundle, which needs a flange pose noise, stated or estimated from the
  // residuals (exact poses fix the scale themselves); kAuto: kYardstick when the set has a yardstick and a
  // pose noise was stated or estimated, else kFlange. A controller's translations carry its own scale
  // error; a measured length is the one the images are scaled to.
  FlangeScale flange_scale = FlangeScale::kAuto;
  // Told the stages (the start, the chosen method, the checks) and, inside the paper's pipeline, its
  // two-view pairs, for a person watching; null: nothing reported.
  ProgressSink* progress = nullptr;
};

// The chosen method's calibrated model, ready for writing.
struct CalibratedModel {
  RobotModel robot;            // nominal values replaced by the calibrated ones, metric
  // The calibrated camera: the observations' with every intrinsic the method estimated replaced (the
  // paper pipeline: f_x), the image size and the held intrinsics as observed.
  CameraIntrinsics camera;
  IntrinsicsMask intrinsics_estimated{};
  // Standard deviations of the estimated intrinsics from the solve that gave them (NaN: held, or
  // unavailable); flange-pose sets: the pose-noise bundle's when it ran.
  IntrinsicsVector intrinsics_stddev = {NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN};
  // The calibrated parameter vector on the observations' nominal model (corrections for base and
  // camera), when the method estimates one (the bundle adjustment); empty otherwise.
  Eigen::VectorXd parameters;
  std::string method_description;  // e.g. "kinematic bundle adjustment"
  // A flange-pose set: the standard deviations of a correction flange_from_cam * Exp(c) (translation m,
  // rotation vector rad, camera frame), from the solve that gave robot.flange_from_cam and the camera
  // (the pose-noise bundle when it ran, else the exact-pose bundle); NaN when unavailable.
  Eigen::Matrix<double, 6, 1> flange_from_cam_stddev = Eigen::Matrix<double, 6, 1>::Constant(NAN);
  // Eye-to-hand (robot.mount; robot.base_from_cam the calibrated fixed camera): the standard deviations of a
  // correction base_from_cam * Exp(c) (translation m, rotation vector rad, camera frame), joint-angle and
  // flange-pose sets alike, from the same solve; flange_from_cam_stddev then stays NaN.
  Eigen::Matrix<double, 6, 1> base_from_cam_stddev = Eigen::Matrix<double, 6, 1>::Constant(NAN);
};

struct CalibrationReport {
  Method method = Method::kBundle;
  Verdict verdict = Verdict::kSolverFailure;
  std::string message;  // why, when not accepted (the chosen method's own message)
  PaperPipelineReport paper;               // run on joint-angle sets (kNotRun on flange-pose sets)
  // A flange-pose set (ObservationSet::UsesFlangePoses): the hand-eye start from the images, which is the
  // bundle's nominal hand-eye transform when the set gave none.
  std::optional<HandEyeStartReport> hand_eye_start;
  // A flange-pose set whose bundle converged: the images' own camera motions against the flange motions.
  std::optional<MotionCheck> motion_check;
  // A flange-pose set with a pose noise, stated in the set or else estimated by the bundle's error model
  // (its camera pose per image): the hand-eye bundle with a corrected flange pose per image
  // (bundle/pose_noise_bundle.h), started from the exact-pose bundle; its hand-eye transform and f_x are
  // the model's when it converged.
  std::optional<bundle::PoseNoiseReport> pose_noise;
  bool pose_noise_estimated = false;  // the noise of pose_noise is the error model's, not the set's
  double pose_noise_translation_m = 0, pose_noise_rotation_rad = 0;  // the noise it modelled, per axis
  // When the pose-noise solve succeeded it is the result (PoseNoiseIsTheResult; pose_noise_result.h): the model,
  // the verdict's held-out test and every figure of the report come from it. Its held-out reprojection of the
  // verification poses (when the set names some; the verdict's heldout_test), and the camera poses and
  // identification residuals of its fit (the report's plots).
  std::optional<HeldOutReprojection> pose_noise_heldout;
  FitGeometry pose_noise_fit_geometry;
  // The noise estimated, not stated: which of the exact-pose and the pose-noise solves predicts identification
  // poses it never saw better (model_choice.h); the exact-pose one is the result when it does.
  std::optional<ModelChoice> model_choice;
  // A flange-pose set: how many yardsticks constrained the scale beside the flange translations (0: the
  // flange translations alone; the yardsticks were checks).
  int flange_scale_yardsticks = 0;
  std::optional<BundleStageReport> bundle;  // when method == kBundle
  // The bundle converged and the set names no verification pose: its k-fold held-out figure (the pose-noise
  // solve's folds when it is the result).
  std::optional<CrossValidationReport> cross_validation;
  // The bundle converged on a set of several scenes sharing point ids: where each lies against the first.
  std::vector<SceneMove> scene_moves;
  // A joint set of one scene whose bundle solved: whether its images see the points in two places (a scene that
  // moved between poses), and when they do whether the solve with a scene each is the result.
  std::optional<SceneSplit> scene_split;
  // The set the result solved when it is not the one given (scene_split applied: the poses with a scene each,
  // SeparateScenes' ids); the outputs (residuals, scene points) are of this set.
  std::optional<ObservationSet> solved_observations;
  std::optional<CalibratedModel> model;    // the chosen method's model, only when accepted or untested
  // The acceptance checks of the chosen method's converged model (empty when it did not converge).
  Acceptance acceptance;
  // Method::kPaper on joint angles, converged: the held-out figures of its model and of the nominal one.
  std::optional<PaperHeldOut> paper_heldout;
  // Wall seconds of the acceptance checks and of the whole call (every stage: paper.seconds_*,
  // bundle->bundle.seconds and bundle->seconds_*).
  double seconds_acceptance = 0, seconds_total = 0;

  bool accepted() const { return verdict == Verdict::kAccepted; }
  bool PoseNoiseIsTheResult() const {
    return pose_noise.has_value() && pose_noise->ok && (!model_choice || model_choice->pose_noise_chosen);
  }
  // A model is written: accepted, or converged and passing what could be checked without a held-out test.
  bool has_model_verdict() const { return verdict == Verdict::kAccepted || verdict == Verdict::kUntested; }
  // The chosen method's held-out verification (3-D error of the check distances), before and after.
  const VerificationSummary& verification_calibrated() const;
  const VerificationSummary& verification_nominal() const;
};

CalibrationReport Calibrate(const ObservationSet& observations, const CalibrateOptions& options);

Verdict VerdictFor(Outcome paper_outcome);
Verdict VerdictFor(bundle::Outcome bundle_outcome);

}  // namespace selfcal::calibration
