// The cost of eq. (13) for RefineEpipolar, twice: EpipolarCost, a templated functor (the definition; used
// with automatic differentiation in the tests as the reference), and AnalyticEpipolarCost, the same
// residuals with a hand-written Jacobian in double, which is what the refinement uses. Private to the
// twoview module and its tests.
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <ceres/cost_function.h>

#include "geometry/rigid3.h"
#include "twoview/two_view_internal.h"

namespace selfcal::twoview::internal {

// Residuals of all correspondences in one block: for each, the signed distance (px) of m' to the
// epipolar line Q m and of m to Q^T m', Q = A^-T [t]x R A^-1 in centred coordinates. Their squared sum is
// the summand of eq. (12), which with Q written out is eq. (13). Distances are converted to raw pixels
// through mu so that the cost means the same for anisotropic pixels.
//
// One block rather than one per correspondence: R and E depend on the parameters only, and computing
// them once per evaluation instead of once per point makes the Jacobian several times cheaper. The Huber
// loss (D8: it bounds the pull of an outlier that slipped under the RANSAC gate) is therefore applied
// inside, by scaling each correspondence's pair of residuals so that their squared sum is rho(s): the
// cost, hence the minimiser, is that of a per-correspondence ceres::HuberLoss, and inside the quadratic
// zone, where Gaussian inliers sit, it is plain least squares.
//
// Parameter blocks: 1/f_x (1), the quaternion in Eigen's coefficient order x, y, z, w (4; used as is,
// not normalised, through Eigen's toRotationMatrix), t (3).
class EpipolarCost {
 public:
  EpipolarCost(const Correspondences& data, const std::vector<int>& indices, double mu, double huber_px)
      : mu_(mu), huber_(huber_px) {
    for (int i : indices) {
      m1_.push_back(data.centred1[i]);
      m2_.push_back(data.centred2[i]);
    }
  }
  int num_residuals() const { return 2 * static_cast<int>(m1_.size()); }

  template <typename T>
  bool operator()(const T* inverse_focal, const T* quaternion, const T* translation, T* residuals) const {
    using std::sqrt;
    const T& s = inverse_focal[0];  // 1 / f_x
    const Eigen::Map<const Eigen::Quaternion<T>> q(quaternion);
    const Mat3T<T> e = Skew<T>(Vec3T<T>(translation[0], translation[1], translation[2])) * q.toRotationMatrix();
    const T inv_mu_sq(1.0 / (mu_ * mu_));
    const T huber_sq(huber_ * huber_);
    for (size_t k = 0; k < m1_.size(); ++k) {
      const Vec3T<T> x1(T(m1_[k].x()) * s, T(m1_[k].y()) * s, T(1));  // A^-1 m
      const Vec3T<T> x2(T(m2_[k].x()) * s, T(m2_[k].y()) * s, T(1));
      const Vec3T<T> ex1 = e * x1;
      const Vec3T<T> etx2 = e.transpose() * x2;
      const T algebraic = x2.dot(ex1);  // m'^T Q m
      // Q m = A^-T E x1 = (s ex1_0, s ex1_1, ex1_2); as a line in pixels its first two coefficients are
      // (s ex1_0, s ex1_1 / mu). Likewise for Q^T m'.
      const T line2_sq = s * s * (ex1(0) * ex1(0) + inv_mu_sq * ex1(1) * ex1(1));
      const T line1_sq = s * s * (etx2(0) * etx2(0) + inv_mu_sq * etx2(1) * etx2(1));
      if (!(line2_sq > T(0)) || !(line1_sq > T(0))) return false;  // a point on an epipole: no line
      T r2 = algebraic / sqrt(line2_sq);
      T r1 = algebraic / sqrt(line1_sq);
      const T sum_sq = r1 * r1 + r2 * r2;
      if (sum_sq > huber_sq) {
        // rho(s) = 2 a sqrt(s) - a^2 beyond the quadratic zone; scale so that r1^2 + r2^2 = rho(s).
        const T scale = sqrt((T(2 * huber_) * sqrt(sum_sq) - huber_sq) / sum_sq);
        r1 *= scale;
        r2 *= scale;
      }
      residuals[2 * k] = r2;
      residuals[2 * k + 1] = r1;
    }
    return true;
  }

 private:
  std::vector<Eigen::Vector2d> m1_, m2_;
  double mu_, huber_;
};

// EpipolarCost's residuals with their derivatives written out (chain rule through E = [t]x R(q), the
// two line norms and the Huber scale). Autodiff with 8-wide Jets spent ~0.7 G instructions of a 2000-dot
// calibration here; the analytic Jacobian agrees with it to round-off (epipolar_cost_test.cc).
class AnalyticEpipolarCost : public ceres::CostFunction {
 public:
  AnalyticEpipolarCost(const Correspondences& data, const std::vector<int>& indices, double mu, double huber_px);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  std::vector<Eigen::Vector2d> m1_, m2_;
  double mu_, huber_;
};

}  // namespace selfcal::twoview::internal
