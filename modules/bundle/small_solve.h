// Internal to the bundle module: the residual, the solve and the screen shared by the free-camera and the
// pose-noise bundles (autodiff problems with the nine intrinsics as one block, camera/camera.h's order): the
// held entries of that block fixed by a SubsetManifold (the whole block constant when none is estimated),
// sparse Schur, one thread (deterministic), silent.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <ceres/ceres.h>

#include "camera/camera.h"

namespace selfcal::bundle::internal {

// Holds the entries of the intrinsics block `intrinsics` (kNumIntrinsics values, already in `problem`)
// that `estimate` does not set.
inline void HoldIntrinsics(ceres::Problem* problem, double* intrinsics, const IntrinsicsMask& estimate) {
  std::vector<int> held;
  for (int k = 0; k < kNumIntrinsics; ++k) {
    if (!estimate[k]) held.push_back(k);
  }
  if (static_cast<int>(held.size()) == kNumIntrinsics) {
    problem->SetParameterBlockConstant(intrinsics);
  } else if (!held.empty()) {
    problem->SetManifold(intrinsics, new ceres::SubsetManifold(kNumIntrinsics, held));
  }
}

inline ceres::Solver::Summary SolveWithIntrinsics(ceres::Problem* problem, double* intrinsics,
                                                  const IntrinsicsMask& estimate, int max_iterations) {
  HoldIntrinsics(problem, intrinsics, estimate);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_SCHUR;
  solver.num_threads = 1;
  solver.max_num_iterations = max_iterations;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, problem, &summary);
  return summary;
}

// The whitened reprojection residual (project(p_in_cam) - pixel) / sigma of one observation with the nine
// intrinsics `intrinsics`, autodiff-ready; false when the point is not in front of the camera.
template <typename T>
bool WhitenedReprojection(const T* intrinsics, const Vec3T<T>& p_in_cam, const Eigen::Vector2d& pixel, double inv_sigma,
                          T* residual) {
  T u, v;
  if (!ProjectWithIntrinsics<T>(intrinsics, p_in_cam, &u, &v)) return false;
  residual[0] = (u - T(pixel.x())) * T(inv_sigma);
  residual[1] = (v - T(pixel.y())) * T(inv_sigma);
  return true;
}

// True (and *message says why) when Ceres failed outright.
inline bool SolverFailed(const ceres::Solver::Summary& summary, std::string* message) {
  if (summary.termination_type != ceres::FAILURE && summary.termination_type != ceres::USER_FAILURE) return false;
  *message = "solver failed: " + summary.message;
  return true;
}

// The screen's limit on |r| (px): screen_sigma robust sigmas of the finite errors (median of a 2-D
// Gaussian's norm is sigma sqrt(2 ln 2)), never below the stated noise; NaN when none is finite.
inline double ScreenLimit(const std::vector<double>& errors, double sigma_px, double screen_sigma) {
  std::vector<double> finite;
  for (double e : errors) {
    if (std::isfinite(e)) finite.push_back(e);
  }
  if (finite.empty()) return NAN;
  std::nth_element(finite.begin(), finite.begin() + finite.size() / 2, finite.end());
  return screen_sigma * std::max(sigma_px, finite[finite.size() / 2] / std::sqrt(2.0 * std::log(2.0)));
}

}  // namespace selfcal::bundle::internal
