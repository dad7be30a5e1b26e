// Cramer-Rao bound of the two-view reprojection model, the yardstick for the estimator's accuracy.
#include <cmath>
#include <sstream>

#include <Eigen/Dense>
#include <ceres/jet.h>

#include "twoview/two_view.h"

namespace selfcal::twoview {
namespace {

// Parameters of one point's measurement model, all perturbations around the truth:
//   0-2 rotation vector w (R = Exp(w) R0), 3-4 tangent coordinates of the direction of t,
//   5 delta f_x, 6-8 the point in cam1.
constexpr int kNumParams = 9;
using Jet = ceres::Jet<double, kNumParams>;

// Pixels of one point in both views (u1, v1, u2, v2) under the perturbed parameters.
template <typename T>
bool PredictPixels(const CameraIntrinsics& camera, const Rigid3& truth, const Eigen::Matrix<double, 3, 2>& tangent,
                   const Eigen::Vector3d& point, const T* x, T* pixels) {
  const Mat3T<T> r = ExpSO3<T>(Vec3T<T>(x[0], x[1], x[2])) * truth.rotation.cast<T>();
  // The norm of t is held at its true value: the gauge of the two-view scale.
  const double norm = truth.translation.norm();
  Vec3T<T> direction = truth.translation.cast<T>() / T(norm) + tangent.cast<T>() * Eigen::Matrix<T, 2, 1>(x[3], x[4]);
  direction /= direction.norm();
  const Vec3T<T> t = T(norm) * direction;
  const T fx = T(camera.fx_px) + x[5];
  const Vec3T<T> p1 = point.cast<T>() + Vec3T<T>(x[6], x[7], x[8]);
  const Vec3T<T> p2 = r * p1 + t;
  const T k1(camera.k1);
  return ProjectPoint<T>(camera, fx, k1, p1, &pixels[0], &pixels[1]) &&
         ProjectPoint<T>(camera, fx, k1, p2, &pixels[2], &pixels[3]);
}

}  // namespace

double TwoViewBound::rotation_rms_rad() const { return std::sqrt(rotation_covariance.trace()); }
double TwoViewBound::translation_dir_rms_rad() const { return std::sqrt(translation_dir_covariance.trace()); }

TwoViewBound TwoViewCramerRao(const CameraIntrinsics& camera, const Rigid3& cam2_from_cam1,
                              const std::vector<Eigen::Vector3d>& points_in_cam1, double sigma_px, bool fx_unknown) {
  TwoViewBound bound;
  bound.rotation_covariance.setZero();
  bound.translation_dir_covariance.setZero();
  const std::string camera_problems = camera.Validate();
  if (!camera_problems.empty()) {
    bound.message = "invalid camera:\n" + camera_problems;
    return bound;
  }
  if (!(sigma_px > 0) || !std::isfinite(sigma_px)) {
    bound.message = "sigma_px must be finite and > 0";
    return bound;
  }
  const double norm = cam2_from_cam1.translation.norm();
  if (!(norm > 0) || !cam2_from_cam1.translation.allFinite() || !cam2_from_cam1.rotation.allFinite()) {
    bound.message = "translation must be finite and non-zero: its direction is a parameter";
    return bound;
  }
  // Orthonormal basis of the plane orthogonal to t: the two directions in which t may turn.
  const Eigen::Vector3d direction = cam2_from_cam1.translation / norm;
  Eigen::Matrix<double, 3, 2> tangent;
  {
    const Eigen::Vector3d helper = std::abs(direction.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    tangent.col(0) = direction.cross(helper).normalized();
    tangent.col(1) = direction.cross(tangent.col(0));
  }

  // Schur complement of the points, point by point: the pose/focal block of the Fisher information with
  // every point marginalised (the points are nuisance parameters the estimator never sees).
  const int num_pose = fx_unknown ? 6 : 5;
  Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(num_pose, num_pose);
  for (size_t j = 0; j < points_in_cam1.size(); ++j) {
    Jet x[kNumParams], pixels[4];
    for (int k = 0; k < kNumParams; ++k) x[k] = Jet(0.0, k);
    if (!points_in_cam1[j].allFinite() ||
        !PredictPixels<Jet>(camera, cam2_from_cam1, tangent, points_in_cam1[j], x, pixels)) {
      std::ostringstream m;
      m << "point " << j << " is not in front of both cameras";
      bound.message = m.str();
      return bound;
    }
    Eigen::Matrix<double, 4, kNumParams> jacobian;
    for (int row = 0; row < 4; ++row) jacobian.row(row) = pixels[row].v.transpose();
    const Eigen::MatrixXd j_pose = jacobian.leftCols(num_pose);
    const Eigen::Matrix<double, 4, 3> j_point = jacobian.rightCols<3>();
    const Eigen::Matrix3d v = j_point.transpose() * j_point;
    const Eigen::MatrixXd w = j_pose.transpose() * j_point;
    Eigen::LDLT<Eigen::Matrix3d> v_ldlt(v);
    if (v_ldlt.info() != Eigen::Success || !(v_ldlt.vectorD().minCoeff() > 1e-12 * v.trace())) {
      std::ostringstream m;
      m << "point " << j << " has no parallax: its depth is not determined";
      bound.message = m.str();
      return bound;
    }
    reduced += j_pose.transpose() * j_pose - w * v_ldlt.solve(w.transpose());
  }
  reduced /= sigma_px * sigma_px;

  Eigen::JacobiSVD<Eigen::MatrixXd> svd(reduced, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd& s = svd.singularValues();
  if (!(s(num_pose - 1) > 1e-12 * s(0))) {
    bound.message = "Fisher information is singular: the pose (and focal) are not observable from these points";
    return bound;
  }
  const Eigen::MatrixXd covariance = svd.matrixV() * s.cwiseInverse().asDiagonal() * svd.matrixU().transpose();
  bound.rotation_covariance = covariance.topLeftCorner<3, 3>();
  bound.translation_dir_covariance = tangent * covariance.block<2, 2>(3, 3) * tangent.transpose();
  bound.fx_variance = fx_unknown ? covariance(5, 5) : 0;
  bound.ok = true;
  return bound;
}

}  // namespace selfcal::twoview
