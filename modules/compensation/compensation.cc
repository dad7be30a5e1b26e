#include "compensation/compensation.h"

#include <cmath>
#include <sstream>

#include <Eigen/Dense>

#include "base/status.h"
#include "kinematics/autodiff_jacobian.h"

namespace selfcal::compensation {
namespace {

// Levenberg-Marquardt's damping: start, bounds and the factors of a good and a bad step.
constexpr double kLambdaStart = 1e-3;
constexpr double kLambdaMin = 1e-12;
constexpr double kLambdaMax = 1e10;

IkResult Measure(const RobotModel& model, TargetFrame frame, const Rigid3& target, const Eigen::VectorXd& q,
                 const IkOptions& options) {
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  const Rigid3 reached = frame == TargetFrame::kCamera ? BaseFromCam(model, rho, q) : BaseFromFlange(model, rho, q);
  const PoseDifference d = ComparePoses(target, reached);
  IkResult result;
  result.q = q;
  result.position_residual_m = d.position_m;
  result.rotation_residual_rad = d.rotation_rad;
  result.converged = d.position_m <= options.position_tolerance_m && d.rotation_rad <= options.rotation_tolerance_rad;
  return result;
}

}  // namespace

std::string IkOptions::Validate() const {
  std::ostringstream out;
  if (max_iterations < 1) out << "max_iterations " << max_iterations << " must be at least 1\n";
  if (!(position_tolerance_m > 0)) out << "position_tolerance_m must be positive\n";
  if (!(rotation_tolerance_rad > 0)) out << "rotation_tolerance_rad must be positive\n";
  if (!(rotation_scale_m > 0)) out << "rotation_scale_m must be positive\n";
  return out.str();
}

IkResult SolveIk(const RobotModel& model, TargetFrame frame, const Rigid3& base_from_target,
                 const Eigen::VectorXd& seed, const IkOptions& options) {
  SELFCAL_CHECK(seed.size() == model.num_joints(), "seed has " << seed.size() << " joints, the model " << model.num_joints());
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  const Rigid3 target_from_base = base_from_target.Inverse();
  const double scale = options.rotation_scale_m;
  auto residual = [&](const auto* q, auto* out) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(q)>>;
    std::vector<T> rho_t(rho.size());
    for (int i = 0; i < rho.size(); ++i) rho_t[i] = T(rho[i]);
    const Rigid3T<T> reached = frame == TargetFrame::kCamera ? BaseFromCam<T>(model, rho_t.data(), q)
                                                             : BaseFromFlange<T>(model, rho_t.data(), q);
    const Rigid3T<T> err = target_from_base.Cast<T>() * reached;
    for (int k = 0; k < 3; ++k) out[k] = err.translation[k];
    // The rotation error's antisymmetric part (sin(angle) times the axis): smooth for Jets and exact to
    // first order at the solution; it also vanishes at a half turn, which the final measure refuses.
    out[3] = T(0.5 * scale) * (err.rotation(2, 1) - err.rotation(1, 2));
    out[4] = T(0.5 * scale) * (err.rotation(0, 2) - err.rotation(2, 0));
    out[5] = T(0.5 * scale) * (err.rotation(1, 0) - err.rotation(0, 1));
  };
  Eigen::VectorXd x = seed, r;
  Eigen::MatrixXd jac = AutodiffJacobian(residual, x, 6, &r);
  double lambda = kLambdaStart;
  int iteration = 0;
  for (; iteration < options.max_iterations; ++iteration) {
    if (Measure(model, frame, base_from_target, x, options).converged) break;
    const Eigen::MatrixXd jtj = jac.transpose() * jac;
    const Eigen::VectorXd step =
        -(jtj + lambda * Eigen::MatrixXd::Identity(jtj.rows(), jtj.cols())).ldlt().solve(jac.transpose() * r);
    const Eigen::VectorXd candidate = x + step;
    Eigen::VectorXd r_new;
    const Eigen::MatrixXd jac_new = AutodiffJacobian(residual, candidate, 6, &r_new);
    if (r_new.allFinite() && r_new.squaredNorm() < r.squaredNorm()) {
      x = candidate;
      r = r_new;
      jac = jac_new;
      lambda = std::max(lambda * 0.3, kLambdaMin);
    } else {
      lambda *= 10;
      if (lambda > kLambdaMax) break;
    }
  }
  IkResult result = Measure(model, frame, base_from_target, x, options);
  result.iterations = iteration;
  return result;
}

CompensationReport Compensate(const RobotModel& nominal, const RobotModel& calibrated, TargetFrame frame,
                              const std::vector<Target>& targets, const IkOptions& options) {
  SELFCAL_CHECK(nominal.num_joints() == calibrated.num_joints(),
                "nominal model of " << nominal.num_joints() << " joints, calibrated of " << calibrated.num_joints());
  const int n = calibrated.num_joints();
  Eigen::VectorXd previous(n);
  for (int j = 0; j < n; ++j) previous[j] = 0.5 * (calibrated.limits[j].min_rad + calibrated.limits[j].max_rad);
  CompensationReport report;
  for (const Target& target : targets) {
    const Eigen::VectorXd seed = target.seed.value_or(previous);
    SELFCAL_CHECK(seed.size() == n, "a target's seed has " << seed.size() << " joints, the robot " << n);
    TargetSolution solution;
    solution.nominal = SolveIk(nominal, frame, target.base_from_target, seed, options);
    solution.compensated = SolveIk(calibrated, frame, target.base_from_target, solution.nominal.q, options);
    for (int j = 0; j < n; ++j) {
      const double q = solution.compensated.q[j];
      if (q < calibrated.limits[j].min_rad || q > calibrated.limits[j].max_rad) {
        solution.joints_outside_limits.push_back(j + 1);
      }
    }
    report.not_converged += solution.compensated.converged ? 0 : 1;
    report.outside_limits += solution.joints_outside_limits.empty() ? 0 : 1;
    if (solution.nominal.converged) previous = solution.nominal.q;
    report.targets.push_back(std::move(solution));
  }
  return report;
}

}  // namespace selfcal::compensation
