// Internal to the bundle module: the Levenberg-Marquardt solve of the kinematic bundle adjustment, with the
// dots eliminated by their Schur complement.
//
// Every reprojection residual depends on the same global block (the free kinematic parameters and the free
// intrinsics) and on one dot. A general sparse solver (Ceres' DENSE_SCHUR: one 2 x (globals) outer
// product per observation, through dynamically sized blocks and a lock each) spent most of a calibration
// forming that reduced system; here each dot's observations are one block of rows, the globals' normal
// matrix one symmetric rank update per dot, and the dot's own 3 x 3 block eliminated in closed form.
//
// The iteration is the trust-region Levenberg-Marquardt of Ceres Solver 2.1, rule for rule, so that the
// calibrations keep their results up to round-off: Jacobi scaling of the columns fixed at the start
// (1 / (1 + |column|)), the LM diagonal clamped to [1e-6, 1e32] and divided by the radius (initially 1e4,
// at most 1e16; after a step of quality rho > 1e-3 it is divided by max(1/3, 1 - (2 rho - 1)^3), after a
// refused step it is divided by 2, 4, 8, ...), the step quality against the linear model's decrease, the
// Huber loss applied as Ceres' corrector does (residual and Jacobian scaled by sqrt(rho'), rho'' <= 0), and
// its tests: function tolerance |cost change| <= tol cost (checked before the step is judged), parameter
// tolerance |step| <= tol (|x| + tol), gradient tolerance max |J^T r| <= tol after a successful step,
// the iteration limit, a radius below 1e-32, five consecutive invalid steps.
#pragma once

#include <string>
#include <vector>

#include "bundle/bundle_problem.h"

namespace selfcal::bundle::internal {

struct LmOptions {
  int max_iterations = 100;
  double function_tolerance = 1e-12;
  double gradient_tolerance = 1e-12;
  double parameter_tolerance = 1e-12;
  // Huber threshold on the whitened residual's norm (in standard deviations); none when not positive.
  double huber_threshold = 0;
};

struct LmSummary {
  enum class Termination { kConvergence, kNoConvergence, kFailure };
  Termination termination = Termination::kFailure;
  std::string message;
  int iterations = 0;  // after the start, successful or not (Ceres' iterations.size() - 1)
  double initial_cost = 0, final_cost = 0;  // 1/2 sum rho(|r|^2), whitened
};
const char* TerminationName(LmSummary::Termination termination);  // "CONVERGENCE", ...

// Minimises over the rho entries `free`, the intrinsics `free_intrinsics` (Intrinsic indices, ascending)
// and every dot of `state`: the whitened reprojection residuals of `data` (under the Huber loss when
// asked) and the yardsticks' length residuals. `state` holds the start and, on return, the point of least
// cost reached.
LmSummary SolveKinematicBundle(const BundleData& data, const std::vector<int>& free,
                               const std::vector<int>& free_intrinsics, const LmOptions& options, BundleState* state);

}  // namespace selfcal::bundle::internal
