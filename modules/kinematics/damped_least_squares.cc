#include "kinematics/damped_least_squares.h"

#include <algorithm>

#include <Eigen/Cholesky>

namespace selfcal {

void MinimiseDampedLeastSquares(const ResidualAndJacobian& evaluate, Eigen::VectorXd* x, int max_iterations) {
  const int n = static_cast<int>(x->size());
  double lambda = 1e-3;
  Eigen::VectorXd r, r_new;
  Eigen::MatrixXd jac, jac_new;
  evaluate(*x, &r, &jac);
  for (int iter = 0; iter < max_iterations; ++iter) {
    if (r.norm() < 1e-12) break;
    const Eigen::MatrixXd jtj = jac.transpose() * jac;
    const Eigen::VectorXd step = -(jtj + lambda * Eigen::MatrixXd::Identity(n, n)).ldlt().solve(jac.transpose() * r);
    const Eigen::VectorXd candidate = *x + step;
    evaluate(candidate, &r_new, &jac_new);
    if (r_new.norm() < r.norm()) {
      *x = candidate;
      r = r_new;
      jac = jac_new;
      lambda = std::max(lambda * 0.3, 1e-12);
    } else {
      lambda *= 10;
      if (lambda > 1e8) break;
    }
  }
}

}  // namespace selfcal
