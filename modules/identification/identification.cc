#include "identification/identification.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

#include <Eigen/Dense>
#include <ceres/ceres.h>

#include "identification/relative_pose_residual.h"

namespace selfcal::identification {

namespace internal {

namespace {

// base_from_cam and its derivative with respect to selected entries of rho, following the factor
// order of BaseFromCam<T> (robot_model.h) exactly, so the value is the same bits:
//   base_from_link0 * Exp(base) * L_1 ... L_n * link_n_from_flange * flange_from_cam * Exp(cam).
// For X = P F S, dX/dp = P (dF/dp) S: rotation R_P dR_F R_S, translation R_P (dR_F t_S + dt_F).
struct ChainDerivative {
  Rigid3 pose;
  std::vector<Eigen::Matrix3d> d_rotation;  // per requested column
  std::vector<Eigen::Vector3d> d_translation;
};

void BaseFromCamWithDerivatives(const RobotModel& model, const double* rho, const Eigen::VectorXd& q,
                                const std::vector<int>& columns, bool derivatives, ChainDerivative* out) {
  const int n = model.num_joints();
  const int num_factors = n + 5;
  const int cam_offset = 6 + 5 * n;
  // Factor holding a parameter: 1 base, 2 + i link i, n + 4 camera (0, n + 2, n + 3 are constant).
  auto factor_of = [&](int p) { return p < 6 ? 1 : (p < cam_offset ? 2 + (p - 6) / 5 : n + 4); };
  auto first_of = [&](int k) { return k == 1 ? 0 : (k == n + 4 ? cam_offset : 6 + 5 * (k - 2)); };

  std::vector<Rigid3> f(num_factors);
  f[0] = model.base_from_link0;
  f[1] = RigidFromTranslationRotvec(rho);
  for (int i = 0; i < n; ++i) {
    const double* p = rho + KinematicParameters::JointOffset(i);
    f[2 + i] = LinkTransform<double>(p[0], p[1], p[2], q[i] + p[3], p[4]);
  }
  f[n + 2] = model.link_n_from_flange;
  f[n + 3] = model.flange_from_cam;
  f[n + 4] = RigidFromTranslationRotvec(rho + cam_offset);
  // prefix[k] = f[0] ... f[k - 1], suffix[k] = f[k + 1] ... f[last].
  std::vector<Rigid3> prefix(num_factors + 1), suffix(num_factors);
  prefix[1] = f[0];
  for (int k = 1; k < num_factors; ++k) prefix[k + 1] = prefix[k] * f[k];
  out->pose = prefix[num_factors];
  if (!derivatives) return;
  suffix[num_factors - 1] = Rigid3();
  for (int k = num_factors - 2; k >= 0; --k) suffix[k] = f[k + 1] * suffix[k + 1];

  out->d_rotation.resize(columns.size());
  out->d_translation.resize(columns.size());
  int loaded_factor = -1;
  Eigen::Matrix3d d_rot_local[6];
  Eigen::Vector3d d_trans_local[6];
  for (size_t c = 0; c < columns.size(); ++c) {
    const int k = factor_of(columns[c]);
    if (k != loaded_factor) {
      const double* p = rho + first_of(k);
      if (k == 1 || k == n + 4) {
        using Jet = ceres::Jet<double, 6>;
        Jet v[6];
        for (int j = 0; j < 6; ++j) v[j] = Jet(p[j], j);
        const Rigid3T<Jet> t = RigidFromTranslationRotvec<Jet>(v);
        for (int j = 0; j < 6; ++j) {
          for (int e = 0; e < 9; ++e) d_rot_local[j](e % 3, e / 3) = t.rotation(e % 3, e / 3).v[j];
          for (int e = 0; e < 3; ++e) d_trans_local[j][e] = t.translation[e].v[j];
        }
      } else {
        using Jet = ceres::Jet<double, 5>;
        const Rigid3T<Jet> t =
            LinkTransform<Jet>(Jet(p[0], 0), Jet(p[1], 1), Jet(p[2], 2), Jet(q[k - 2] + p[3], 3), Jet(p[4], 4));
        for (int j = 0; j < 5; ++j) {
          for (int e = 0; e < 9; ++e) d_rot_local[j](e % 3, e / 3) = t.rotation(e % 3, e / 3).v[j];
          for (int e = 0; e < 3; ++e) d_trans_local[j][e] = t.translation[e].v[j];
        }
      }
      loaded_factor = k;
    }
    const int j = columns[c] - first_of(k);
    const Eigen::Matrix3d& rp = prefix[k].rotation;
    out->d_rotation[c] = rp * d_rot_local[j] * suffix[k].rotation;
    out->d_translation[c] = rp * (d_rot_local[j] * suffix[k].translation + d_trans_local[j]);
  }
}

}  // namespace

bool EvaluateRelativePoseResidual(const RobotModel& model, const double* rho, const Eigen::VectorXd& q_ref,
                                  const Eigen::VectorXd& q_i, const Rigid3& measured, bool translation_valid,
                                  double inv_sigma_position, double inv_sigma_rotation, const std::vector<int>& columns,
                                  double* residuals, double* jacobian) {
  const int m = translation_valid ? 6 : 3;
  const bool derivatives = jacobian != nullptr;
  ChainDerivative ref, cur;
  BaseFromCamWithDerivatives(model, rho, q_ref, columns, derivatives, &ref);
  BaseFromCamWithDerivatives(model, rho, q_i, columns, derivatives, &cur);
  const Rigid3 relative = ref.pose.Inverse() * cur.pose;

  // Residual head through Jets in the 12 entries of the relative pose (rotation column-major, then
  // translation): D = d r / d (R_rel, t_rel).
  using Jet = ceres::Jet<double, 12>;
  Rigid3T<Jet> rel_jet;
  for (int e = 0; e < 9; ++e) rel_jet.rotation(e % 3, e / 3) = Jet(relative.rotation(e % 3, e / 3), e);
  for (int e = 0; e < 3; ++e) rel_jet.translation[e] = Jet(relative.translation[e], 9 + e);
  Jet out[6];
  RelativePoseResidual<Jet>(rel_jet, measured, translation_valid, inv_sigma_position, inv_sigma_rotation, out);
  bool finite = true;
  for (int r = 0; r < m; ++r) {
    residuals[r] = out[r].a;
    finite = finite && std::isfinite(residuals[r]);
  }
  if (!derivatives) return finite;

  const int num_parameters = model.num_parameters();
  std::fill(jacobian, jacobian + m * num_parameters, 0.0);
  const Eigen::Matrix3d rt_ref = ref.pose.rotation.transpose();
  const Eigen::Vector3d t_diff = cur.pose.translation - ref.pose.translation;
  for (size_t c = 0; c < columns.size(); ++c) {
    // d(R_ref^T R_i) and d(R_ref^T (t_i - t_ref)).
    const Eigen::Matrix3d d_rot = ref.d_rotation[c].transpose() * cur.pose.rotation + rt_ref * cur.d_rotation[c];
    const Eigen::Vector3d d_trans =
        ref.d_rotation[c].transpose() * t_diff + rt_ref * (cur.d_translation[c] - ref.d_translation[c]);
    for (int r = 0; r < m; ++r) {
      double sum = 0;
      for (int e = 0; e < 9; ++e) sum += out[r].v[e] * d_rot(e % 3, e / 3);
      for (int e = 0; e < 3; ++e) sum += out[r].v[9 + e] * d_trans[e];
      jacobian[r * num_parameters + columns[c]] = sum;
      finite = finite && std::isfinite(sum);
    }
  }
  return finite;
}

}  // namespace internal

namespace {

// Relative to the largest column norm / singular value of the column-normalised Jacobian of the free
// parameters; below it the covariance is declared unavailable (K8).
constexpr double kCovarianceRankTolerance = 1e-10;

// What every residual block shares.
struct SharedInputs {
  const RobotModel* model = nullptr;
  std::vector<int> free_indices;
  Eigen::VectorXd q_ref;
  double inv_sigma_position = 1, inv_sigma_rotation = 1;
};

// One measurement; the parameter block is the whole rho, derivatives are formed for the free entries
// only (the fixed columns are zero, and the SubsetManifold ignores them).
class RelativePoseCost final : public ceres::CostFunction {
 public:
  RelativePoseCost(std::shared_ptr<const SharedInputs> problem, const Eigen::VectorXd& q_i, const Rigid3& measured,
                   bool translation_valid)
      : problem_(std::move(problem)), q_i_(q_i), measured_(measured), translation_valid_(translation_valid) {
    set_num_residuals(translation_valid ? 6 : 3);
    mutable_parameter_block_sizes()->push_back(problem_->model->num_parameters());
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const SharedInputs& p = *problem_;
    return internal::EvaluateRelativePoseResidual(*p.model, parameters[0], p.q_ref, q_i_, measured_, translation_valid_,
                                                  p.inv_sigma_position, p.inv_sigma_rotation, p.free_indices, residuals,
                                                  jacobians != nullptr ? jacobians[0] : nullptr);
  }

