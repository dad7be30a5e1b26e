// The hand-eye bundle adjustment of a flange-pose set when the controller's flange poses are not exact:
// each recorded pose gets a correction with a Gaussian prior of the stated noise,
//
//   base_from_cam_i = base_from_flange_i * Exp(delta_i) * flange_from_cam,   delta_i ~ N(0, diag(s_t, s_r)),
//
// (eye-to-hand, observations.robot.mount: the fixed camera base_from_cam is the hand-eye transform and the
// points live in the flange frame, points_from_cam_i = (base_from_flange_i * Exp(delta_i))^-1 * base_from_cam)
//
// and the hand-eye transform, the intrinsics asked for (f_x by default), the dots and every delta_i are
// estimated together
// (autodiff, Huber while outliers are screened at 4 robust sigmas, then plain least squares). Started
// from the exact-pose solution (bundle_adjustment.h on the same set). The prior fixes the gauge and the
// scale: the scene's size comes from the flange translations, weighted by their stated noise, and from
// the set's yardsticks when it has any.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "geometry/rigid3.h"
#include "observations/observation_set.h"

namespace selfcal::bundle {

struct PoseNoiseOptions {
  double translation_sigma_m = 0;  // per axis, of each recorded flange pose
  double rotation_sigma_rad = 0;   // per axis (rotation vector)
  IntrinsicsMask intrinsics = kFocalLengthOnly;  // estimated; the others held at observations.camera's
  double huber_px = 2.0;
  // Std of a yardstick's length (observations.yardsticks with both ends among the dots: length
  // constraints beside the flange translations; the caller leaves none when the flanges alone scale).
  double yardstick_sigma_m = 1e-6;
  double screen_sigma = 4.0;
  int max_iterations = 200;
};

struct PoseNoiseReport {
  bool ok = false;
  std::string message;
  // The hand-eye transform: flange_from_cam (eye-in-hand), or the fixed camera base_from_cam (eye-to-hand;
  // flange_from_cam is then the identity).
  Rigid3 flange_from_cam;
  Rigid3 base_from_cam;
  IntrinsicsVector intrinsics{};  // every intrinsic, held ones at the start
  // Standard deviations of a correction hand_eye * Exp(c) (translation m, rotation vector rad, camera
  // frame) and of the intrinsics, scaled by the residual variance; NaN when unavailable or held.
  Eigen::Matrix<double, 6, 1> stddev = Eigen::Matrix<double, 6, 1>::Constant(NAN);
  IntrinsicsVector intrinsics_stddev = {NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN};
  IntrinsicsMask intrinsics_estimated{};  // options.intrinsics
  // The covariance of [c (6: translation m, rotation vector rad), the estimated intrinsics in camera/camera.h's
  // order] at the stated noises (pixel, flange pose), not scaled by variance_factor: what a prediction at those
  // noises uses (calibration/heldout_reprojection.h); empty when unavailable. variance_factor: the residuals'
  // sum of squares over their degrees of freedom (stddev above = sqrt(variance_factor * diagonal)).
  Eigen::MatrixXd covariance;
  double variance_factor = NAN;
  // The solved dots, in the points' frame (the base eye-in-hand, the flange eye-to-hand): those seen by two
  // identification poses at least.
  std::map<int, Eigen::Vector3d> dots;
  std::vector<std::string> pose_ids;                  // identification poses, in order
  std::vector<Eigen::Matrix<double, 6, 1>> corrections;  // delta_i per pose (translation m, rotation vector rad)
  std::vector<double> correction_translation_m;       // |delta_i| translation per pose
  std::vector<double> correction_rotation_rad;        // |delta_i| rotation per pose
  int num_observations = 0, num_removed = 0;
  std::vector<std::pair<std::string, int>> removed;   // (pose id, dot id) the screen left out
  std::vector<double> yardstick_lengths_m;            // the solved lengths of the yardsticks constrained
  double rms_reprojection_px = 0;
};

// The intrinsics start at observations.camera's; hand_eye_start: flange_from_cam, or base_from_cam eye-to-hand.
PoseNoiseReport RunPoseNoiseBundle(const ObservationSet& observations, const Rigid3& hand_eye_start,
                                   const std::map<int, Eigen::Vector3d>& dots_start, const PoseNoiseOptions& options);

}  // namespace selfcal::bundle
