// Module twoview (ARCHITECTURE.md): the factor method (this header: 8-point, f_x from Q (Bougnoux),
// Theorem 1 factorisation + cheirality, RANSAC, the homography path with the plane of both solutions, LM on
// eq. (13) with Ceres manifolds; epipolar_cost.h writes the Jacobian out, its autodiff functor kept as the
// test reference); an OpenCV reference; the two-view Cramer-Rao bound; planar_views.h: every view of one flat
// target from a reference view at once, the shared plane normal resolving each view's two-fold ambiguity and
// fixing f_x (three or more views), translations in one scale. Uses camera, geometry, base; Ceres, OpenCV
// private.
//
// Two-view relative pose with an unknown focal length: the paper's refined nonlinear factor method
// (section 3.1, eq. (8)-(13)), made robust (RANSAC, planar scenes, cheirality, degeneracy outcomes).
//
// Convention (eq. (9)): P1 = A [I | 0], P2 = A [R | t], i.e. (R, t) is cam2_from_cam1:
//   p_in_cam2 = R * p_in_cam1 + t.
// Only the direction of t is observable; ||translation_direction|| = 1.
// Intrinsics follow eq. (8): principal point (cx, cy) and mu = fy/fx known, skew zero; f_x is the
// unknown when options.estimate_focal is true (camera.fx_px is then only the prior used when f_x is
// unobservable from this pair).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "geometry/rigid3.h"

namespace selfcal::twoview {

// ../shared/RELIABILITY.md G1-G10.
enum class Outcome {
  kNotRun,
  kSuccess,
  kInvalidInput,       // size mismatch, non-finite pixel (D7)
  kTooFewPoints,       // G1: fewer than options.min_points correspondences (or inliers)
  kDegenerate,         // rank-deficient design (collinear points, identical images, ...)
  kPureRotation,       // G3: R valid, translation unobservable (translation_observable = false)
  kLowDepthVariation,  // G6: most points farther than 50 baselines: translation direction unreliable
  kAmbiguousPose,      // G5: no clear cheirality winner
  kTooManyOutliers,    // G7: inlier ratio below the floor
  kNoConvergence,      // G9: refinement failed; the linear estimate is kept and flagged
};
const char* OutcomeName(Outcome outcome);

struct TwoViewOptions {
  bool estimate_focal = true;          // paper: f_x unknown, estimated per pair
  bool refine = true;                  // LM on eq. (13) after the linear factor method
  double ransac_threshold_px = 1.0;    // on the Sampson distance, in pixels
  double ransac_confidence = 0.999;
  int ransac_max_iterations = 2000;    // cap on the adaptive count (G7, G8)
  int min_points = 8;                  // G1
  double min_inlier_ratio = 0.3;       // G7
  double planar_homography_ratio = 0.45;  // G4: R_H = S_H / (S_H + S_F) above this -> homography path
  double min_parallax_deg = 1.0;       // G3: median parallax below this -> pure rotation
  // G3: a rotation alone explains a pair when its median transfer residual is within the homography
  // gate and at most max_rotation_excess times a general homography's on the same inliers plus
  // rotation_excess_floor_px (noise alone: a ratio near 1; a real translation, even one a rotation
  // mostly absorbs, leaves the rotation well above the homography). Measured on the real ROS dot grid
  // (test/cross_module/two_view_real_dotgrid_test.cc): no pure-rotation verdict on its 104 pairs whose
  // wrist moved 2 cm or more, where the noise gate alone gave 3.
  double max_rotation_excess = 1.5;
  double rotation_excess_floor_px = 0.1;
  // G6: fraction of inliers triangulated farther than 50 baselines above this -> kLowDepthVariation.
  // A point that far has a triangulation angle below 1/50 rad (1.15 deg), so with the default
  // min_parallax_deg the G3 test, which is checked first, usually catches such a pair already; this
  // one matters when min_parallax_deg is lowered.
  double max_far_point_fraction = 0.5;
  double focal_observability_min = 0.05;  // see FocalFromFundamental
  int max_refine_iterations = 100;
  uint64_t seed = 1;                   // RANSAC sampling (P9: deterministic)

  // Empty when valid; every problem otherwise, one per line.
  std::string Validate() const;
};

struct TwoViewReport {
  Outcome outcome = Outcome::kNotRun;
  std::string message;  // why, in words

  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();       // R of cam2_from_cam1
  Eigen::Vector3d translation_direction = Eigen::Vector3d::Zero();  // unit t of cam2_from_cam1
  bool translation_observable = false;
  // kAmbiguousPose: the strongest rival the cheirality test could not rule out (for a flat scene the
  // other of the homography's two solutions), so that a caller with other evidence (the robot's motion,
  // more views) can choose; cam2_from_cam1 as above, unit translation.
  bool has_rival = false;
  Eigen::Matrix3d rival_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d rival_translation_direction = Eigen::Vector3d::Zero();
  // The homography path (planar): the plane of the chosen solution and of the rival, a unit normal in
  // cam1 towards the points' side. The normal is one vector for every view of the same plane, so a caller
  // with several views can resolve the ambiguity (planar_views.h does so for a whole set).
  bool has_plane = false, has_rival_plane = false;
  Eigen::Vector3d plane_normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d rival_plane_normal = Eigen::Vector3d::Zero();

  double fx_px = 0;              // final f_x (estimated, or the prior when !fx_observable)
  bool fx_observable = false;    // false when the optical axes (nearly) intersect, or f_x was given
  double fx_linear_px = 0;       // from the fundamental matrix, before refinement (0 if unobservable)

