// Module bundle (ARCHITECTURE.md): the kinematic bundle adjustment (this header), called by
// calibration::RunBundleStage (the product's default method) and the study. Its files:
//   error_model.h           the cell's error model from the residuals by variance components: pixel noise and
//                           each image's pose error, the covariance under it, the score test of held values
//   kinematic_lm.h          the solver: Ceres' trust-region Levenberg-Marquardt rule for rule, dots eliminated by
//                           their Schur complement in closed form, the globals' normal matrix one rank update
//   ceres_reference_solve.h the Ceres DENSE_SCHUR solve it replaced, kept as the tests' reference
//   weak_directions.cc      joint parameters the poses determine worse than a manufacturing tolerance held at the
//                           description's value and named
//   free_camera_bundle.h    every image's camera free, for checking recorded poses against the images
//   pose_noise_bundle.h     the hand-eye bundle with a stated flange pose noise (a corrected pose per image)
//   small_solve.h           both of those with the nine intrinsics as one block, the held ones fixed by a
//                           ceres::SubsetManifold
// Intrinsics by an IntrinsicsMask over camera/camera.h's nine (f_x by default), parameters held or freed by name
// (--fix / --free, the groups lens and intrinsics); an intrinsic the poses cannot separate is refused by name.
// Uses identification, observations, kinematics, camera, base; Ceres private.
//
// Kinematic bundle adjustment (../shared/DESIGN.md section 5): one least-squares problem over every identification
// image, beyond the paper's pipeline (which only initialises it).
//
// Residual of dot j seen at identification pose i (pixels, whitened by sigma = pixel_noise_px):
//
//   r_ij = ( project(intrinsics, cam_i_from_base * p_j_in_base) - pixel_ij ) / sigma,
//   cam_i_from_base = base_from_cam(q_i; rho)^-1          (kinematics/robot_model.h, camera/camera.h)
//
// with OpenCV's radial-tangential lens (intrinsics fx, mu, cx, cy, k1, k2, p1, p2, k3)
//
// Eye-to-hand (observations.robot.mount: a fixed camera, the dots on the flange) cam_i_from_base becomes
// cam_i_from_flange = points_from_cam(q_i; rho)^-1 = base_from_cam(rho)^-1 * base_from_flange(q_i; rho) and the
// dots p_j live in the flange frame (kinematics/robot_model.h, PointsFromCam; dots_in_base holds them there).
// The gauge mirrors eye-in-hand's: the camera correction absorbs the base correction and joint 1, the points
// the tail (j_n.theta, j_n.d), so the same selection order keeps the camera and fixes those.
//
// and, per yardstick (dots a, b, known length L), the length constraint
//
//   r_L = ( |p_a_in_base - p_b_in_base| - L ) / yardstick_sigma_m
//
// a soft constraint with a tiny sigma (1e-6 m by default) rather than a hard parameterisation: it keeps
// every dot an ordinary 3-vector, is exactly satisfied by noise-free data (so exact recovery stays exact),
// and its variance is ~1e4 times below what the images alone give for a length (they know it to ~0.1 mm). Its two dots stay out of
// the Schur-eliminated group (a residual may touch only one eliminated block).
//
// Unknowns: the identifiable entries of rho (camera correction included), the intrinsics asked for (f_x
// by default; any subset of the nine by name), and every dot seen in at least two identification poses
// (p_j in the base frame, m). Gauge: with unknown
// dots a rigid motion of the whole scene is invisible, so the base correction and joint 1's parameters
// cannot be seen; the yardstick fixes the scale. Nothing is assumed: the rank of the reduced Jacobian
// (the dots eliminated: J_g^T (I - P_dots) J_g with J_g the columns of rho and the estimated
// intrinsics) decides, evaluated
// at the nominal model (where nominally parallel axes are exactly parallel; at a perturbed start the d
// offsets of a parallel pair would look independent, K2) with the dots triangulated from the start.
// Columns are taken greedily in the order of the estimated intrinsics (fx, mu, cx, cy, k1, k2, p1, p2,
// k3), camera, base, alpha/a/theta/d joint by joint, betas last (the order of
// identification/identifiability.h, so that the same representative of each dependent set is kept).
// An estimated intrinsic the poses cannot separate from those before it is refused (kDegenerate, named);
// a principal point traded against the camera rotation keeps both when the perspective of the views
// separates them, with their correlation in the covariance. Everything else is held at its start value
// and reported by name. For the
// PUMA 560 on the arc trajectory this frees 24 kinematic parameters + f_x and fixes the base, joint 1,
// j2.beta, j3.d, j4-j6.beta, j6.theta and j6.d: the same set as the relative-pose analysis with known
// scale.
//
// Solver: Levenberg-Marquardt (Ceres), DENSE_SCHUR with the dots eliminated; one residual block per
// observation with an analytic Jacobian (per pose, cam_from_base and its derivative with respect to the
// free parameters are computed once per evaluation point by forward-mode autodiff and shared by the
// pose's dots). About 20-30 ms for 15 poses x 80 dots.
//
// Frames and units: rho in m and rad (robot_model.h); dots in the base frame of the model (the gauge is
// the start's base and joint-1 parameters); pixels as in camera/camera.h; f_x, c_x, c_y in px.
#pragma once

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bundle/error_model.h"
#include "camera/camera.h"
#include "kinematics/joint_motion.h"
#include "kinematics/robot_model.h"
#include "observations/observation_set.h"

