// Levenberg-Marquardt on eq. (13) of the paper with Ceres: f_x (as 1/f_x), R on the quaternion manifold,
// the direction of t on the unit sphere.
#include <cmath>
#include <sstream>

#include <Eigen/Geometry>
#include <ceres/ceres.h>

#include "twoview/epipolar_cost.h"
#include "twoview/two_view_internal.h"

namespace selfcal::twoview::internal {
namespace {

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
  // Eq. (13) with its Jacobian written out (epipolar_cost.h); automatic differentiation of the same
  // residuals (EpipolarCost) cost about as much again as the rest of the two-view stage.
  problem.AddResidualBlock(new AnalyticEpipolarCost(data, indices, camera.mu, huber_px), nullptr, &inverse_focal,
                           q.coeffs().data(), t.data());
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