 private:
  std::shared_ptr<const SharedInputs> problem_;
  Eigen::VectorXd q_i_;
  Rigid3 measured_;
  bool translation_valid_;
};

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

// Checks the caller's data; an empty string when usable.
std::string CheckInputs(const RobotModel& model, const Eigen::VectorXd& rho_start, const std::vector<int>& free_indices,
                        const std::vector<Eigen::VectorXd>& joint_poses, int reference_index,
                        const std::vector<RelativePoseMeasurement>& measurements) {
  std::ostringstream out;
  const int n = model.num_parameters();
  const int num_poses = static_cast<int>(joint_poses.size());
  if (rho_start.size() != n) out << "rho has " << rho_start.size() << " entries, the model needs " << n << "\n";
  if (reference_index < 0 || reference_index >= num_poses) {
    out << "reference index " << reference_index << " outside [0, " << num_poses << ")\n";
  }
  for (int i = 0; i < num_poses; ++i) {
    if (joint_poses[i].size() != model.num_joints()) {
      out << "joint pose " << i << " has " << joint_poses[i].size() << " angles, the robot " << model.num_joints()
          << "\n";
    } else if (!joint_poses[i].allFinite()) {
      out << "joint pose " << i << " is not finite\n";
    }
  }
  if (free_indices.empty()) out << "no free parameters\n";
  std::vector<bool> seen(std::max(n, 0), false);
  for (int index : free_indices) {
    if (index < 0 || index >= n) {
      out << "free index " << index << " outside [0, " << n << ")\n";
    } else if (seen[index]) {
      out << "free index " << index << " listed twice\n";
    } else {
      seen[index] = true;
    }
  }
  if (measurements.empty()) out << "no measurements\n";
  for (size_t k = 0; k < measurements.size(); ++k) {
    const int p = measurements[k].pose_index;
    if (p < 0 || p >= num_poses) {
      out << "measurement " << k << ": pose index " << p << " outside [0, " << num_poses << ")\n";
    } else if (p == reference_index) {
      out << "measurement " << k << ": pose index " << p << " is the reference pose\n";
    }
  }
  return out.str();
}

// The residual blocks, one per measurement; *num_residuals is their total. Owned by the ceres::Problem
// once added; the raw pointers stay valid as long as it lives.
std::vector<std::unique_ptr<RelativePoseCost>> MakeCosts(std::shared_ptr<const SharedInputs> shared,
                                                         const std::vector<Eigen::VectorXd>& joint_poses,
                                                         const std::vector<RelativePoseMeasurement>& measurements,
                                                         int* num_residuals) {
  std::vector<std::unique_ptr<RelativePoseCost>> costs;
  *num_residuals = 0;
  for (const RelativePoseMeasurement& m : measurements) {
    costs.push_back(std::make_unique<RelativePoseCost>(shared, joint_poses[m.pose_index], m.cam_ref_from_cam_i,
                                                       m.translation_valid));
    *num_residuals += costs.back()->num_residuals();
  }
  return costs;
}

// K5: every block must give finite residuals and derivatives at the start, before Ceres sees it. The
// blocks that do not, named; empty when all do.
std::string NonFiniteBlocks(const std::vector<std::unique_ptr<RelativePoseCost>>& costs,
                            const std::vector<RelativePoseMeasurement>& measurements, const Eigen::VectorXd& rho,
                            int num_parameters) {
  std::vector<double> residuals(6), jac(6 * num_parameters);
  const double* parameters[1] = {rho.data()};
  double* jacobians[1] = {jac.data()};
  std::ostringstream bad;
  int num_bad = 0;
  for (size_t k = 0; k < costs.size(); ++k) {
    if (!costs[k]->Evaluate(parameters, residuals.data(), jacobians)) {
      bad << (num_bad++ ? ", " : "") << "measurement " << k << " (pose " << measurements[k].pose_index << ")";
    }
  }
  return bad.str();
}

// Levenberg-Marquardt on rho in place, the entries outside `free` held by a SubsetManifold. Hands the
// blocks to `problem`; `blocks` keeps non-owning pointers to them, valid as long as the problem lives.
ceres::Solver::Summary Solve(std::vector<std::unique_ptr<RelativePoseCost>> costs, const std::vector<int>& free,
                             const IdentificationOptions& options, Eigen::VectorXd* rho, ceres::Problem* problem_ptr,
                             std::vector<const RelativePoseCost*>* blocks) {
  const int n = static_cast<int>(rho->size());
  ceres::Problem& problem = *problem_ptr;
  for (auto& cost : costs) {
    blocks->push_back(cost.get());
    problem.AddResidualBlock(cost.release(), nullptr, rho->data());
  }
  std::vector<int> constant;
  {
    std::vector<bool> is_free(n, false);
    for (int i : free) is_free[i] = true;
    for (int i = 0; i < n; ++i) {
      if (!is_free[i]) constant.push_back(i);
    }
  }
  if (!constant.empty()) problem.SetManifold(rho->data(), new ceres::SubsetManifold(n, constant));

  ceres::Solver::Options solver_options;
  solver_options.minimizer_type = ceres::TRUST_REGION;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  return summary;
}

// The whitened Jacobian of the free parameters at rho (rows in block order) and the RMS errors.
struct SolutionResiduals {
  Eigen::MatrixXd jacobian;
  double rms_rotation_rad = 0, rms_position_m = 0;  // over measurements, of the error norms
};

SolutionResiduals EvaluateSolution(const std::vector<const RelativePoseCost*>& blocks, const Eigen::VectorXd& rho,
                                   const std::vector<int>& free, int num_residuals,
                                   const IdentificationOptions& options) {
  const int n = static_cast<int>(rho.size());
  const int num_free = static_cast<int>(free.size());
  SolutionResiduals out;
  out.jacobian = Eigen::MatrixXd::Zero(num_residuals, num_free);
  double sum_sq_position = 0, sum_sq_rotation = 0;
  int num_position = 0;
  std::vector<double> residuals(6), jac(6 * n);
  const double* parameters[1] = {rho.data()};
  double* jacobians[1] = {jac.data()};
  int row = 0;
  for (const RelativePoseCost* cost : blocks) {
    const int m = cost->num_residuals();
    cost->Evaluate(parameters, residuals.data(), jacobians);
    for (int r = 0; r < m; ++r) {
      for (int k = 0; k < num_free; ++k) out.jacobian(row + r, k) = jac[r * n + free[k]];
    }
    const Eigen::Map<const Eigen::Vector3d> rot(residuals.data());
    sum_sq_rotation += rot.squaredNorm() * options.sigma_rotation_rad * options.sigma_rotation_rad;
    if (m == 6) {
      const Eigen::Map<const Eigen::Vector3d> pos(residuals.data() + 3);
      sum_sq_position += pos.squaredNorm() * options.sigma_position_m * options.sigma_position_m;
      ++num_position;
    }
    row += m;
  }
  out.rms_rotation_rad = std::sqrt(sum_sq_rotation / static_cast<double>(blocks.size()));
  out.rms_position_m = num_position > 0 ? std::sqrt(sum_sq_position / num_position) : 0.0;
  return out;
}

// Names of the free parameters involved in a null direction of the column-normalised Jacobian.
std::vector<std::string> DeficientNames(const Eigen::JacobiSVD<Eigen::MatrixXd>& svd, int num_residuals,
                                        const std::vector<int>& free, const KinematicParameters& params) {
  const int num_free = static_cast<int>(free.size());
  const Eigen::VectorXd sv = svd.singularValues();
  const double sigma_max = sv.size() > 0 ? sv[0] : 0.0;
  std::vector<std::string> deficient;
  const int rank_limit = std::min(num_residuals, num_free);
  std::vector<bool> involved(num_free, false);
  for (int k = 0; k < num_free; ++k) {
    const bool is_null = k >= rank_limit || !(sv[k] > kCovarianceRankTolerance * sigma_max);
    if (!is_null) continue;
    for (int j = 0; j < num_free; ++j) involved[j] = involved[j] || std::abs(svd.matrixV()(j, k)) > 0.05;
  }
  for (int j = 0; j < num_free; ++j) {
    if (involved[j]) deficient.push_back(params.name(free[j]));
  }
  return deficient;
}

// Covariance s^2 (J^T J)^-1 through the SVD of the column-normalised J (K8: never garbage sigmas), with
// the standard deviations and correlations from it; or the reason it is unavailable.
void EstimateCovariance(const Eigen::MatrixXd& jacobian, const std::vector<int>& free,
                        const KinematicParameters& params, double final_cost, IdentificationReport* report) {
  const int num_residuals = static_cast<int>(jacobian.rows());
  const int num_free = static_cast<int>(free.size());
  const int dof = num_residuals - num_free;
  const Eigen::VectorXd norms = jacobian.colwise().norm().transpose();
  const double max_norm = norms.size() > 0 ? norms.maxCoeff() : 0.0;
  Eigen::MatrixXd normalized = Eigen::MatrixXd::Zero(num_residuals, num_free);
  // A column below the tolerance is round-off (a parameter the data cannot see): it stays zero so that
  // it shows as a null direction instead of a unit-norm noise pattern.
  for (int k = 0; k < num_free; ++k) {
    if (max_norm > 0 && norms[k] > kCovarianceRankTolerance * max_norm) normalized.col(k) = jacobian.col(k) / norms[k];
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(normalized, Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  const std::vector<std::string> deficient = DeficientNames(svd, num_residuals, free, params);
  if (!deficient.empty()) {
    report->covariance_message = "uncertainty unavailable (rank deficient: " + JoinNames(deficient) + ")";
    return;
  }
  if (dof <= 0) {
    report->covariance_message = "uncertainty unavailable (no redundancy: " + std::to_string(num_residuals) +
                                 " residuals for " + std::to_string(num_free) + " free parameters)";
    return;
  }
  const double s2 = 2.0 * final_cost / dof;
  const Eigen::MatrixXd v = svd.matrixV();
  const Eigen::VectorXd inv_sv2 = sv.head(num_free).array().square().inverse();
  const Eigen::MatrixXd normalized_cov = v * inv_sv2.asDiagonal() * v.transpose();
  const Eigen::VectorXd inv_norms = norms.array().inverse();
  report->covariance_free = s2 * (inv_norms.asDiagonal() * normalized_cov * inv_norms.asDiagonal());
  report->covariance_available = true;
  report->covariance_message = "ok";
  const Eigen::VectorXd sd = report->covariance_free.diagonal().array().sqrt();
  report->correlation_free = report->covariance_free;
  for (int i = 0; i < num_free; ++i) {
    report->stddev[free[i]] = sd[i];
    for (int j = 0; j < num_free; ++j) {
      report->correlation_free(i, j) =
          sd[i] > 0 && sd[j] > 0 ? report->covariance_free(i, j) / (sd[i] * sd[j]) : 0.0;
    }
  }
}

}  // namespace

std::string IdentificationOptions::Validate() const {
  std::ostringstream out;
  if (!std::isfinite(sigma_position_m) || sigma_position_m <= 0) {
    out << "sigma_position_m = " << sigma_position_m << " must be finite and > 0\n";
  }
  if (!std::isfinite(sigma_rotation_rad) || sigma_rotation_rad <= 0) {
    out << "sigma_rotation_rad = " << sigma_rotation_rad << " must be finite and > 0\n";
  }
  if (max_iterations < 1) out << "max_iterations = " << max_iterations << " must be >= 1\n";
  if (!(function_tolerance >= 0)) out << "function_tolerance = " << function_tolerance << " must be >= 0\n";
  if (!(gradient_tolerance >= 0)) out << "gradient_tolerance = " << gradient_tolerance << " must be >= 0\n";
  if (!(parameter_tolerance >= 0)) out << "parameter_tolerance = " << parameter_tolerance << " must be >= 0\n";
  return out.str();
}

const char* OutcomeName(Outcome outcome) {
  switch (outcome) {
    case Outcome::kNotRun:
      return "not_run";
    case Outcome::kConverged:
      return "converged";
    case Outcome::kNoConvergence:
      return "unconverged";
    case Outcome::kFailure:
      return "failure";
    case Outcome::kInvalidInput:
      return "invalid_input";
  }
  return "unknown";
}

IdentificationReport IdentifyFromRelativePoses(const RobotModel& model, const Eigen::VectorXd& rho_start,
                                               const std::vector<int>& free_indices,
                                               const std::vector<Eigen::VectorXd>& joint_poses, int reference_index,
                                               const std::vector<RelativePoseMeasurement>& measurements,
                                               const IdentificationOptions& options) {
  IdentificationReport report;
  report.rho = rho_start;
  report.free_indices = free_indices;
  const int n = model.num_parameters();
  report.stddev =
      Eigen::VectorXd::Constant(std::max<Eigen::Index>(rho_start.size(), 0), std::numeric_limits<double>::quiet_NaN());
  const std::string problems =
      options.Validate() + CheckInputs(model, rho_start, free_indices, joint_poses, reference_index, measurements);
  if (!problems.empty()) {
    report.outcome = Outcome::kInvalidInput;
    report.message = problems.substr(0, problems.size() - 1);
    return report;
  }
  std::vector<int> free = free_indices;
  std::sort(free.begin(), free.end());
  report.free_indices = free;
  const KinematicParameters params(model.num_joints());

  auto shared = std::make_shared<SharedInputs>();
  shared->model = &model;
  shared->free_indices = free;
  shared->q_ref = joint_poses[reference_index];
  shared->inv_sigma_position = 1.0 / options.sigma_position_m;
  shared->inv_sigma_rotation = 1.0 / options.sigma_rotation_rad;
  int num_residuals = 0;
  std::vector<std::unique_ptr<RelativePoseCost>> costs = MakeCosts(shared, joint_poses, measurements, &num_residuals);

  if (!rho_start.allFinite()) {
    std::vector<std::string> names;
    for (int i = 0; i < n; ++i) {
      if (!std::isfinite(rho_start[i])) names.push_back(params.name(i));
    }
    report.outcome = Outcome::kFailure;
    report.message = "non-finite start parameters: " + JoinNames(names);
    return report;
  }
  const std::string bad = NonFiniteBlocks(costs, measurements, rho_start, n);
  if (!bad.empty()) {
    report.outcome = Outcome::kFailure;
    report.message = "non-finite residual or Jacobian at the start: " + bad;
    return report;
  }

  Eigen::VectorXd rho = rho_start;
  ceres::Problem::Options problem_options;
  ceres::Problem problem(problem_options);
  std::vector<const RelativePoseCost*> blocks;
  const ceres::Solver::Summary summary = Solve(std::move(costs), free, options, &rho, &problem, &blocks);
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;
  report.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  report.termination = std::string(ceres::TerminationTypeToString(summary.termination_type)) + ": " + summary.message;
  switch (summary.termination_type) {
    case ceres::CONVERGENCE:
      report.outcome = Outcome::kConverged;
      break;
    case ceres::NO_CONVERGENCE:
      report.outcome = Outcome::kNoConvergence;
      break;
    default:
      report.outcome = Outcome::kFailure;
      break;
  }
  if (report.outcome == Outcome::kFailure) {
    report.message = "solver failed: " + report.termination;
    return report;
  }
  report.rho = rho;
  report.message = report.outcome == Outcome::kConverged ? "converged" : "not converged: " + report.termination;

  const SolutionResiduals solution = EvaluateSolution(blocks, rho, free, num_residuals, options);
  report.rms_rotation_rad = solution.rms_rotation_rad;
  report.rms_position_m = solution.rms_position_m;
  EstimateCovariance(solution.jacobian, free, params, summary.final_cost, &report);
  return report;
}

}  // namespace selfcal::identification
