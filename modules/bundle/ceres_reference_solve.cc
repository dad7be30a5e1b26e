// The kinematic bundle adjustment's solve through Ceres' DENSE_SCHUR, as the bundle solved it before
// kinematic_lm.h: kept as the reference that solver is tested against (bundle_adjustment_test.cc).
#include "bundle/ceres_reference_solve.h"

#include <algorithm>
#include <memory>

#include <ceres/ceres.h>

namespace selfcal::bundle::internal {

namespace {

// Camera pose per pose and its derivatives, recomputed only when the free parameters change and shared
// by every residual block of that pose. Keyed by the values Ceres passes in, so it is right whatever
// memory Ceres evaluates in (solver state, user state, Problem::Evaluate). Filled from const Evaluate:
// single-threaded use only.
class PoseCacheSet {
 public:
  PoseCacheSet(const BundleData* data, const Eigen::VectorXd& rho, std::vector<int> free)
      : data_(data), rho_(rho), free_(std::move(free)), entries_(data->joints.size()) {}

  const PoseCache& Get(int pose, const double* free_values, bool derivatives) const {
    Entry& e = entries_[pose];
    const int m = static_cast<int>(free_.size());
    if (!e.valid || (derivatives && !e.derivatives) || !std::equal(free_values, free_values + m, e.values.begin())) {
      for (int k = 0; k < m; ++k) rho_[free_[k]] = free_values[k];
      ComputePoseCache(*data_, pose, rho_.data(), free_, derivatives, &e.cache);
      e.values.assign(free_values, free_values + m);
      e.valid = true;
      e.derivatives = derivatives;
    }
    return e.cache;
  }
  int num_free() const { return static_cast<int>(free_.size()); }

 private:
  struct Entry {
    bool valid = false, derivatives = false;
    std::vector<double> values;
    PoseCache cache;
  };
  const BundleData* data_;
  mutable Eigen::VectorXd rho_;  // fixed entries at their start values; free ones overwritten per call
  std::vector<int> free_;
  mutable std::vector<Entry> entries_;
};

// The intrinsics of one solve: the held ones' values and which entries the intrinsics block carries.
struct IntrinsicsLayout {
  IntrinsicsVector held;     // every intrinsic at the start; the free ones are overwritten per evaluation
  std::vector<int> free;     // Intrinsic indices in the block, ascending
};

// One observation: blocks the free kinematic parameters, the free intrinsics (absent when none is free),
// the dot. Only the free parameters are blocks (not rho or the nine intrinsics with a SubsetManifold):
// Ceres then never multiplies 2 x |rho| Jacobians by the manifold's, which was a fifth of the solve, and
// the problem with f_x alone free is the one it was before the full lens, bit for bit. Analytic Jacobian
// from the pose cache by the chain rule.
class ReprojectionCost final : public ceres::CostFunction {
 public:
  ReprojectionCost(std::shared_ptr<const PoseCacheSet> caches, std::shared_ptr<const IntrinsicsLayout> intrinsics,
                   const BundleData* data, int observation)
      : caches_(std::move(caches)), intrinsics_(std::move(intrinsics)), data_(data),
        observation_(data->observations[observation]) {
    set_num_residuals(2);
    *mutable_parameter_block_sizes() = {caches_->num_free()};
    if (!intrinsics_->free.empty()) mutable_parameter_block_sizes()->push_back(static_cast<int>(intrinsics_->free.size()));
    mutable_parameter_block_sizes()->push_back(3);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const bool kinematic_jacobian = jacobians != nullptr && jacobians[0] != nullptr;
    const PoseCache& cache = caches_->Get(observation_.pose, parameters[0], kinematic_jacobian);
    const std::vector<int>& free = intrinsics_->free;
    const int dot_block = free.empty() ? 1 : 2;
    IntrinsicsVector in = intrinsics_->held;
    for (size_t k = 0; k < free.size(); ++k) in[free[k]] = parameters[1][k];
    const Eigen::Map<const Eigen::Vector3d> dot(parameters[dot_block]);
    double* const d_block = jacobians != nullptr && !free.empty() ? jacobians[1] : nullptr;
    double d_intrinsics[2 * kNumIntrinsics];
    if (!EvaluateReprojection(in, data_->sigma_px, cache, dot, observation_.pixel, residuals,
                                        kinematic_jacobian ? jacobians[0] : nullptr,
                                        d_block != nullptr ? d_intrinsics : nullptr,
                                        jacobians != nullptr ? jacobians[dot_block] : nullptr)) {
      return false;
    }
    if (d_block != nullptr) {
      const size_t m = free.size();
      for (size_t k = 0; k < m; ++k) {
        d_block[k] = d_intrinsics[free[k]];
        d_block[m + k] = d_intrinsics[kNumIntrinsics + free[k]];
      }
    }
    return true;
  }

