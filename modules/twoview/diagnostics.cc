// Statistics the task-level estimator reports on its final estimate: the fraction of far points (G6)
// and a test for radial distortion in the epipolar residuals (G10). Policy (thresholds) lives in
// two_view.cc.
#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "twoview/two_view_internal.h"

namespace selfcal::twoview::internal {

double FarPointFraction(const Rigid3& cam2_from_cam1, const std::vector<Eigen::Vector2d>& n1,
                        const std::vector<Eigen::Vector2d>& n2, const std::vector<int>& indices) {
  if (indices.empty()) return 0;
  const Eigen::Matrix3d& r = cam2_from_cam1.rotation;
  const Eigen::Vector3d t = cam2_from_cam1.translation.normalized();
  const Eigen::Vector3d centre2 = -r.transpose() * t;  // camera 2's centre in camera 1
  int far = 0;
  for (int i : indices) {
    // Midpoint triangulation in closed form, in camera 1: lambda1 d1 = centre2 + lambda2 d2 in the least-
    // squares sense, with d1 = (n1, 1) and d2 = R^T (n2, 1), so that lambda1 and lambda2 are the depths in
    // the two cameras. Both are num / det; det = |d1 x d2|^2 vanishes for parallel rays, a point at
    // infinity. Compared without dividing so that det = 0 (and NaN) count as far. (OpenCV triangulates
    // by homogeneous DLT; the two differ at the noise level only, and this is ten times cheaper.)
    const Eigen::Vector3d d1(n1[i].x(), n1[i].y(), 1);
    const Eigen::Vector3d d2 = r.transpose() * Eigen::Vector3d(n2[i].x(), n2[i].y(), 1);
    const double d11 = d1.squaredNorm(), d22 = d2.squaredNorm(), d12 = d1.dot(d2);
    const double c1 = d1.dot(centre2), c2 = d2.dot(centre2);
    const double det = d11 * d22 - d12 * d12;
    const double depth1 = c1 * d22 - d12 * c2;
    const double depth2 = d12 * c1 - d11 * c2;
    const double limit = kFarDepthBaselines * det;
    if (!(std::abs(depth1) < limit) || !(std::abs(depth2) < limit)) ++far;
  }
  return static_cast<double>(far) / static_cast<double>(indices.size());
}

namespace {

// Parameters of the epipolar model plus a radial term: 1/f_x, R, the direction of t and k1.
struct RadialModel {
  double inverse_focal = 0;
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  double k1 = 0;
};

// Signed Sampson distance (raw px) of one correspondence: x2^T E x1 over the norm of its gradient
// with respect to the four raw pixel coordinates. The centred points are first undistorted to first
// order, c (1 - k1 r^2) with r^2 = |c|^2 / f^2 (the inverse of x_d = x (1 + k1 r^2) to that order).
double SignedSampsonPx(const RadialModel& m, double mu, const Eigen::Vector2d& c1, const Eigen::Vector2d& c2) {
  const double s = m.inverse_focal;
  const Eigen::Vector2d u1 = c1 * (1 - m.k1 * s * s * c1.squaredNorm());
  const Eigen::Vector2d u2 = c2 * (1 - m.k1 * s * s * c2.squaredNorm());
  const Eigen::Vector3d x1(s * u1.x(), s * u1.y(), 1), x2(s * u2.x(), s * u2.y(), 1);
  const Eigen::Matrix3d e = Skew<double>(m.translation) * m.rotation;
  const Eigen::Vector3d ex1 = e * x1, etx2 = e.transpose() * x2;
  const double inv_mu_sq = 1 / (mu * mu);
  const double gradient_sq =
      s * s * (ex1(0) * ex1(0) + inv_mu_sq * ex1(1) * ex1(1) + etx2(0) * etx2(0) + inv_mu_sq * etx2(1) * etx2(1));
  return x2.dot(ex1) / std::sqrt(gradient_sq);
}

}  // namespace

RadialDistortionScore ScoreRadialDistortion(const CameraIntrinsics& camera, double fx_px, const Rigid3& cam2_from_cam1,
                                            const Correspondences& data, const std::vector<int>& indices) {
  constexpr int kPoseParameters = 6;  // 1/f_x, rotation (3), direction of t (2)
  RadialDistortionScore score;
  score.n = static_cast<int>(indices.size());
  if (score.n <= kPoseParameters + 1) return score;
  RadialModel base;
  base.inverse_focal = 1 / fx_px;
  base.rotation = cam2_from_cam1.rotation;
  base.translation = cam2_from_cam1.translation.normalized();
  // Tangent basis of the direction of t.
  const Eigen::Vector3d b1 = base.translation.unitOrthogonal();
  const Eigen::Vector3d b2 = base.translation.cross(b1);

  auto residuals = [&](const RadialModel& m, Eigen::VectorXd* out) {
    out->resize(score.n);
    for (int k = 0; k < score.n; ++k) {
      const int i = indices[k];
      (*out)(k) = SignedSampsonPx(m, camera.mu, data.centred1[i], data.centred2[i]);
    }
  };
  Eigen::VectorXd e;
  residuals(base, &e);
  if (!e.allFinite()) return score;  // a point on an epipole

  // Central differences: the model is smooth and cheap, and 7 columns need 14 evaluations.
  auto perturbed = [&](int parameter, double step) {
    RadialModel m = base;
    if (parameter == 0) {
      m.inverse_focal *= 1 + step;  // relative: 1/f_x is ~1e-3
    } else if (parameter <= 3) {
      m.rotation = ExpSO3<double>(Eigen::Vector3d(step * Eigen::Vector3d::Unit(parameter - 1))) * m.rotation;
    } else if (parameter <= 5) {
      m.translation = (m.translation + step * (parameter == 4 ? b1 : b2)).normalized();
    } else {
      m.k1 = step;
    }
    return m;
  };
  constexpr double kStep = 1e-6;
  Eigen::MatrixXd pose_jacobian(score.n, kPoseParameters);
  Eigen::VectorXd plus, minus;
  for (int p = 0; p < kPoseParameters; ++p) {
    residuals(perturbed(p, kStep), &plus);
    residuals(perturbed(p, -kStep), &minus);
    const Eigen::VectorXd column = (plus - minus) / (2 * kStep);
    const double norm = column.norm();
    pose_jacobian.col(p) = norm > 0 ? Eigen::VectorXd(column / norm) : column;  // scaled for the rank test
  }
  residuals(perturbed(kPoseParameters, kStep), &plus);
  residuals(perturbed(kPoseParameters, -kStep), &minus);
  const Eigen::VectorXd k1_column = (plus - minus) / (2 * kStep);
  if (!pose_jacobian.allFinite() || !k1_column.allFinite() || !(k1_column.norm() > 0)) return score;

  // Remove from the k1 column and the residuals what f_x and the pose explain: the score test of k1 = 0
  // given the fitted pose, i.e. one Gauss-Newton step on k1 with the pose re-optimised alongside.
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(pose_jacobian);
  qr.setThreshold(1e-10);
  const int rank = static_cast<int>(qr.rank());
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(score.n, rank);  // thin
  const Eigen::VectorXd k1_free = k1_column - q * (q.transpose() * k1_column);
  const Eigen::VectorXd e_free = e - q * (q.transpose() * e);
  const double free_norm = k1_free.norm();
  // k1 indistinguishable from a change of f_x or pose: nothing to test.
  if (!(free_norm > 1e-6 * k1_column.norm())) return score;
  score.observable = true;
  const double projection = k1_free.dot(e_free) / free_norm;  // residual along the free k1 direction
  const int dof = score.n - rank - 1;
  const double sigma_sq = std::max(0.0, e_free.squaredNorm() - projection * projection) / dof;
  // To first order the residuals with k1 are e + k1_column * k1: least squares sets k1 so that the free
  // part cancels, and its standard error is sigma / |k1_free|.
  score.k1 = -projection / free_norm;
  score.z = sigma_sq > 0 ? -projection / std::sqrt(sigma_sq) : 0;
  double r_max_sq = 0;
  for (int i : indices) {
    r_max_sq = std::max({r_max_sq, data.centred1[i].squaredNorm(), data.centred2[i].squaredNorm()});
  }
  score.max_displacement_px = std::abs(score.k1) * std::pow(r_max_sq, 1.5) / (fx_px * fx_px);
  return score;
}

}  // namespace selfcal::twoview::internal
