#include "identification/rank_selection.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "kinematics/robot_model.h"

namespace selfcal::identification {

// Terms above 0.05 in magnitude, largest first, leading sign positive.
std::string FormatCombination(const Eigen::VectorXd& v, const std::vector<std::string>& names) {
  std::vector<int> order(v.size());
  std::iota(order.begin(), order.end(), 0);
  // Terms by their printed weight, ties in column order, the first positive: a combination reads the same
  // whatever the round-off of its weights (0.71 a - 0.71 b, never flipping to 0.71 b - 0.71 a).
  const auto printed = [&](int i) { return std::lround(std::abs(v[i]) * 100.0); };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return printed(a) > printed(b); });
  const double sign = (!order.empty() && v[order[0]] < 0) ? -1.0 : 1.0;
  std::string out;
  for (int idx : order) {
    const double c = sign * v[idx];
    if (std::abs(c) <= 0.05) break;
    char buf[32];
    if (out.empty()) {
      std::snprintf(buf, sizeof(buf), "%.2f ", c);
    } else {
      std::snprintf(buf, sizeof(buf), " %c %.2f ", c < 0 ? '-' : '+', std::abs(c));
    }
    out += buf;
    out += names[idx];
  }
  return out;
}

Eigen::MatrixXd NormalizeColumns(const Eigen::MatrixXd& j, double tolerance, Eigen::VectorXd* norms,
                                 std::vector<bool>* zero) {
  *norms = j.colwise().norm().transpose();
  const double max_norm = norms->size() > 0 ? norms->maxCoeff() : 0.0;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(j.rows(), j.cols());
  zero->assign(j.cols(), true);
  for (int c = 0; c < j.cols(); ++c) {
    if (max_norm > 0 && (*norms)[c] > tolerance * max_norm) {
      out.col(c) = j.col(c) / (*norms)[c];
      (*zero)[c] = false;
    }
  }
  return out;
}

// Plain rho order would fix poor representatives: d_i instead of beta_i for a non-parallel pair with a
// small common normal (PUMA joint 4, where theta_3 + beta_4 then shows only through a_4 = 20 mm and the
// kept set is ~30x worse conditioned), and two camera parameters instead of the last joint's theta and d.
// So: the camera correction, the base, then alpha, a, theta, d joint by joint, and the Hayati betas last,
// which keeps the betas only where they are needed (nominally parallel axes) and lets the camera absorb
// the last joint's offsets.
std::vector<int> PreferredParameterOrder(int num_joints) {
  const KinematicParameters params(num_joints);
  std::vector<int> order;
  for (int k = 0; k < 6; ++k) order.push_back(params.CamOffset() + k);
  for (int k = 0; k < 6; ++k) order.push_back(KinematicParameters::BaseOffset() + k);
  const int kAlpha = 0, kA = 1, kBeta = 2, kTheta = 3, kD = 4;
  for (int j = 0; j < num_joints; ++j) {
    for (int k : {kAlpha, kA, kTheta, kD}) order.push_back(KinematicParameters::JointOffset(j) + k);
  }
  for (int j = 0; j < num_joints; ++j) order.push_back(KinematicParameters::JointOffset(j) + kBeta);
  return order;
}

namespace {

// *v minus its projection on the first num_basis columns of the orthonormal `basis`, re-orthogonalised once.
void OrthogonaliseAgainst(const Eigen::MatrixXd& basis, int num_basis, Eigen::VectorXd* v) {
  for (int pass = 0; pass < 2; ++pass) {
    const auto q = basis.leftCols(num_basis);
    *v -= q * (q.transpose() * *v);
  }
}

// The columns `which` of `m`, in that order.
Eigen::MatrixXd ColumnsOf(const Eigen::MatrixXd& m, const std::vector<int>& which) {
  Eigen::MatrixXd sub(m.rows(), which.size());
  for (size_t k = 0; k < which.size(); ++k) sub.col(k) = m.col(which[k]);
  return sub;
}

// The direction unit column c minus its least-squares expansion on the `kept` columns (qr: of those
// columns), normalised, over `cols` parameters: what the data cannot tell from the kept ones. With
// `expand` false (no kept column, or c is zero) the unit column alone.
Eigen::VectorXd NullDirection(const Eigen::ColPivHouseholderQR<Eigen::MatrixXd>& qr, const std::vector<int>& kept,
                              const Eigen::VectorXd& column, int c, int cols, bool expand) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(cols);
  x[c] = 1.0;
  if (expand) {
    const Eigen::VectorXd a = qr.solve(column);
    for (size_t k = 0; k < kept.size(); ++k) x[kept[k]] = -a[k];
  }
  return x.normalized();
}

}  // namespace