 private:
  std::shared_ptr<const PoseCacheSet> caches_;
  std::shared_ptr<const IntrinsicsLayout> intrinsics_;
  const BundleData* data_;
  Observation observation_;
};

struct YardstickResidual {
  YardstickResidual(double length_m, double sigma_m) : length_m(length_m), inv_sigma(1.0 / sigma_m) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    using std::sqrt;
    const T dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    residual[0] = (sqrt(dx * dx + dy * dy + dz * dz) - T(length_m)) * T(inv_sigma);
    return true;
  }
  double length_m, inv_sigma;
};

}  // namespace

LmSummary SolveWithCeres(const BundleData& data, const std::vector<int>& free, const std::vector<int>& free_intrinsics,
                         const LmOptions& options, BundleState* state) {
  auto caches = std::make_shared<const PoseCacheSet>(&data, state->rho, free);
  auto layout = std::make_shared<IntrinsicsLayout>();
  layout->held = state->intrinsics;
  layout->free = free_intrinsics;
  // Every parameter block lives in one buffer, in a fixed layout [free rho | free intrinsics | dots]:
  // Ceres orders the blocks of an elimination group by address, so blocks scattered over the heap and the
  // stack would make the arithmetic, and the last bits of the result, depend on the process (P9).
  const size_t n = free.size();
  const size_t m = layout->free.size();
  std::vector<double> buffer(n + m + 3 * state->dots.size());
  double* const x = buffer.data();
  double* const intrinsics = x + n;
  auto dot = [&](int d) { return intrinsics + m + 3 * d; };
  for (size_t k = 0; k < n; ++k) x[k] = state->rho[free[k]];
  for (size_t k = 0; k < m; ++k) intrinsics[k] = state->intrinsics[layout->free[k]];
  for (size_t d = 0; d < state->dots.size(); ++d) Eigen::Map<Eigen::Vector3d>(dot(static_cast<int>(d))) = state->dots[d];
  // Residuals are whitened, so the Huber threshold is huber_px in units of sigma. Declared before the
  // problem, which holds non-owning wrappers of it.
  const bool robust = options.huber_threshold > 0;
  ceres::HuberLoss huber(robust ? options.huber_threshold : 1.0);
  ceres::Problem problem;
  problem.AddParameterBlock(x, static_cast<int>(n));
  if (m > 0) problem.AddParameterBlock(intrinsics, static_cast<int>(m));
  for (size_t k = 0; k < data.observations.size(); ++k) {
    std::vector<double*> blocks = {x};
    if (m > 0) blocks.push_back(intrinsics);
    blocks.push_back(dot(data.observations[k].dot));
    problem.AddResidualBlock(new ReprojectionCost(caches, layout, &data, static_cast<int>(k)),
                             robust ? new ceres::LossFunctionWrapper(&huber, ceres::DO_NOT_TAKE_OWNERSHIP) : nullptr,
                             blocks);
  }
  std::vector<bool> in_yardstick(data.dot_ids.size(), false);
  for (const Yardstick& y : data.yardsticks) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<YardstickResidual, 1, 3, 3>(
                                 new YardstickResidual(y.length_m, data.yardstick_sigma_m)),
                             nullptr, dot(y.dot_a), dot(y.dot_b));
    in_yardstick[y.dot_a] = in_yardstick[y.dot_b] = true;
  }
  // Schur: the dots are eliminated, except the yardstick's ends (their length residual couples two dots,
  // and an eliminated block may appear in a residual only with non-eliminated ones).
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (size_t d = 0; d < data.dot_ids.size(); ++d) {
    ordering->AddElementToGroup(dot(static_cast<int>(d)), in_yardstick[d] ? 1 : 0);
  }
  ordering->AddElementToGroup(x, 1);
  if (m > 0) ordering->AddElementToGroup(intrinsics, 1);

  ceres::Solver::Options solver_options;
  solver_options.minimizer_type = ceres::TRUST_REGION;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.linear_solver_ordering = ordering;
  solver_options.num_threads = 1;  // the pose cache is filled from Evaluate; also deterministic (P9)
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver_options, &problem, &ceres_summary);
  for (size_t k = 0; k < n; ++k) state->rho[free[k]] = x[k];
  for (size_t k = 0; k < m; ++k) state->intrinsics[layout->free[k]] = intrinsics[k];
  for (size_t d = 0; d < state->dots.size(); ++d) state->dots[d] = Eigen::Map<const Eigen::Vector3d>(dot(static_cast<int>(d)));
  LmSummary summary;
  summary.termination = ceres_summary.termination_type == ceres::CONVERGENCE      ? LmSummary::Termination::kConvergence
                        : ceres_summary.termination_type == ceres::NO_CONVERGENCE ? LmSummary::Termination::kNoConvergence
                                                                                  : LmSummary::Termination::kFailure;
  summary.message = ceres_summary.message;
  summary.iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
  summary.initial_cost = ceres_summary.initial_cost;
  summary.final_cost = ceres_summary.final_cost;
  return summary;
}

}  // namespace selfcal::bundle::internal
