// Internal to the identification module: the relative-pose residual shared by the identifiability
// Jacobian and the Ceres cost, templated so that Jets flow through it.
//
//   cam_ref_from_cam_i(rho) = base_from_cam(q_ref; rho)^-1 * base_from_cam(q_i; rho)
//   r = [ log(R_model^T R_meas) / sigma_rotation ; (t_model - t_meas) / sigma_position ]
#pragma once

#include <vector>

#include <Eigen/Core>
#include <ceres/rotation.h>

#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"

namespace selfcal::identification::internal {

template <typename T>
Eigen::Matrix<T, Eigen::Dynamic, 1> JointsAs(const Eigen::VectorXd& q) {
  return q.cast<T>();
}

// cam_ref_from_base at rho (the inverse of the reference camera pose in the points' frame: PointsFromCam,
// the base in eye-in-hand, the flange in eye-to-hand).
template <typename T>
Rigid3T<T> CamRefFromBase(const RobotModel& model, const T* rho, const Eigen::VectorXd& q_ref) {
  const auto q = JointsAs<T>(q_ref);
  return PointsFromCam<T>(model, rho, q.data()).Inverse();
}

// Writes 6 residuals (3 when !translation_valid: rotation only) of a predicted cam_ref_from_cam_i.
template <typename T>
void RelativePoseResidual(const Rigid3T<T>& predicted, const Rigid3& measured, bool translation_valid,
                          double inv_sigma_position, double inv_sigma_rotation, T* out) {
  // Column-major, as ceres::RotationMatrixToAngleAxis expects; its quaternion route has a Jet-safe
  // branch at the identity, where the residual sits at the solution.
  const Mat3T<T> error = predicted.rotation.transpose() * measured.rotation.cast<T>();
  T angle_axis[3];
  ceres::RotationMatrixToAngleAxis(error.data(), angle_axis);
  for (int k = 0; k < 3; ++k) out[k] = angle_axis[k] * inv_sigma_rotation;
  if (translation_valid) {
    for (int k = 0; k < 3; ++k) out[3 + k] = (predicted.translation[k] - measured.translation[k]) * inv_sigma_position;
  }
}

template <typename T>
void RelativePoseResidual(const RobotModel& model, const T* rho, const Rigid3T<T>& cam_ref_from_base,
                          const Eigen::VectorXd& q_i, const Rigid3& measured, bool translation_valid,
                          double inv_sigma_position, double inv_sigma_rotation, T* out) {
  const auto q = JointsAs<T>(q_i);
  RelativePoseResidual<T>(cam_ref_from_base * PointsFromCam<T>(model, rho, q.data()), measured, translation_valid,
                          inv_sigma_position, inv_sigma_rotation, out);
}

// The same residual for the solver, in double with its Jacobian: the forward kinematics are
// differentiated factor by factor (each link transform through Jets, combined with its double prefix and
// suffix), the residual head through Jets, so one evaluation costs about two plain forward passes
// instead of one Jet pass per chunk of parameters. Writes num_residuals (6, or 3 when
// !translation_valid) values; when jacobian != nullptr, the row-major num_residuals x num_parameters
// derivative, zero outside `columns`. Returns false if anything is non-finite.
bool EvaluateRelativePoseResidual(const RobotModel& model, const double* rho, const Eigen::VectorXd& q_ref,
                                  const Eigen::VectorXd& q_i, const Rigid3& measured, bool translation_valid,
                                  double inv_sigma_position, double inv_sigma_rotation, const std::vector<int>& columns,
                                  double* residuals, double* jacobian);

}  // namespace selfcal::identification::internal