RankSelection SelectColumns(const Eigen::MatrixXd& jacobian, const std::vector<int>& order, double tolerance,
                            const std::vector<std::string>& names) {
  const int rows = static_cast<int>(jacobian.rows()), cols = static_cast<int>(jacobian.cols());
  Eigen::VectorXd norms;
  std::vector<bool> zero;
  const Eigen::MatrixXd normalized = NormalizeColumns(jacobian, tolerance, &norms, &zero);
  RankSelection out;
  Eigen::VectorXd sv;
  Eigen::MatrixXd v_full;
  if (rows > 0 && cols > 0) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(normalized, Eigen::ComputeFullV);
    sv = svd.singularValues();
    v_full = svd.matrixV();
  }
  out.singular_values = sv;
  const double sigma_max = sv.size() > 0 ? sv[0] : 0.0;
  const double threshold = tolerance * sigma_max;
  Eigen::MatrixXd basis(rows, std::min(rows, cols));
  int num_basis = 0;
  for (int c : order) {
    bool keep = false;
    if (!zero[c] && sigma_max > 0 && num_basis < rows) {
      Eigen::VectorXd v = normalized.col(c);
      OrthogonaliseAgainst(basis, num_basis, &v);
      const double residual = v.norm();
      if (residual > threshold) {
        basis.col(num_basis++) = v / residual;
        keep = true;
      }
    }
    (keep ? out.kept : out.dependent).push_back(c);
  }
  std::sort(out.kept.begin(), out.kept.end());
  std::sort(out.dependent.begin(), out.dependent.end());
  if (!out.kept.empty()) {
    const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(ColumnsOf(normalized, out.kept)).singularValues();
    out.condition_number =
        s[s.size() - 1] > 0 ? s[0] / s[s.size() - 1] : std::numeric_limits<double>::infinity();
  } else {
    out.condition_number = std::numeric_limits<double>::infinity();
  }
  // One readable null direction per dependent column (itself minus its expansion on the kept ones) when
  // the SVD agrees on the dimension; otherwise the SVD's own basis.
  int svd_rank = 0;
  for (int k = 0; k < sv.size(); ++k) svd_rank += sv[k] > threshold ? 1 : 0;
  std::vector<Eigen::VectorXd> null_vectors;
  if (cols - svd_rank == static_cast<int>(out.dependent.size())) {
    // Eigen's QR of a matrix without columns reads past its ends: nothing kept, nothing to expand on.
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr;
    if (!out.kept.empty()) qr.compute(ColumnsOf(normalized, out.kept));
    for (int c : out.dependent) {
      null_vectors.push_back(NullDirection(qr, out.kept, normalized.col(c), c, cols, !out.kept.empty() && !zero[c]));
    }
  } else if (v_full.size() > 0) {
    for (int k = svd_rank; k < cols; ++k) null_vectors.push_back(v_full.col(k));
  }
  for (const Eigen::VectorXd& x : null_vectors) out.null_combinations.push_back(FormatCombination(x, names));
  return out;
}

std::vector<WeakColumn> FindWeakColumns(const Eigen::MatrixXd& whitened, const std::vector<int>& order,
                                        const Eigen::VectorXd& tolerance, const std::vector<std::string>& names) {
  const int rows = static_cast<int>(whitened.rows()), cols = static_cast<int>(whitened.cols());
  Eigen::MatrixXd normalized = whitened;  // for the combinations
  for (int c = 0; c < cols; ++c) {
    if (whitened.col(c).norm() > 0) normalized.col(c) = whitened.col(c) / whitened.col(c).norm();
  }
  std::vector<WeakColumn> weak;
  Eigen::MatrixXd basis(rows, std::min<int>(rows, static_cast<int>(order.size())));
  std::vector<int> kept;
  for (int c : order) {
    Eigen::VectorXd v = whitened.col(c);
    const double norm = v.norm();
    const int num_basis = static_cast<int>(kept.size());
    OrthogonaliseAgainst(basis, num_basis, &v);
    const double residual = v.norm();
    const double conditional_std = residual > 0 ? 1.0 / residual : std::numeric_limits<double>::infinity();
    if (tolerance[c] > 0 && conditional_std > tolerance[c]) {
      // The column on the earlier kept ones, all normalised: the direction the data cannot see.
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr;
      if (!kept.empty()) qr.compute(ColumnsOf(normalized, kept));
      const Eigen::VectorXd x = NullDirection(qr, kept, normalized.col(c), c, cols, !kept.empty() && norm > 0);
      weak.push_back({c, conditional_std, tolerance[c], FormatCombination(x, names)});
      continue;
    }
    if (residual > 0 && num_basis < rows) {
      basis.col(num_basis) = v / residual;
      kept.push_back(c);
    }
  }
  return weak;
}

}  // namespace selfcal::identification
