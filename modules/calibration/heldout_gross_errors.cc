#include "calibration/heldout_gross_errors.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

#include <Eigen/Cholesky>

namespace selfcal::calibration::internal {
namespace {

// The rows of a pose's block that are still in, and the largest statistic among them given each other:
// (statistic, row), or (0, -1) when none is in.
std::pair<double, int> WorstOfPose(double sigma, const Residuals& residuals, const std::vector<int>& rows) {
  const int width = residuals.num_theta;
  const int m = static_cast<int>(rows.size());
  if (m == 0) return {0.0, -1};
  Eigen::MatrixXd u(2 * m, width);
  Eigen::MatrixXd c = sigma * sigma * Eigen::MatrixXd::Identity(2 * m, 2 * m);
  Eigen::VectorXd r(2 * m);
  for (int i = 0; i < m; ++i) {
    const int k = rows[i];
    const Residual& e = residuals.rows[k];
    if (width > 0) {
      u.middleRows<2>(2 * i) =
          Eigen::Map<const RowMajor>(residuals.g.data() + static_cast<size_t>(2 * width) * k, 2, width);
    }
    c.block<2, 2>(2 * i, 2 * i) += e.d * e.d.transpose();  // a pose sees each dot once
    r.segment<2>(2 * i) = e.r;
  }
  if (width > 0) c.noalias() += u * u.transpose();
  const Eigen::MatrixXd inverse = c.ldlt().solve(Eigen::MatrixXd::Identity(2 * m, 2 * m));
  const Eigen::VectorXd w = inverse * r;
  std::pair<double, int> worst = {0.0, -1};
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector2d wk = w.segment<2>(2 * i);
    const double statistic = wk.dot(inverse.block<2, 2>(2 * i, 2 * i).ldlt().solve(wk));
    if (statistic > worst.first) worst = {statistic, rows[i]};
  }
  return worst;
}

}  // namespace

void ScreenGrossErrors(double sigma, Residuals* residuals, std::vector<int>* first_row_of_pose,
                       std::vector<ObservedResidual>* observed, std::vector<ObservedResidual>* gross) {
  const int width = residuals->num_theta;
  const int n = static_cast<int>(residuals->rows.size());
  const int most = static_cast<int>(std::floor(kMaxGrossErrorShare * n));
  const size_t num_poses = first_row_of_pose->empty() ? 0 : first_row_of_pose->size() - 1;
  std::vector<std::vector<int>> in(num_poses);  // the rows still in, per pose
  std::vector<std::pair<double, int>> worst(num_poses);
  for (size_t s = 0; s < num_poses; ++s) {
    for (int k = (*first_row_of_pose)[s]; k < (*first_row_of_pose)[s + 1]; ++k) in[s].push_back(k);
    if (most > 0) worst[s] = WorstOfPose(sigma, *residuals, in[s]);
  }
  std::vector<bool> out(n, false);
  for (int removed = 0; removed < most && num_poses > 0; ++removed) {
    size_t pose = 0;
    for (size_t s = 1; s < num_poses; ++s) {
      if (worst[s].first > worst[pose].first) pose = s;
    }
    if (!(worst[pose].first > kGrossErrorChiSquare)) break;
    const int k = worst[pose].second;
    out[k] = true;
    in[pose].erase(std::find(in[pose].begin(), in[pose].end(), k));
    worst[pose] = WorstOfPose(sigma, *residuals, in[pose]);
  }
  Residuals kept;
  kept.num_theta = width;
  std::vector<ObservedResidual> kept_observed;
  std::vector<int> first(first_row_of_pose->size(), 0);
  size_t pose = 0;
  for (int k = 0; k < n; ++k) {
    while (pose < first_row_of_pose->size() && (*first_row_of_pose)[pose] <= k) {
      first[pose++] = static_cast<int>(kept.rows.size());
    }
    if (out[k]) {
      gross->push_back((*observed)[k]);
      continue;
    }
    kept.rows.push_back(residuals->rows[k]);
    kept.g.insert(kept.g.end(), residuals->g.begin() + static_cast<std::ptrdiff_t>(2 * width) * k,
                  residuals->g.begin() + static_cast<std::ptrdiff_t>(2 * width) * (k + 1));
    kept_observed.push_back((*observed)[k]);
  }
  while (pose < first_row_of_pose->size()) first[pose++] = static_cast<int>(kept.rows.size());
  *residuals = std::move(kept);
  *observed = std::move(kept_observed);
  *first_row_of_pose = std::move(first);
}

}  // namespace selfcal::calibration::internal
