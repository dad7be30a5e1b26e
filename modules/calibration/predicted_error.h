// Predicted 3-D error of the held-out check distances (issue 3, items 2 and 3).
//
// The check of section 4.1 step 5 (VerifyDistances, paper_pipeline.h) triangulates both ends of a known
// distance from the verification poses with a model (rho on `robot`) and f_x and compares their distance
// d with the known length. To first order its error has two independent sources:
//   (a) the calibrated parameters theta = (free entries of rho, f_x), with covariance Sigma (e.g. the
//       bundle adjustment's covariance_free, or its Cramer-Rao covariance at the truth), and
//   (b) the pixel noise of the verification images (sigma_px per coordinate, independent of theta: the
//       verification poses do not enter the calibration),
// so that
//
//   var(d) = g_theta^T Sigma g_theta + sigma_px^2 |g_px|^2,
//
// g_theta = dd/dtheta and g_px = dd/d(pixels of both ends in every verification view that sees them).
// Both ends are triangulated exactly as VerifyDistances does (identification/triangulation.h, Gauss-Newton
// to convergence); the gradients are then analytic at that point. The point minimises its reprojection
// error E(X; theta, pixels), i.e. solves dE/dX = 0, so by the implicit function theorem
//   dX/dq = -H^-1 d(J_X^T r)/dq,   H = J_X^T J_X + sum_i r_i d2r_i/dX2 (the exact Hessian),
// with J_X, J_theta the analytic Jacobians of the reprojections (the camera poses' derivatives with respect
// to rho by forward-mode autodiff through the kinematics), and dd/dX = +-(a - b)^T / d. Cost
// O(distances x views x parameters): linear in the number of views (the central differences of the full
// triangulation used before were O(distances x views^3)); the two agree to below 1e-6 relative
// (predicted_error_test.cc, docs/performance.md).
//
// Frames and units: rho in m and rad on `robot` (robot_model.h); f_x and sigma_px in px; results in m.
// The camera (lens included) is observations.camera with fx_px replaced by `fx_px`; the other intrinsics are
// not propagated (a covariance with more than free + 1 rows is used through its top-left block).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "kinematics/robot_model.h"
#include "observations/observation_set.h"

namespace selfcal::calibration {

struct PredictedDistanceError {
  KnownDistance known;
  bool ok = false;           // both ends triangulated (and apart)
  double measured_m = 0;     // triangulated distance at the given model
  double std_m = 0;          // sqrt(parameters_std_m^2 + pixels_std_m^2)
  double parameters_std_m = 0;   // part (a): sqrt(g_theta^T Sigma g_theta)
  double pixels_std_m = 0;       // part (b): sigma_px |g_px|
  Eigen::VectorXd gradient_theta;  // m per unit: free entries of rho in free_indices order, then f_x (m/px)
  Eigen::VectorXd gradient_px;     // m/px: end a's views (u, v each), then end b's
};

struct PredictedDistanceErrors {
  bool ok = false;
  std::string message;
  std::vector<PredictedDistanceError> distances;  // in the order given
  int num_ok = 0;
  // Quadratic means over the distances that are ok: the predicted RMS 3-D error and its two parts.
  double rms_std_m = 0, rms_parameters_std_m = 0, rms_pixels_std_m = 0;
};

PredictedDistanceErrors PredictDistanceErrors(const ObservationSet& observations, const std::vector<int>& pose_indices,
                                              const RobotModel& robot, const Eigen::VectorXd& rho, double fx_px,
                                              const std::vector<int>& free_indices,
                                              const Eigen::MatrixXd& covariance_free_plus_fx, double sigma_px,
                                              const std::vector<KnownDistance>& distances);

}  // namespace selfcal::calibration
