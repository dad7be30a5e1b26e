// Dense Jacobians of templated functions by forward-mode autodiff (ceres::Jet), in chunks of kStride
// derivatives so that any input size works with a fixed-size Jet.
#pragma once

#include <algorithm>
#include <vector>

#include <Eigen/Core>
#include <ceres/jet.h>

namespace selfcal {

// f is callable as f(const T* x, T* y) for T = double and T = ceres::Jet<double, kStride>, writing
// num_outputs values. Returns dy/dx (num_outputs x x.size()); the value f(x) goes to *value if given.
template <int kStride = 8, typename Functor>
Eigen::MatrixXd AutodiffJacobian(const Functor& f, const Eigen::VectorXd& x, int num_outputs,
                                 Eigen::VectorXd* value = nullptr) {
  using Jet = ceres::Jet<double, kStride>;
  const int n = static_cast<int>(x.size());
  Eigen::MatrixXd jacobian(num_outputs, n);
  std::vector<Jet> xj(n), yj(num_outputs);
  for (int start = 0; start < std::max(n, 1); start += kStride) {
    for (int i = 0; i < n; ++i) {
      xj[i] = Jet(x[i]);
      if (i >= start && i < start + kStride) xj[i].v[i - start] = 1.0;
    }
    f(xj.data(), yj.data());
    for (int o = 0; o < num_outputs; ++o) {
      for (int k = 0; k < kStride && start + k < n; ++k) jacobian(o, start + k) = yj[o].v[k];
    }
    if (value != nullptr && start == 0) {
      value->resize(num_outputs);
      for (int o = 0; o < num_outputs; ++o) (*value)[o] = yj[o].a;
    }
  }
  return jacobian;
}

// Central-difference Jacobian for checking the above (and anything else).
template <typename Functor>
Eigen::MatrixXd NumericJacobian(const Functor& f, const Eigen::VectorXd& x, int num_outputs, double step = 1e-6) {
  const int n = static_cast<int>(x.size());
  Eigen::MatrixXd jacobian(num_outputs, n);
  Eigen::VectorXd xp = x, yp(num_outputs), ym(num_outputs);
  for (int i = 0; i < n; ++i) {
    xp[i] = x[i] + step;
    f(xp.data(), yp.data());
    xp[i] = x[i] - step;
    f(xp.data(), ym.data());
    xp[i] = x[i];
    jacobian.col(i) = (yp - ym) / (2 * step);
  }
  return jacobian;
}

}  // namespace selfcal
