// The error model of a real cell, estimated from the bundle's own residuals (issue 35, item 1).
//
// Beside the detection noise (sigma_px per coordinate, independent), every image carries a pose error:
// its camera is where the model puts it only up to a small motion e_i = (v_i, omega_i) in the camera's own
// frame (the joint readings' noise and what the kinematic model does not hold, for a joint set; the
// controller's pose error, for a flange set), the same for all the image's dots:
//
//   pixel_ij = project(Exp(e_i) * cam_i_from_base(rho) * p_j) + n_ij,   n_ij ~ N(0, sigma_px^2 I),
//   v_i ~ N(0, s_t^2 I),   omega_i ~ N(0, s_r^2 I).
//
// The three variances are variance components, estimated by Foerstner's iteration (Koch, "Parameter
// estimation and hypothesis testing in linear models", 3.6): with the e_i as unknowns under the prior
// above, each component's new variance is its residuals' sum of squares over its redundancy number,
// r_k = n_k - tr(N^-1 N_k), until they settle; a pose component whose redundancy stays below one is taken as
// absent (zero). The dots are eliminated (bundle_problem.h's reduced
// Jacobian with the pose columns), so the iteration works on a matrix of (globals + 6 x poses) squared.
// Linearised at the bundle's solution: the pixel-only least-squares estimate, which stays the estimate
// (in simulation without pose error the components vanish and nothing changes).
//
// Its covariance under the model (the "sandwich"): with S = J_g^T (I - P_dots) J_g and
// S_ge = J_g^T (I - P_dots) J_e (whitened by the stated noise),
//
//   Cov(g) = S^-1 (s_px^2 S + S_ge Theta S_eg) S^-1,   Theta = diag(s_t^2 I, s_r^2 I) per pose,
//
// s_px the estimated pixel noise over the stated one. A pose error moves every dot of an image
// together, so n dots of one image are not n independent measurements: the pixel-only covariance was
// 3-50 times too small on real recordings.
//
// A joint set's images carry a third component beside the two isotropic ones: the joint readings' noise,
// dq_i ~ N(0, s_q^2 I) per image, which moves the camera by A_i dq_i (kinematics/joint_motion.h,
// CameraMotionPerJoint). Its shape changes with the configuration (a reading error of the first joint moves
// a camera far from the base by much more than one of the last), which the isotropic camera-frame
// components cannot take: it enters as n more unknowns per image, columns J_e A_i, under the same iteration,
// and Theta_i = diag(s_t^2 I, s_r^2 I) + s_q^2 A_i A_i^T.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace selfcal::bundle {

struct ErrorModel {
  bool estimated = false;
  std::string message;                 // why not, when not estimated
  double pixel_px = NAN;               // per coordinate
  double pose_translation_m = NAN;     // per axis, camera frame, per image
  double pose_rotation_rad = NAN;      // per axis (rotation vector)
  double joint_rad = NAN;              // per joint reading (a joint set's; NaN: not modelled)
  // Redundancy numbers (the degrees of freedom each component's estimate rests on).
  double pixel_redundancy = NAN, translation_redundancy = NAN, rotation_redundancy = NAN, joint_redundancy = NAN;
  // How precisely the data give the variances: the covariance of the estimated variances, each relative to
  // its value, over (pixel, translation, rotation, joint), zero rows and columns for an absent or unmodelled
  // component (Koch 3.6: D(sigma^2) = 2 S^-1, S_kl = tr(W V_k W V_l), at the estimate). A component's
  // redundancy alone promises 2 / r_k on the diagonal; the components share residuals (a reading error of
  // the last joints and the pixel noise look alike in a few images), so the joint estimate is less precise.
  Eigen::Matrix4d relative_covariance = Eigen::Matrix4d::Zero();
  int iterations = 0;
};

// The parameters held by request (--fix) tested against the data: the score test. At the solution the
// cost's gradient with respect to a held parameter, s = J_h^T r, is zero on average when its value is right;
// its covariance under the error model, with the free parameters and the dots projected out, is
// s_px^2 S_hh + S_he Theta S_eh, and T = s^T Cov(s)^-1 s is chi-square with as many degrees of freedom as held
// parameters the data can see (the others, e.g. the gauge's, are left out). A held value the images
// disagree with shows here long before it shows in the pose error it leaves behind.
struct HeldValueTest {
  bool tested = false;
  std::vector<std::string> names;  // the held parameters the data can see
  int dof = 0;
  double chi_square = NAN;
  std::string largest;  // the parameter whose own score is the largest, in words
  // False when the request trusts a whole model (`kinematics`, or a free list holding everything else): the
  // hand-eye-only solve takes the arm's model as it is, its errors part of each image's pose error.
  bool decisive = true;
};

// Theta_i above: the covariance of one image's camera motion e = (v, omega) given the components' sizes
// (non-positive or NaN: absent) and, for a joint set, the image's CameraMotionPerJoint (6 x n; empty: none).
Eigen::Matrix<double, 6, 6> PoseErrorCovariance(double translation_m, double rotation_rad, double joint_rad,
                                                const Eigen::MatrixXd& camera_motion_per_joint);

namespace internal {

// reduced: the reduced Jacobian with the pose columns (bundle_problem.h, whitened by sigma_px: the
// stated noise), num_global columns of globals first; gradient, residual_sq: its PoseErrorColumns; dof:
// residuals (pixel coordinates and yardsticks) minus unknowns (globals and dots).
// global_gradient (optional): J^T r of the global columns, for columns that are not at their optimum (held
// ones taken as free: the error model of the fit with them freed, one linear step away).
// joint_motion: a joint set's CameraMotionPerJoint per pose (the joint component); empty: none.
ErrorModel EstimateErrorModel(const Eigen::MatrixXd& reduced, int num_global, const Eigen::VectorXd& gradient,
                              double residual_sq, int dof, double sigma_px,
                              const Eigen::VectorXd& global_gradient = Eigen::VectorXd(),
                              const std::vector<Eigen::MatrixXd>& joint_motion = {});

// The globals' covariance under `model` (above), given inverse = S^-1 of the globals' reduced matrix
// (CovarianceFromJacobian of reduced's first num_global columns); *pose_part: its pose-error term.
Eigen::MatrixXd ModelCovariance(const Eigen::MatrixXd& reduced, int num_global, const Eigen::MatrixXd& inverse,
                                const ErrorModel& model, double sigma_px, Eigen::MatrixXd* pose_part,
                                const std::vector<Eigen::MatrixXd>& joint_motion = {});

// reduced: the reduced Jacobian with pose columns over [free globals (num_free) | held (num_held)]; names:
// the held columns'; gradient, norm_sq: J^T r and the squared norms (before the dots' elimination) of the held
// columns; pixel_variance: the pixel variance in units of the stated noise's square (used when no pose error
// was estimated).
HeldValueTest TestHeldValues(const Eigen::MatrixXd& reduced, int num_free, const std::vector<std::string>& names,
                             const Eigen::VectorXd& gradient, const Eigen::VectorXd& norm_sq, const ErrorModel& model,
                             double sigma_px, double pixel_variance,
                             const std::vector<Eigen::MatrixXd>& joint_motion = {});

}  // namespace internal
}  // namespace selfcal::bundle
