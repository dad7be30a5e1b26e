// Levenberg-Marquardt on eq. (13) of the paper with Ceres: f_x (as 1/f_x), R on the quaternion manifold,
// the direction of t on the unit sphere.
#include <cmath>
#include <sstream>

#include <Eigen/Geometry>
#include <ceres/ceres.h>

#include "twoview/two_view_internal.h"

namespace selfcal::twoview::internal {
namespace {

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

const char* TerminationName(ceres::TerminationType type) {
  switch (type) {
    case ceres::CONVERGENCE:
      return "convergence";
    case ceres::NO_CONVERGENCE:
      return "no_convergence";
    case ceres::FAILURE:
      return "failure";
    case ceres::USER_SUCCESS:
      return "user_success";
    case ceres::USER_FAILURE:
      return "user_failure";
  }
  return "unknown";
}

}  // namespace

RefineResult RefineEpipolar(const CameraIntrinsics& camera, const Correspondences& data,
                            const std::vector<int>& indices, double fx_px, const Rigid3& cam2_from_cam1,
                            bool refine_focal, int max_iterations, double huber_px, double min_focal_px,
                            double max_focal_px) {
  RefineResult result;
  result.fx_px = fx_px;
  result.cam2_from_cam1 = cam2_from_cam1;

  // Unknown: 1/f_x rather than f_x. Normalised coordinates m / f_x are linear in it, which makes the
  // Gauss-Newton model of eq. (13) far more accurate along the focal direction (22 LM iterations from
  // the true pose at 0.5 px became 8).
  double inverse_focal = 1.0 / fx_px;
  Eigen::Quaterniond q(cam2_from_cam1.rotation);
  q.normalize();
  Eigen::Vector3d t = cam2_from_cam1.translation.normalized();

  ceres::Problem problem;
  auto* cost = new EpipolarCost(data, indices, camera.mu, huber_px);
  const int num_residuals = cost->num_residuals();
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<EpipolarCost, ceres::DYNAMIC, 1, 4, 3>(cost, num_residuals),
                           nullptr, &inverse_focal, q.coeffs().data(), t.data());
  problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
  // The scale of t is not observable from two views (eq. (11)): only its direction is estimated.
  problem.SetManifold(t.data(), new ceres::SphereManifold<3>);
  // No bound keeps f_x > 0: a bounded problem makes Ceres project every step with a line search that
  // evaluates the Jacobian twice per iteration; positivity is checked on the result instead (G9).
  if (!refine_focal) problem.SetParameterBlockConstant(&inverse_focal);

  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::DENSE_QR;  // 6 unknowns: dense and single-threaded is fastest
  options.num_threads = 1;
  options.max_num_iterations = max_iterations;
  // A relative cost change of 1e-12 leaves the parameters ~1e-6 of their noise from the optimum; exact
  // data start at the optimum anyway (the linear estimate is exact to ~1e-12 there).
  options.function_tolerance = 1e-12;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-12;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;

  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  result.termination = TerminationName(summary.termination_type);
  result.iterations =
      static_cast<int>(summary.iterations.size()) > 0 ? static_cast<int>(summary.iterations.size()) - 1 : 0;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;

  q.normalize();
  const double fx = 1.0 / inverse_focal;
  // As 1/f_x -> 0 the model tends to an affine camera, which outliers or a shallow scene can favour: a
  // focal outside the plausible band is a diverged refinement, not a measurement.
  const bool finite = std::isfinite(summary.final_cost) && std::isfinite(fx) && fx > min_focal_px &&
                      fx < max_focal_px && q.coeffs().allFinite() && t.allFinite() && std::abs(t.norm() - 1) < 1e-6;
  const bool solver_failed =
      summary.termination_type == ceres::FAILURE || summary.termination_type == ceres::USER_FAILURE;
  result.failed = solver_failed || !finite || summary.final_cost > summary.initial_cost;
  // G9: a result is used only if it is finite and strictly better; LM that cannot improve (an exact
  // start) is not a failure but is not "accepted" either.
  result.accepted = !result.failed && summary.final_cost < summary.initial_cost;
  if (result.accepted) {
    result.fx_px = fx;
    result.cam2_from_cam1 = Rigid3(q.toRotationMatrix(), t.normalized());
  }
  std::ostringstream detail;
  detail << result.termination << " after " << result.iterations << " iterations, cost " << summary.initial_cost
         << " -> " << summary.final_cost;
  result.detail = detail.str();
  return result;
}

}  // namespace selfcal::twoview::internal