  bool planar = false;           // the homography path was taken (G4)
  double homography_ratio = 0;   // R_H
  std::vector<bool> inliers;     // per correspondence
  int num_inliers = 0;
  double rms_epipolar_px = -1;   // RMS of the symmetric epipolar distance (eq. 12) over inliers, final

  bool refinement_accepted = false;  // G9: only if cost decreased and result finite
  std::string refinement_termination;
  int refinement_iterations = 0;

  // G6: fraction of the final inliers that triangulate farther than 50 baselines (|t| = 1) along either
  // camera's axis, on either side (a far point's depth sign is noise): OpenCV recoverPose's
  // distanceThresh rule. Computed whenever a full pose was estimated (kSuccess, kNoConvergence,
  // kPureRotation by the parallax test, kLowDepthVariation); 0 otherwise.
  double far_point_fraction = 0;

  // G10: diagnostics that do not change the outcome, one sentence each:
  //  - "inlier ratio X: outliers or wrong intrinsics" when fewer than 80 % of the correspondences are
  //    final inliers (any outcome that got as far as choosing a model, except kTooManyOutliers);
  //  - "intrinsics/distortion suspect: residuals grow with radius (...)" when a radial distortion term
  //    k1 (camera.h's model) explains the signed epipolar residuals of the final model significantly
  //    better than f_x and the pose alone (a score test; statistic and thresholds in two_view.cc),
  //    checked whenever a full pose was estimated and >= 30 correspondences lie near the model.
  std::vector<std::string> warnings;

  Rigid3 cam2_from_cam1() const { return Rigid3(rotation, translation_direction); }
};

// Task-level estimator: validation, RANSAC on the normalised 8-point fundamental matrix (or homography
// for planar scenes), f_x from Q, factorisation (Theorem 1) with cheirality, LM refinement of eq. (13)
// over f_x, R (SO(3) manifold) and the direction of t (sphere manifold).
// pixels1[k] and pixels2[k] are the same dot (correspondence by index, already matched by id).
TwoViewReport EstimateTwoView(const TwoViewOptions& options, const CameraIntrinsics& camera,
                              const std::vector<Eigen::Vector2d>& pixels1,
                              const std::vector<Eigen::Vector2d>& pixels2);

// ---- Pure math building blocks (no policy) ------------------------------------------------------

// Hartley-normalised 8-point fundamental matrix from >= 8 correspondences (x2^T F x1 = 0), rank 2
// enforced. Coordinates are whatever the caller passes (pixels or centred pixels).
Eigen::Matrix3d EightPointFundamental(const std::vector<Eigen::Vector2d>& x1, const std::vector<Eigen::Vector2d>& x2);

// Focal length shared by both views from a fundamental matrix in centred coordinates (principal point at
// the origin, mu divided out), Bougnoux's formula. Returns false when f is unobservable: f^2 <= 0, or the
// relative observability measure (written to *observability when non-null, ~0 when the optical axes
// intersect) is below min_observability.
bool FocalFromFundamental(const Eigen::Matrix3d& f_centered, double min_observability, double* fx_px,
                          double* observability = nullptr);

// Theorem 1: the four (R, t) candidates of an essential matrix, t unit.
std::vector<Rigid3> FactorEssential(const Eigen::Matrix3d& essential);

// Linear triangulation of one point from normalised coordinates in two views (cam2_from_cam1 given);
// the point in cam1 coordinates.
Eigen::Vector3d TriangulateTwoView(const Rigid3& cam2_from_cam1, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2);

// Symmetric epipolar distance of eq. (12) for one correspondence, in the units of the coordinates.
double SymmetricEpipolarDistance(const Eigen::Matrix3d& f, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2);

// ---- Reference and bound -------------------------------------------------------------------------

// OpenCV's findEssentialMat (RANSAC, threshold options.ransac_threshold_px) + recoverPose with the
// true f_x (camera.fx_px): the comparison row of the study. Outcome kSuccess or a failure outcome.
// Should OpenCV return several stacked solutions (G2), each 3x3 candidate is scored by its own inliers
// in front of both cameras and one is chosen explicitly. Inliers are OpenCV's RANSAC inliers that are
// also within the threshold of the chosen E by our own Sampson distance (G8) and pass recoverPose's
// cheirality and 50-baseline test. far_point_fraction and warnings are not filled.
TwoViewReport EstimateTwoViewOpenCv(const TwoViewOptions& options, const CameraIntrinsics& camera,
                                    const std::vector<Eigen::Vector2d>& pixels1,
                                    const std::vector<Eigen::Vector2d>& pixels2);

// Cramer-Rao bound of the two-view reprojection model: unknowns R (3), direction of t (2), f_x (1 when
// fx_unknown) and every point (3 each); measurements both images' pixels with i.i.d. N(0, sigma_px^2)
// per coordinate. Points are marginalised (Schur complement).
struct TwoViewBound {
  bool ok = false;
  std::string message;
  Eigen::Matrix3d rotation_covariance;          // rad^2, of the rotation-vector error of R
  Eigen::Matrix3d translation_dir_covariance;   // of the unit direction (rank 2), rad^2
  double fx_variance = 0;                       // px^2 (0 when f_x known)
  double rotation_rms_rad() const;              // sqrt(trace)
  double translation_dir_rms_rad() const;       // sqrt(trace)
};
TwoViewBound TwoViewCramerRao(const CameraIntrinsics& camera, const Rigid3& cam2_from_cam1,
                              const std::vector<Eigen::Vector3d>& points_in_cam1, double sigma_px, bool fx_unknown);

}  // namespace selfcal::twoview
