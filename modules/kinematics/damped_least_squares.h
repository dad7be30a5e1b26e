// Damped least squares (Levenberg-Marquardt with a scalar damping), shared by the inverse kinematics of
// kinematics/robot_model.h and the planner's candidate pool (planning/candidate_pool.cc), which differ only
// in how they get the residual's Jacobian.
#pragma once

#include <functional>

#include <Eigen/Core>

namespace selfcal {

// The residual r and its Jacobian j at x.
using ResidualAndJacobian = std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd* r, Eigen::MatrixXd* j)>;

// From *x: steps -(J^T J + lambda I)^-1 J^T r with lambda from 1e-3 (times 0.3, at least 1e-12, after a step
// that lowers |r|; times 10 after one that does not, which is not taken), until |r| < 1e-12, after
// max_iterations steps, or when lambda exceeds 1e8. *x is the last point taken.
void MinimiseDampedLeastSquares(const ResidualAndJacobian& evaluate, Eigen::VectorXd* x, int max_iterations = 200);

}  // namespace selfcal