namespace selfcal::bundle {

struct BundleOptions {
  // The intrinsics estimated (camera/camera.h's Intrinsic order); the others are held at
  // observations.camera's values (f_x at fx_start). Names in held_parameters / free_parameters override.
  IntrinsicsMask intrinsics = kFocalLengthOnly;
  // Huber loss on each observation's 2-D reprojection error, in pixels (the loss acts on the whitened
  // residual at huber_px / pixel_noise_px standard deviations). Used while outliers are screened; the
  // final fit is plain least squares on the kept observations.
  double huber_px = 2.0;
  // Post-fit screen (K7): after each robust solve every observation is judged against the solution;
  // those with reprojection error |r| (2-D norm, px) above screen_sigma * sigma are left out of the next
  // solve (and earlier exclusions that now pass come back), until the set is stable or max_screen_rounds
  // refits were made. sigma = max(pixel_noise_px, median(|r|) / sqrt(2 ln 2)), so an understated noise
  // level does not strip inliers.
  double screen_sigma = 4.0;
  int max_screen_rounds = 5;
  int max_iterations = 100;
  double function_tolerance = 1e-12;
  double gradient_tolerance = 1e-12;
  double parameter_tolerance = 1e-12;
  double yardstick_sigma_m = 1e-6;
  double rank_tolerance = 1e-8;        // relative, on the column-normalised reduced Jacobian
  int min_identification_poses = 3;    // fewer: kDegenerate before anything else
  // K3: refuse (kDegenerate) when these poses identify fewer kinematic parameters than generic poses of
  // the same robot do (too few poses, or poses that do not excite some joint).
  bool require_generic_rank = true;
  // Parameters held at their start values by request (e.g. a hand-eye-only solve with kinematics
  // trusted: {"kinematics"}), and, when not empty, the only ones that may be estimated (everything else
  // held). Names: a parameter (`j2.beta`, `cam.tx`), a joint (`j3`), a group (`base`, `camera` or
  // `hand_eye`, `kinematics` = base and every joint), an intrinsic (`fx`, `mu` or its alias `fy`, `cx`,
  // `cy`, `k1`, `k2`, `p1`, `p2`, `k3`), `lens` (k1 k2 p1 p2 k3), `intrinsics` (all nine). A held
  // intrinsic is as false in `intrinsics`; one named in free_parameters is estimated, and a non-empty
  // free list holds every intrinsic it does not name. The rank analysis still decides among the rest.
  // With anything held, the generic-rank check (require_generic_rank) does not apply.
  std::vector<std::string> held_parameters;
  std::vector<std::string> free_parameters;
  // Weak directions (near-unidentifiable, not only rank deficient): a joint parameter (alpha, a, theta, d,
  // beta) whose standard deviation given the parameters kept before it (the gauge's selection order:
  // intrinsics, camera, base, joint by joint) exceeds its manufacturing tolerance at the stated pixel noise is
  // held at the robot description's value and named in BundleReport::weak: the description is then the
  // better estimate. The camera, base and intrinsics are never held this way. 0 turns a kind off.
  double weak_length_tolerance_m = 5e-3;
  double weak_angle_tolerance_rad = 8.726646259971648e-3;  // 0.5 deg
  // Estimate the cell's pose error beside the pixel noise (error_model.h) and state the covariance under
  // that model; false: pixel noise only (the covariance of the stated model, as before).
  bool estimate_pose_error = true;
  // Empty when valid; otherwise every problem, one per line.
  std::string Validate() const;
};

enum class Outcome {
  kNotRun,
  kConverged,        // Ceres CONVERGENCE (K4)
  kNoConvergence,    // result kept but not to be applied
  kFailure,          // solver failure, non-finite start (K5)
  kInvalidInput,     // the observation set or the arguments fail validation (names pose and dot)
  kScaleUnresolved,  // no yardstick with both ends seen from two identification poses (S1)
  kDegenerate,       // too few poses, insufficient excitation, f_x unidentifiable
};
const char* OutcomeName(Outcome outcome);

struct RemovedObservation {
  std::string pose_id;
  int dot_id = -1;
  double residual_px = 0;  // |r| at the final solution
};

// A joint parameter held at the robot description's value because the data determine it worse than its
// tolerance (BundleOptions::weak_length_tolerance_m, weak_angle_tolerance_rad).
struct WeakParameter {
  std::string name;            // "j4.d"
  bool length = true;          // m, else rad
  double conditional_std = 0;  // given the parameters kept before it, at the stated pixel noise (or the error model's)
  double tolerance = 0;
  std::string combination;     // "0.71 j2.d - 0.71 j4.d": what it trades off with
  // Found after the fit, under its estimated error model (pixel noise and each image's pose error), rather
  // than at the stated pixel noise before it.
  bool under_error_model = false;
};

struct BundleReport {
  Outcome outcome = Outcome::kNotRun;
  std::string message;
  Eigen::VectorXd rho;                        // full; fixed entries keep their start values
  double fx_px = 0;                           // = intrinsics[kFx], for its many readers
  // Every intrinsic (Intrinsic order), held ones at their start; what was estimated (BundleOptions::
  // intrinsics after the names of held_parameters / free_parameters).
  IntrinsicsVector intrinsics{};
  IntrinsicsMask intrinsics_estimated{};
  std::map<int, Eigen::Vector3d> dots_in_base;  // every dot that entered the solve (flange frame eye-to-hand)
  double yardstick_sigma_m = 0;                 // BundleOptions::yardstick_sigma_m when a yardstick entered it
  std::vector<int> free_indices;              // kinematic, in rho order
  std::vector<std::string> free_names, fixed_names;  // fixed: by the rank analysis and by request
  std::vector<std::string> held_names;        // held by request (BundleOptions::held_parameters, free_parameters)
  std::vector<std::string> null_combinations; // "1.00 base.tx", "0.71 j2.d - 0.71 j3.d", ...
  std::vector<WeakParameter> weak;            // held at the description's value: the data determine them too poorly
  std::vector<BarelyMovingJoint> barely_moving;  // over the identification poses (kinematics/joint_motion.h)
  int generic_rank = 0;                       // free kinematic count for generic poses of this robot
  double condition_number = 0;                // column-normalised reduced Jacobian of the free set
  // The estimated error model of the cell (BundleOptions::estimate_pose_error; error_model.h).
  ErrorModel error_model;
  // The parameters held by request tested against the data (error_model.h's score test).
  HeldValueTest held_values;
  // Marginal standard deviations, dots as nuisance, under error_model when it was estimated (error_model.h's
  // sandwich), else s^2 (J_g^T (I - P_dots) J_g)^-1 over the free columns, s^2 = 2 final_cost /
  // (residuals - unknowns). NaN for fixed entries or when unavailable (K8).
  Eigen::VectorXd stddev;                     // rho size
  double fx_stddev = 0;                       // = intrinsics_stddev[kFx]
  IntrinsicsVector intrinsics_stddev{};       // NaN when not estimated or unavailable
  bool covariance_available = false;
  std::string covariance_message;
  // Order: free_indices, then the estimated intrinsics in Intrinsic order (EstimatedIntrinsics).
  Eigen::MatrixXd covariance_free, correlation_free;
  // The part of covariance_free that the images' pose errors give (error_model.h); the rest scales with the
  // pixel variance. Empty when no pose error was estimated.
  Eigen::MatrixXd covariance_pose_part;
  std::vector<RemovedObservation> removed;    // by the screen
  std::vector<int> dropped_dots;              // seen fewer than twice, or not triangulable at the start
  int num_observations = 0;                   // used in the final fit
  double rms_reprojection_px = 0;             // RMS of |r| over them
  // The pixel noise these residuals imply, per coordinate: pixel_noise_px * s, s^2 = 2 final_cost / dof
  // (dof = residuals - unknowns). NaN without redundancy. The covariance above is scaled by s^2.
  double pixel_noise_estimate_px = NAN;
  int residual_dof = 0;                       // that dof (0 without redundancy)
  double initial_cost = 0, final_cost = 0;    // Ceres cost of the first and the final solve
  int iterations = 0;                         // over every solve
  std::string termination;                    // of the final solve
  double seconds = 0;
};

// Runs the bundle adjustment on the identification poses of `observations`. The start: rho_start on the
// model observations.robot (e.g. the nominal rho, or the paper pipeline's result via ExpressOnModel) and
// fx_start; the other intrinsics start at observations.camera's; the dots are triangulated from the start model
// (identification/triangulation.h). Single-threaded and deterministic.
BundleReport RunBundleAdjustment(const ObservationSet& observations, const Eigen::VectorXd& rho_start,
                                 double fx_start, const BundleOptions& options);

// rho indices named by `names` (see BundleOptions::held_parameters; intrinsics and their groups are set
// true in *intrinsics, when given, and not returned). Returns the unknown names, one per line with the
// valid forms, or empty.
std::string ResolveParameterNames(const std::vector<std::string>& names, int num_joints, std::vector<int>* indices,
                                  IntrinsicsMask* intrinsics = nullptr);

// The intrinsics a bundle with these options estimates: options.intrinsics after the names of
// held_parameters and free_parameters (unknown names are ignored here; RunBundleAdjustment refuses them).
IntrinsicsMask EstimatedIntrinsicsOf(const BundleOptions& options, int num_joints);

// The rho indices a bundle with these options holds by request: those named in held_parameters, and
// with a free_parameters list every index it does not name, ascending. Unknown names are ignored, or
// listed in *unknown (ResolveParameterNames' words) when given.
std::vector<int> HeldParameterIndices(const BundleOptions& options, int num_joints, std::string* unknown = nullptr);

// The rho on `target` (same joint count) that gives the same base_from_cam(q) for every q as `source_rho`
// on `source`: joint parameters copied, base and camera corrections re-expressed against target's
// constant transforms (exact). E.g. the paper pipeline's metric calibrated model on the nominal model.
// Eye-to-hand (target.mount) the camera correction is re-expressed against target's base_from_cam; a
// different link_n_from_flange then moves the flange frame, which the points absorb.
Eigen::VectorXd ExpressOnModel(const RobotModel& target, const RobotModel& source, const Eigen::VectorXd& source_rho);

// The truth (or any point) of the bundle problem, for the bound.
struct BundleTruth {
  Eigen::VectorXd rho;                          // on observations.robot
  CameraIntrinsics camera;                      // every intrinsic (the image size is the geometry's)
  std::map<int, Eigen::Vector3d> dots_in_base;  // at least every dot seen twice in identification poses
};

struct CramerRaoReport {
  bool ok = false;
  std::string message;
  std::vector<int> free_indices;  // as the solve would choose them at this point
  std::vector<std::string> fixed_names;
  // (J_g^T (I - P_dots) J_g)^-1 with pixel std sigma_px, the yardstick as in the solve; order as in
  // BundleReport::covariance_free.
  Eigen::MatrixXd covariance_free;
  Eigen::VectorXd stddev;         // rho size, NaN for fixed
  double fx_stddev = 0;           // = intrinsics_stddev[kFx]
  IntrinsicsVector intrinsics_stddev{};  // NaN for held
  // Propagated to the predicted relative pose cam_ref_from_cam_v (ref = first identification pose) of
  // every verification pose: RMS position error bound sqrt(trace cov_t) (m) and orientation bound
  // sqrt(trace cov_w) (rad, small-angle vector).
  std::vector<std::string> verification_pose_ids;
  std::vector<double> position_bound_m, orientation_bound_rad;
  double rms_position_bound_m = 0, rms_orientation_bound_rad = 0;
};

// Cramer-Rao bound of the bundle adjustment's free parameters at `truth`: the Fisher information of the
// reprojection model with the dots marginalised (Schur complement), the gauge fixed as in the solve (free
// set chosen at the nominal model), the yardstick as the same stiff length residual, pixel std sigma_px
// per coordinate. `geometry` supplies
// the robot, camera, yardsticks, joint angles and which dots each identification pose sees (the pixel
// values are not used).
CramerRaoReport BundleCramerRao(const ObservationSet& geometry, const BundleTruth& truth, double sigma_px,
                                const BundleOptions& options);

}  // namespace selfcal::bundle
