#include "geometry/rigid3.h"

#include <algorithm>

#include <Eigen/SVD>

namespace selfcal {

double RotationAngle(const Eigen::Matrix3d& r) {
  // atan2 of (|axis part|, cos part) stays accurate at both ends, unlike acos((tr-1)/2).
  const Eigen::Vector3d axis(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));
  return std::atan2(0.5 * axis.norm(), 0.5 * (r.trace() - 1.0));
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& r) {
  // Through the unit quaternion (Shepperd's method inside Eigen): accurate at both 0 and pi, where the
  // antisymmetric part of r vanishes.
  Eigen::Quaterniond q(r);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double vnorm = q.vec().norm();
  if (vnorm < 1e-300) return Eigen::Vector3d::Zero();
  const double angle = 2.0 * std::atan2(vnorm, q.w());
  return (angle / vnorm) * q.vec();
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

PoseDifference ComparePoses(const Rigid3& a, const Rigid3& b) {
  PoseDifference d;
  d.position_m = (a.translation - b.translation).norm();
  d.rotation_rad = RotationAngle(a.rotation.transpose() * b.rotation);
  return d;
}

}  // namespace selfcal
