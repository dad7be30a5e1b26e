// Held-out reprojection (issue 14, item 1): a verification that needs nothing but the images.
//
// The dots are placed from the identification images alone (for the calibrated model: as the bundle
// adjustment estimated them; for the nominal model: triangulated with it, a structure-only solve), then
// projected into every verification image with the same model and compared with the detections there.
// The verification images entered no solve, so their residuals test the model's predictions.
//
// Test. Each residual r (2 px) is normalised by the covariance of (detection - prediction):
//
//   C = sigma^2 I  +  J_d H_dd^-1 J_d^T  +  G Sigma G^T,      G = J_theta - J_d H_dd^-1 H_dtheta
//
// (plus, with an estimated error model, each verification image's pose error J_e Theta J_e^T, J_e the
// derivative of its pixels with respect to a small motion of its camera; PredictionModel. Then the
// identification images' pose errors also moved the fit: their share of Sigma is replaced by U_i U_i^T, U_i
// their effect on the parameters and the dots together, as the least-squares fit carries them. And a weak
// parameter held at the robot description's value, PredictionModel::held_prior, adds its manufacturing
// tolerance's effect, directly and through what the fit made of it: without it the bias of a held value
// failed 16 % of correct models under a 0.01 deg joint noise, where the weak directions are held.)
//
// sigma^2 I: the detection noise of the verification image; J_d H_dd^-1 J_d^T: the dot's position error
// given the parameters (H_dd = sum over its identification views of J^T J / sigma^2, the same dot seen in
// several verification images correlates them); G Sigma G^T: the parameters' error (Sigma: the bundle's
// covariance of the free parameters, f_x, k1, dots marginalised) including the dot's correlated response
// to it (H_dtheta: the identification views' cross term; theta: the free rho entries and the estimated
// intrinsics, whatever subset of the nine). This is the bundle's own joint covariance of
// (dots, parameters), to first order, except that the yardstick's coupling of its two dots is left out
// (those two dots' positions are taken as slightly less certain than they are). For the nominal model the
// parameters are taken as exact (no Sigma). The statistic is r^T C^-1 r over the residuals of a pose
// (per pose) or of all of them (overall), with all correlations, computed by the Woodbury identity; for a
// correct model and a known noise it is chi-square with 2 degrees of freedom per predicted dot; with the
// noise estimated from the identification residuals (noise_dof of them), statistic / dof is
// F(dof, noise_dof) instead (the estimate's own scatter, ~3 % in variance for 2000 residuals, would
// otherwise fail a correct model far more often than 1 %). The test passes when the statistic is at or
// below its 95 % quantile (kHeldOutTestLevel): Wilson-Hilferty for chi-square (relative error of the quantile below 1e-3 for 4
// or more degrees of freedom), Paulson's cube-root approximation for F (which is Wilson-Hilferty's when
// noise_dof is infinite).
//
// Jacobians: central differences of the projection with the full lens (steps 1e-6 m or rad for rho and
// the dots, 1e-3 px for f_x, c_x, c_y, 1e-6 for mu and the lens coefficients). Frames and units as in
// bundle/bundle_adjustment.h; pixels in px.
#pragma once

#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "kinematics/robot_model.h"
#include "observations/observation_set.h"

