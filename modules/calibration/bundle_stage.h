// The product's calibration stage beyond the paper (../shared/DESIGN.md section 5): the kinematic bundle adjustment
// (bundle/bundle_adjustment.h) started from the paper pipeline's result, then the same held-out 3-D check
// as the paper's step 5 with the bundle's model and f_x.
//
// Start. When the paper pipeline succeeded: its metric calibrated model re-expressed on the nominal model
// (bundle::ExpressOnModel), with the entries the paper held fixed (its gauge: base, joint 1, redundant
// offsets, which its yardstick step had scaled) put back to their nominal values, and its f_x. The
// bundle then fixes its own gauge at the nominal values, as "identify corrections from the nominal model"
// asks, and the result is comparable entry by entry with a simulator's truth. When the paper pipeline
// failed (e.g. kDegenerate on a flat dot sheet, where the factor method has no unique solution): the
// nominal model with the prior f_x. A held f_x (not estimated) is always the stated prior. A start
// from the paper's result that does not converge is retried
// once from the nominal model (the report says so).
//
// Works on an ObservationSet only: no files, no hardware, no truth.
#pragma once

#include <string>

#include <Eigen/Core>

#include "bundle/bundle_adjustment.h"
#include "observations/observation_set.h"
#include "calibration/fit_geometry.h"
#include "calibration/hand_eye_start.h"
#include "calibration/heldout_reprojection.h"
#include "calibration/paper_pipeline.h"
#include "calibration/predicted_error.h"

namespace selfcal::calibration {

struct BundleStageOptions {
  bundle::BundleOptions bundle;
  bool retry_from_nominal = true;  // when the start from the paper's result does not converge
  // A joint-angle set started at the nominal model takes its camera correction from the images
  // (StartCameraFromImages) instead of the robot description's camera mount.
  bool camera_start_from_images = true;
  HandEyeStartOptions hand_eye;
};

enum class BundleStart { kNotRun, kPaperPipeline, kNominal };
const char* BundleStartName(BundleStart start);

struct BundleStageReport {
  bundle::BundleReport bundle;          // outcome, free/fixed names, rho (on observations.robot), covariance
  BundleStart start = BundleStart::kNotRun;
  std::string start_note;               // why this start, in words
  bool camera_from_images = false;      // the camera correction's start came from the images (StartCameraFromImages)
  double fx_start_px = 0;
  // The calibrated model ready for writing: ApplyParameters(observations.robot, bundle.rho), and its
  // rho (= Nominal(calibrated_robot), zero corrections). Empty unless the bundle produced a full rho.
  RobotModel calibrated_robot;
  Eigen::VectorXd calibrated_rho;
  // observations.camera with the bundle's intrinsics (every estimated one; the held ones as they were).
  CameraIntrinsics calibrated_camera;
  // Section 4.1 step 5 with the bundle's model and calibrated camera: 3-D error of the check distances
  // triangulated from the verification poses.
  VerificationSummary verification;
  VerificationSummary verification_nominal;  // the same with the nominal model and the prior f_x (before)
  // The predicted std of that 3-D error (calibration/predicted_error.h): the bundle's covariance of the free
  // parameters and f_x (the other intrinsics' uncertainty is not propagated), and the stated pixel noise
  // (observations.pixel_noise_px) of the verification images. ok = false when the covariance was unavailable.
  PredictedDistanceErrors predicted_error;
  // Held-out reprojection (heldout_reprojection.h), with no check distance needed: the bundle's dots and
  // model (its covariance in the normalisation), and the nominal model with the prior f_x and the dots it
  // triangulates from the identification images (taken as exact). Both are normalised with the bundle's
  // pixel noise estimate from the identification residuals (the stated noise when there is none);
  // heldout_at_stated_noise is the calibrated overall figure normalised with observations.pixel_noise_px.
  HeldOutReprojection heldout, heldout_nominal;
  HeldOutFigure heldout_at_stated_noise;
  // The camera poses and the identification residuals at the bundle's solution (fit_geometry.h), for the
  // report's plots; empty when the bundle gave no model.
  FitGeometry fit_geometry;
  // Wall seconds of each step after the solve (bundle.seconds), and of the whole stage.
  double seconds_verification = 0;     // the check distances with the nominal and the bundle's model
  double seconds_heldout = 0;          // both held-out reprojections
  double seconds_fit_geometry = 0;
  double seconds_predicted_error = 0;
  double seconds_total = 0;
};

// The held-out reprojection of a bundle's model on the verification poses of `observations`: the model with
// the bundle's intrinsics (observations.camera's otherwise) and covariance, the dots as the bundle placed
// them, the observations its screen removed left out, normalised with the bundle's pixel noise estimate
// where it has one, else the stated noise (*noise_px, *noise_dof: the normalisation's, noise_dof 0 for the
// stated noise; noise_source says which). With the bundle's estimated error model, each verification
// image's pose error is in the test too. at_noise_px > 0: normalised with that pixel noise instead, taken as
// known, the pixel part of the covariance scaled to it (the pose part as estimated). Shared by the stage and
// the cross-validation's folds.
HeldOutReprojection HeldOutReprojectionOfBundle(const ObservationSet& observations, const bundle::BundleReport& b,
                                                double* noise_px, int* noise_dof, double at_noise_px = 0);

// Runs the bundle adjustment on `observations` started as described above from `paper` (the report of
// RunPaperPipeline on the same observations; any outcome). kInvalidInput from the bundle's own checks when
// the observations or options are invalid.
BundleStageReport RunBundleStage(const ObservationSet& observations, const PaperPipelineReport& paper,
                                 const BundleStageOptions& options);

// The start described above, for callers that time the solve alone (benchmarks). *fx_px receives f_x.
Eigen::VectorXd BundleStartFromPaper(const ObservationSet& observations, const PaperPipelineReport& paper,
                                     double* fx_px, BundleStart* start = nullptr, std::string* note = nullptr);

}  // namespace selfcal::calibration
