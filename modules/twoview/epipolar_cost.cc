// AnalyticEpipolarCost: EpipolarCost's residuals (epipolar_cost.h) and their Jacobian in closed form.
#include "twoview/epipolar_cost.h"

#include <array>

namespace selfcal::twoview::internal {
namespace {

// Parameters, in the order of the Jacobian columns: 1/f_x, q_x, q_y, q_z, q_w, t_x, t_y, t_z.
constexpr int kNumParameters = 8;
using Row = std::array<double, kNumParameters>;

// dR/dq of Eigen's toRotationMatrix (tx = 2 q_x, R(0, 0) = 1 - (ty q_y + tz q_z), ...), which holds for
// an unnormalised quaternion too; entry [j] is the derivative with respect to coefficient j (x, y, z, w).
std::array<Eigen::Matrix3d, 4> RotationDerivatives(double x, double y, double z, double w) {
  std::array<Eigen::Matrix3d, 4> d;
  d[0] << 0, 2 * y, 2 * z, 2 * y, -4 * x, -2 * w, 2 * z, 2 * w, -4 * x;
  d[1] << -4 * y, 2 * x, 2 * w, 2 * x, 0, 2 * z, -2 * w, 2 * z, -4 * y;
  d[2] << -4 * z, -2 * w, 2 * x, 2 * w, -4 * z, 2 * y, 2 * x, 2 * y, 0;
  d[3] << 0, -2 * z, 2 * y, 2 * z, 0, -2 * x, -2 * y, 2 * x, 0;
  return d;
}

}  // namespace

AnalyticEpipolarCost::AnalyticEpipolarCost(const Correspondences& data, const std::vector<int>& indices, double mu,
                                           double huber_px)
    : mu_(mu), huber_(huber_px) {
  m1_.reserve(indices.size());
  m2_.reserve(indices.size());
  for (int i : indices) {
    m1_.push_back(data.centred1[i]);
    m2_.push_back(data.centred2[i]);
  }
  set_num_residuals(2 * static_cast<int>(m1_.size()));
  mutable_parameter_block_sizes()->assign({1, 4, 3});
}

bool AnalyticEpipolarCost::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const double s = parameters[0][0];
  const double* qc = parameters[1];
  const Eigen::Map<const Eigen::Quaterniond> q(qc);
  const Eigen::Vector3d t(parameters[2][0], parameters[2][1], parameters[2][2]);
  const Eigen::Matrix3d r = q.toRotationMatrix();
  const Eigen::Matrix3d e = Skew<double>(t) * r;
  const double inv_mu_sq = 1.0 / (mu_ * mu_);
  const double huber_sq = huber_ * huber_;
  const bool want_jacobian =
      jacobians != nullptr && (jacobians[0] != nullptr || jacobians[1] != nullptr || jacobians[2] != nullptr);
  // dE/dp for p = q_x .. t_z (E does not depend on 1/f_x): [t]x dR/dq_j, then [e_i]x R.
  std::array<Eigen::Matrix3d, kNumParameters - 1> de;
  if (want_jacobian) {
    const std::array<Eigen::Matrix3d, 4> dr = RotationDerivatives(qc[0], qc[1], qc[2], qc[3]);
    const Eigen::Matrix3d skew_t = Skew<double>(t);
    for (int j = 0; j < 4; ++j) de[j] = skew_t * dr[j];
    for (int i = 0; i < 3; ++i) de[4 + i] = Skew<double>(Eigen::Vector3d::Unit(i)) * r;
  }
  for (size_t k = 0; k < m1_.size(); ++k) {
    const Eigen::Vector3d x1(m1_[k].x() * s, m1_[k].y() * s, 1);  // A^-1 m
    const Eigen::Vector3d x2(m2_[k].x() * s, m2_[k].y() * s, 1);
    const Eigen::Vector3d ex1 = e * x1;
    const Eigen::Vector3d etx2 = e.transpose() * x2;
    const double algebraic = x2.dot(ex1);
    const double norm2_sq = ex1(0) * ex1(0) + inv_mu_sq * ex1(1) * ex1(1);
    const double norm1_sq = etx2(0) * etx2(0) + inv_mu_sq * etx2(1) * etx2(1);
    const double line2_sq = s * s * norm2_sq;
    const double line1_sq = s * s * norm1_sq;
    if (!(line2_sq > 0) || !(line1_sq > 0)) return false;  // a point on an epipole: no line
    const double line2 = std::sqrt(line2_sq), line1 = std::sqrt(line1_sq);
    double r2 = algebraic / line2;
    double r1 = algebraic / line1;
    const double sum_sq = r1 * r1 + r2 * r2;
    const bool beyond = sum_sq > huber_sq;
    double scale = 1;
    if (beyond) scale = std::sqrt((2 * huber_ * std::sqrt(sum_sq) - huber_sq) / sum_sq);
    residuals[2 * k] = r2 * scale;
    residuals[2 * k + 1] = r1 * scale;
    if (!want_jacobian) continue;

    // Derivatives of the algebraic residual and of the lines' first two coefficients (before the factor
    // s), for every parameter. Through E: d(E x1) = dE x1, d(E^T x2) = dE^T x2. Through 1/f_x:
    // dx1/ds = (m_x, m_y, 0).
    Row d_alg, d_e0, d_e1, d_f0, d_f1;
    const Eigen::Vector3d dx1(m1_[k].x(), m1_[k].y(), 0), dx2(m2_[k].x(), m2_[k].y(), 0);
    const Eigen::Vector3d e_dx1 = e * dx1;
    const Eigen::Vector3d et_dx2 = e.transpose() * dx2;
    d_alg[0] = dx2.dot(ex1) + x2.dot(e_dx1);
    d_e0[0] = e_dx1(0);
    d_e1[0] = e_dx1(1);
    d_f0[0] = et_dx2(0);
    d_f1[0] = et_dx2(1);
    for (int j = 0; j < kNumParameters - 1; ++j) {
      const Eigen::Vector3d u = de[j] * x1;
      d_alg[j + 1] = x2.dot(u);
      d_e0[j + 1] = u(0);
      d_e1[j + 1] = u(1);
      d_f0[j + 1] = de[j].col(0).dot(x2);
      d_f1[j + 1] = de[j].col(1).dot(x2);
    }
    // r = alg / (|s| n): dr = (d alg - r d(|s| n)) / (|s| n), with d(s^2 n^2) = 2 s ds n^2 + s^2 d(n^2).
    Row d_r2, d_r1;
    for (int p = 0; p < kNumParameters; ++p) {
      const double ds = p == 0 ? 1.0 : 0.0;
      const double d_line2_sq = 2 * s * ds * norm2_sq + s * s * 2 * (ex1(0) * d_e0[p] + inv_mu_sq * ex1(1) * d_e1[p]);
      const double d_line1_sq = 2 * s * ds * norm1_sq + s * s * 2 * (etx2(0) * d_f0[p] + inv_mu_sq * etx2(1) * d_f1[p]);
      d_r2[p] = (d_alg[p] - r2 * d_line2_sq / (2 * line2)) / line2;
      d_r1[p] = (d_alg[p] - r1 * d_line1_sq / (2 * line1)) / line1;
    }
    // Huber: out = c(S) r with S = r1^2 + r2^2, c^2 = 2 a S^-1/2 - a^2 S^-1, so
    // d out = c dr + r (dc/dS) 2 (r . dr), 2 dc/dS = (a^2 S^-2 - a S^-3/2) / c.
    double g = 0;
    if (beyond) g = (huber_sq / (sum_sq * sum_sq) - huber_ / (sum_sq * std::sqrt(sum_sq))) / scale;
    double* row2[3] = {nullptr, nullptr, nullptr};
    double* row1[3] = {nullptr, nullptr, nullptr};
    const int widths[3] = {1, 4, 3};
    for (int b = 0; b < 3; ++b) {
      if (jacobians[b] == nullptr) continue;
      row2[b] = jacobians[b] + (2 * k) * widths[b];
      row1[b] = jacobians[b] + (2 * k + 1) * widths[b];
    }
    for (int p = 0; p < kNumParameters; ++p) {
      const int b = p == 0 ? 0 : (p < 5 ? 1 : 2);
      if (row2[b] == nullptr) continue;
      const int col = p == 0 ? 0 : (p < 5 ? p - 1 : p - 5);
      const double dot = r1 * d_r1[p] + r2 * d_r2[p];
      row2[b][col] = scale * d_r2[p] + r2 * g * dot;
      row1[b][col] = scale * d_r1[p] + r1 * g * dot;
    }
  }
  return true;
}

}  // namespace selfcal::twoview::internal
