#include "calibration/heldout_chi_square.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace selfcal::calibration {

namespace {

// ChiSquare::share from the LDLT of M's theta block after the dots' elimination, whose inverse is M^-1's.
void Shares(const Eigen::LDLT<Eigen::MatrixXd>& ldlt, double s2, const VarianceParts& parts, ChiSquare* result) {
  const Eigen::MatrixXd inverse = ldlt.solve(Eigen::MatrixXd::Identity(ldlt.rows(), ldlt.cols()));
  for (const VarianceBlock& b : parts.blocks) {
    const Eigen::Matrix<double, 6, 6> seen =
        Eigen::Matrix<double, 6, 6>::Identity() - s2 * inverse.block<6, 6>(b.column, b.column);
    for (int k = 0; k < 3; ++k) result->share[k] += b.e[k].cwiseProduct(seen.transpose()).sum();
  }
}

}  // namespace

// r^T C^-1 r over the residuals [begin, end), C = sigma^2 I + U U^T, by the Woodbury identity:
// (r^T r - b^T M^-1 b) / sigma^2 with M = U^T U + sigma^2 I and b = U^T r. M's dot part is block
// diagonal (3 x 3 per dot), so M^-1 b comes from the Schur complement on the theta block:
// O(residuals x theta^2 + theta^3), not O(dots^3) (the dense M had 3 x dots + theta rows); G^T G is one
// symmetric rank update over the range's rows, the dots' correction one product over the dots.
ChiSquare ChiSquareOf(int begin, int end, const Residuals& residuals, int num_dots, double sigma,
                      const VarianceParts* parts) {
  ChiSquare result;
  if (begin >= end) return result;
  const int nt = residuals.num_theta;
  const double s2 = sigma * sigma;
  const Eigen::Map<const RowMajor> g_rows(residuals.g.data() + static_cast<size_t>(2 * nt) * begin, 2 * (end - begin), nt);
  std::vector<Eigen::Matrix3d> mdd(num_dots, Eigen::Matrix3d::Zero());
  RowMajor mdt = RowMajor::Zero(3 * num_dots, nt);  // D_j^T G, 3 x theta per dot
  std::vector<Eigen::Vector3d> bd(num_dots, Eigen::Vector3d::Zero());
  std::vector<bool> seen(num_dots, false);
  Eigen::MatrixXd mtt = Eigen::MatrixXd::Zero(nt, nt);
  Eigen::VectorXd bt = Eigen::VectorXd::Zero(nt);
  Eigen::VectorXd r_rows(2 * (end - begin));
  double rr = 0;
  for (int k = begin; k < end; ++k) {
    const Residual& e = residuals.rows[k];
    seen[e.dot] = true;
    mdd[e.dot] += e.d.transpose() * e.d;
    mdt.middleRows<3>(3 * e.dot).noalias() += e.d.transpose().lazyProduct(g_rows.middleRows<2>(2 * (k - begin)));
    bd[e.dot] += e.d.transpose() * e.r;
    r_rows.segment<2>(2 * (k - begin)) = e.r;
    rr += e.r.squaredNorm();
  }
  if (nt > 0) {
    mtt.selfadjointView<Eigen::Lower>().rankUpdate(g_rows.transpose());
    bt.noalias() = g_rows.transpose() * r_rows;
  }
  mtt.diagonal().array() += s2;
  double quadratic = 0;  // b^T M^-1 b
  RowMajor k_all = RowMajor::Zero(3 * num_dots, nt);  // M_dd^-1 M_dt per dot
  Eigen::VectorXd y_all = Eigen::VectorXd::Zero(3 * num_dots);
  for (int j = 0; j < num_dots; ++j) {
    if (!seen[j]) continue;
    mdd[j].diagonal().array() += s2;
    const Eigen::LDLT<Eigen::Matrix3d> block(mdd[j]);
    k_all.middleRows<3>(3 * j) = block.solve(mdt.middleRows<3>(3 * j));
    const Eigen::Vector3d y = block.solve(bd[j]);
    y_all.segment<3>(3 * j) = y;
    quadratic += bd[j].dot(y);
  }
  if (nt > 0) {
    mtt.triangularView<Eigen::Lower>() -= mdt.transpose() * k_all;
    bt.noalias() -= mdt.transpose() * y_all;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt = mtt.selfadjointView<Eigen::Lower>().ldlt();
    quadratic += bt.dot(ldlt.solve(bt));
    if (parts != nullptr) Shares(ldlt, s2, *parts, &result);
  }
  result.value = (rr - quadratic) / s2;
  return result;
}


int DegreesOfFreedomOf(double relative_variance) {
  if (!(relative_variance > 0)) return 0;
  constexpr double kLargest = 1e8;  // beyond this the estimate is as good as known
  return static_cast<int>(std::lround(std::clamp(2.0 / relative_variance, 1.0, kLargest)));
}

int PoseNoiseDof(const ChiSquare& chi_square, const Eigen::Matrix4d& relative_covariance) {
  const Eigen::Vector3d s(chi_square.share[0], chi_square.share[1], chi_square.share[2]);
  const double total = s.sum();
  if (!(total > 0)) return 0;
  return DegreesOfFreedomOf(s.dot(relative_covariance.bottomRightCorner<3, 3>() * s) / (total * total));
}

}  // namespace selfcal::calibration