namespace selfcal::calibration {

// The probability at which the held-out test's limit is the statistic's quantile: a correct model with
// the right noise passes it in 95 % of calibrations (the verdict's false refusal rate is 5 %).
inline constexpr double kHeldOutTestLevel = 0.95;

// The model whose predictions are checked.
struct PredictionModel {
  RobotModel robot;           // the rho below is on this model
  Eigen::VectorXd rho;
  CameraIntrinsics camera;    // every intrinsic as the model has it (the calibrated lens)
  // The covariance of the estimated entries in the order free_indices, then the estimated intrinsics in
  // camera/camera.h's Intrinsic order; empty: the model is taken as exact.
  std::vector<int> free_indices;
  IntrinsicsMask intrinsics_estimated{};
  Eigen::MatrixXd covariance;
  // The part of `covariance` that the images' pose errors make (bundle/error_model.h, the sandwich's second
  // term; empty: none). With a camera pose error (not pose_error_at_flange) the identification images' pose
  // errors then enter the prediction explicitly, moving the parameters and the dots together.
  Eigen::MatrixXd covariance_pose_part;
  // Parameters held at the robot description's value with a prior: rho index and the standard deviation of
  // the true value about it (a weak parameter's manufacturing tolerance). The prediction carries their
  // errors, directly and through what the fit made of them.
  std::vector<std::pair<int, double>> held_prior;
  // Each verification image's own camera pose error (bundle/error_model.h), per axis in the camera frame:
  // C gains J_e diag(s_t^2 I, s_r^2 I) J_e^T over the dots of that image. 0: none.
  double pose_translation_m = 0, pose_rotation_rad = 0;
  // A joint set's joint-reading noise per joint (rad): Theta gains s_q^2 A A^T with A the image's
  // CameraMotionPerJoint (kinematics/joint_motion.h). 0: none.
  double joint_rad = 0;
  // True: the two sizes above are the recorded flange pose's noise instead (bundle/pose_noise_bundle.h:
  // base_from_flange * Exp(delta), delta per axis in the flange frame), carried to the camera through the
  // hand-eye transform: J_e A diag(s_t^2 I, s_r^2 I) A^T J_e^T with A the adjoint of cam_from_flange.
  bool pose_error_at_flange = false;
  // The yardsticks' standard deviation in the fit (bundle/bundle_adjustment.h; 0: the fit had none, or the
  // model was not fitted): their two dots were solved together, and so are they here.
  double yardstick_sigma_m = 0;
  // How well the fit's residuals gave the variances in C (bundle::ErrorModel::relative_covariance over
  // pixel, translation, rotation, joint; zero rows: stated, taken as known). Non-zero: the test's F
  // distribution takes its noise degrees of freedom from it (heldout_chi_square.h), not from noise_dof.
  Eigen::Matrix4d relative_variance_covariance = Eigen::Matrix4d::Zero();
};

// One detection beside the model's prediction of it (for plots of the residuals over the image).
struct ObservedResidual {
  std::string pose_id;
  int dot_id = -1;
  Eigen::Vector2d pixel_px = Eigen::Vector2d::Zero();     // the detection
  Eigen::Vector2d residual_px = Eigen::Vector2d::Zero();  // detection - prediction
};

// One verification pose, or all of them.
struct HeldOutFigure {
  std::string pose_id;        // empty for the overall figure
  int num_residuals = 0;      // predicted dots (2 coordinates each)
  int dof = 0;                // 2 per predicted dot
  double rms_px = NAN;        // RMS of (detection - prediction) per coordinate
  double max_px = NAN;        // largest 2-D error
  double chi_square = NAN;    // r^T C^-1 r
  int noise_dof = 0;          // the noise's degrees of freedom when it was estimated, 0 when taken as known
  // The part of the statistic that the images' estimated pose errors make, tr(C^-1 C_pose) (of dof), and the
  // degrees of freedom of their size's estimate (0: none, or taken as known; heldout_chi_square.h).
  double pose_share = 0;
  int pose_noise_dof = 0;
  double chi_square_limit = NAN;  // kHeldOutTestLevel quantile of the statistic (ChiSquareQuantile)
  double p_value = NAN;       // probability of a larger statistic with a correct model
  bool test_passed = false;   // chi_square <= chi_square_limit
};

struct HeldOutReprojection {
  bool ok = false;            // at least one residual
  std::string message;        // why not, in words
  double noise_px = NAN;      // the sigma of the normalisation
  std::string noise_source;   // where it came from, in words
  bool prediction_uncertainty = false;  // the parameters' covariance is in C (the dots' always is)
  int num_not_predicted = 0;  // detections of dots that the identification images do not place
  std::vector<HeldOutFigure> poses;   // verification poses in file order (those with a residual)
  // Verification poses with dots none of which is predicted (not placed by the identification images, or
  // behind the camera at this pose): poses that cannot be used, in file order.
  std::vector<std::string> unused_poses;
  HeldOutFigure overall;
  // overall.rms_px at the scene: mm_per_px is the median camera-to-dot distance over f_x
  // (fit_geometry.h), rms_mm = overall.rms_px * mm_per_px; NaN when the stage did not give the depth.
  double mm_per_px = NAN, rms_mm = NAN;
  std::vector<ObservedResidual> residuals;  // every predicted detection, pose by pose (those in `overall`)
  // Gross detection errors left out of the figures: a detection whose residual, given the other detections
  // of its pose, lies beyond kGrossErrorChiSquare (4.4 sigma), the worst first and at most kMaxGrossErrorShare
  // of the predicted detections (heldout_gross_errors.h: a misdetected corner moves one dot; a wrong model
  // moves many and keeps all but the worst few in the test).
  std::vector<ObservedResidual> gross_errors;
};

inline constexpr double kGrossErrorChiSquare = 19.3;  // P = 6.5e-5 for 2 degrees of freedom
inline constexpr double kMaxGrossErrorShare = 0.05;

// The identification observations (pose id, dot id) that a solve left out, e.g. by its screen.
using ExcludedObservations = std::set<std::pair<std::string, int>>;

// The held-out figures of `model` with the dots `dots_in_base` (in the base frame of model.robot),
// normalised with `noise_px` (estimated from noise_dof residual degrees of freedom, or 0: taken as known).
// Dots seen in fewer than two kept identification views are not predicted.
HeldOutReprojection HeldOutReprojectionOf(const ObservationSet& observations, const PredictionModel& model,
                                          const std::map<int, Eigen::Vector3d>& dots_in_base,
                                          const ExcludedObservations& excluded, double noise_px, int noise_dof);

// The dots triangulated from the identification images with a model taken as exact (every dot seen in
// at least two of them; those not triangulable are left out).
std::map<int, Eigen::Vector3d> TriangulateIdentificationDots(const ObservationSet& observations,
                                                             const PredictionModel& model);

// The nominal model's held-out figures: observations.robot at its nominal values and camera, taken as exact,
// with the dots it triangulates from the identification images.
HeldOutReprojection NominalHeldOutReprojection(const ObservationSet& observations, double noise_px, int noise_dof);

// The distribution of the statistic X with `dof` degrees of freedom: chi-square (noise_dof = 0,
// Wilson-Hilferty) or dof F(dof, noise_dof) (Paulson): the quantile at probability p (0 < p < 1), and the
// upper tail P(X > x). With a pose part (pose_share of the dof, its size estimated from pose_noise_dof degrees
// of freedom), X = lambda_p (chi-square of dof - pose_share) + lambda_e (chi-square of pose_share), lambda_e
// the true size over the estimate, pose_noise_dof / chi-square(pose_noise_dof) (the estimate's sampling
// distribution, as for the pixel noise's lambda_p in F): moment-matched to a scaled chi-square for each
// lambda_e and averaged over a grid of them.
double ChiSquareQuantile(double p, int dof, int noise_dof = 0, double pose_share = 0, int pose_noise_dof = 0);
double ChiSquareUpperTail(double x, int dof, int noise_dof = 0, double pose_share = 0, int pose_noise_dof = 0);

}  // namespace selfcal::calibration
