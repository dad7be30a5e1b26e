#include "identification/identifiability.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

#include <Eigen/Dense>

#include "base/status.h"
#include "identification/relative_pose_residual.h"
#include "kinematics/autodiff_jacobian.h"

namespace selfcal::identification {

namespace {

void CheckInputs(const RobotModel& model, const Eigen::VectorXd& rho, const std::vector<Eigen::VectorXd>& joint_poses,
                 int reference_index, double sigma_position_m, double sigma_rotation_rad) {
  SELFCAL_CHECK(rho.size() == model.num_parameters(),
                "rho has " << rho.size() << " entries, the model needs " << model.num_parameters());
  SELFCAL_CHECK(reference_index >= 0 && reference_index < static_cast<int>(joint_poses.size()),
                "reference index " << reference_index << " outside [0, " << joint_poses.size() << ")");
  for (size_t i = 0; i < joint_poses.size(); ++i) {
    SELFCAL_CHECK(joint_poses[i].size() == model.num_joints(), "joint pose " << i << " has " << joint_poses[i].size()
                                                                             << " angles, the robot "
                                                                             << model.num_joints());
  }
  SELFCAL_CHECK(std::isfinite(sigma_position_m) && sigma_position_m > 0, "sigma_position_m = " << sigma_position_m);
  SELFCAL_CHECK(std::isfinite(sigma_rotation_rad) && sigma_rotation_rad > 0,
                "sigma_rotation_rad = " << sigma_rotation_rad);
}

// "0.71 j2.d - 0.71 j3.d": terms above 0.05 in magnitude, largest first (ties in parameter order), sign
// chosen so that the leading term is positive.
std::string FormatCombination(const Eigen::VectorXd& v, const std::vector<std::string>& names) {
  std::vector<int> order(v.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(v[a]) > std::abs(v[b]); });
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

// Column order of the greedy selection (column = rho index + offset; column 0 is the scale when
// offset is 1). Plain rho order would fix poor representatives: d_i instead of beta_i for a
// non-parallel pair with a small common normal (PUMA joint 4, where theta_3 + beta_4 then shows only
// through a_4 = 20 mm and the kept set is ~30x worse conditioned), and two camera parameters instead of
// the last joint's theta and d. So: the scale (a nuisance, always kept), the camera correction, the
// base, then alpha, a, theta, d joint by joint, and the Hayati betas last, which keeps the betas only
// where they are needed (nominally parallel axes) and lets the camera absorb the last joint's offsets.
std::vector<int> SelectionOrder(const KinematicParameters& params, int offset) {
  std::vector<int> order;
  for (int c = 0; c < offset; ++c) order.push_back(c);
  for (int k = 0; k < 6; ++k) order.push_back(offset + params.CamOffset() + k);
  for (int k = 0; k < 6; ++k) order.push_back(offset + KinematicParameters::BaseOffset() + k);
  const int kAlpha = 0, kA = 1, kBeta = 2, kTheta = 3, kD = 4;
  for (int j = 0; j < params.num_joints(); ++j) {
    for (int k : {kAlpha, kA, kTheta, kD}) order.push_back(offset + KinematicParameters::JointOffset(j) + k);
  }
  for (int j = 0; j < params.num_joints(); ++j) order.push_back(offset + KinematicParameters::JointOffset(j) + kBeta);
  return order;
}

}  // namespace

Eigen::MatrixXd RelativePoseJacobian(const RobotModel& model, const Eigen::VectorXd& rho,
                                     const std::vector<Eigen::VectorXd>& joint_poses, int reference_index,
                                     double sigma_position_m, double sigma_rotation_rad) {
  CheckInputs(model, rho, joint_poses, reference_index, sigma_position_m, sigma_rotation_rad);
  const int num_poses = static_cast<int>(joint_poses.size());
  // Measurements equal to the model: only the derivative matters and the residual is zero.
  const Rigid3 cam_ref_from_base = internal::CamRefFromBase<double>(model, rho.data(), joint_poses[reference_index]);
  std::vector<Rigid3> measured(num_poses);
  for (int i = 0; i < num_poses; ++i) measured[i] = cam_ref_from_base * BaseFromCam(model, rho, joint_poses[i]);

  const double inv_sp = 1.0 / sigma_position_m, inv_sr = 1.0 / sigma_rotation_rad;
  auto residuals = [&](const auto* x, auto* y) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(x)>>;
    const Rigid3T<T> ref_from_base = internal::CamRefFromBase<T>(model, x, joint_poses[reference_index]);
    int row = 0;
    for (int i = 0; i < num_poses; ++i) {
      if (i == reference_index) continue;
      internal::RelativePoseResidual<T>(model, x, ref_from_base, joint_poses[i], measured[i], true, inv_sp, inv_sr,
                                        y + row);
      row += 6;
    }
  };
  return AutodiffJacobian<8>(residuals, rho, 6 * (num_poses - 1));
}

IdentifiabilityReport AnalyzeIdentifiability(const RobotModel& model, const Eigen::VectorXd& rho,
                                             const std::vector<Eigen::VectorXd>& joint_poses, int reference_index,
                                             const IdentifiabilityOptions& options) {
  SELFCAL_CHECK(std::isfinite(options.rank_tolerance) && options.rank_tolerance > 0 && options.rank_tolerance < 1,
                "rank_tolerance = " << options.rank_tolerance << " must lie in (0, 1)");
  const Eigen::MatrixXd jacobian = RelativePoseJacobian(model, rho, joint_poses, reference_index,
                                                        options.sigma_position_m, options.sigma_rotation_rad);
  const int n = model.num_parameters();
  const int rows = static_cast<int>(jacobian.rows());
  const KinematicParameters params(model.num_joints());

  // Column 0 is the global scale of the measured translations when it is unknown: the residual
  // (t_model - s t_meas) / sigma has derivative -t_meas / sigma at s = 1, and t_meas = t_model here.
  const int offset = options.scale_known ? 0 : 1;
  const int cols = n + offset;
  std::vector<std::string> names;
  if (!options.scale_known) names.push_back("scale");
  names.insert(names.end(), params.names().begin(), params.names().end());
  Eigen::MatrixXd full(rows, cols);
  full.rightCols(n) = jacobian;
  if (!options.scale_known) {
    full.col(0).setZero();
    const Rigid3 cam_ref_from_base = internal::CamRefFromBase<double>(model, rho.data(), joint_poses[reference_index]);
    int row = 0;
    for (int i = 0; i < static_cast<int>(joint_poses.size()); ++i) {
      if (i == reference_index) continue;
      const Rigid3 rel = cam_ref_from_base * BaseFromCam(model, rho, joint_poses[i]);
      full.col(0).segment<3>(row + 3) = -rel.translation / options.sigma_position_m;
      row += 6;
    }
  }

  // Column normalisation. A column below the tolerance relative to the largest is a pure round-off
  // pattern (e.g. the base correction, which cancels exactly in relative poses): scaling it to unit
  // norm would fake rank, so it is set to zero instead.
  Eigen::VectorXd norms = full.colwise().norm().transpose();
  const double max_norm = cols > 0 && rows > 0 ? norms.maxCoeff() : 0.0;
  Eigen::MatrixXd normalized = Eigen::MatrixXd::Zero(rows, cols);
  std::vector<bool> zero_column(cols, true);
  for (int c = 0; c < cols; ++c) {
    if (max_norm > 0 && norms[c] > options.rank_tolerance * max_norm) {
      normalized.col(c) = full.col(c) / norms[c];
      zero_column[c] = false;
    }
  }

  IdentifiabilityReport report;
  report.num_parameters = n;
  Eigen::VectorXd sv;
  Eigen::MatrixXd v_full;
  if (rows > 0) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(normalized, Eigen::ComputeFullV);
    sv = svd.singularValues();
    v_full = svd.matrixV();
  }
  report.singular_values = sv;
  const double sigma_max = sv.size() > 0 ? sv[0] : 0.0;
  const double threshold = options.rank_tolerance * sigma_max;

  // Greedy selection by Gram-Schmidt with one re-orthogonalisation: a column is kept when its part
  // orthogonal to the kept ones exceeds the threshold. The order decides which member of each dependent
  // set is fixed; see SelectionOrder.
  Eigen::MatrixXd basis(rows, std::min(rows, cols));
  int num_basis = 0;
  std::vector<int> kept, dependent;
  for (int c : SelectionOrder(params, offset)) {
    bool keep = false;
    if (!zero_column[c] && sigma_max > 0 && num_basis < rows) {
      Eigen::VectorXd v = normalized.col(c);
      for (int pass = 0; pass < 2; ++pass) {
        const auto q = basis.leftCols(num_basis);
        v -= q * (q.transpose() * v);
      }
      const double residual = v.norm();
      if (residual > threshold) {
        basis.col(num_basis++) = v / residual;
        keep = true;
      }
    }
    (keep ? kept : dependent).push_back(c);
  }
  std::sort(kept.begin(), kept.end());
  std::sort(dependent.begin(), dependent.end());
  for (int c : kept) {
    if (c >= offset) report.free_indices.push_back(c - offset);
  }
  for (int c : dependent) {
    if (c >= offset) report.fixed_indices.push_back(c - offset);
  }
  report.rank = static_cast<int>(report.free_indices.size());
  for (int i : report.free_indices) report.free_names.push_back(params.name(i));
  for (int i : report.fixed_indices) report.fixed_names.push_back(params.name(i));

  // Condition number of the kept columns (scale included: it is estimated alongside).
  if (!kept.empty()) {
    Eigen::MatrixXd sub(rows, kept.size());
    for (size_t k = 0; k < kept.size(); ++k) sub.col(k) = normalized.col(kept[k]);
    const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(sub).singularValues();
    report.condition_number = s[s.size() - 1] > 0 ? s[0] / s[s.size() - 1] : std::numeric_limits<double>::infinity();
  } else {
    report.condition_number = std::numeric_limits<double>::infinity();
  }

  // Null space. Its dimension is set by the SVD; when it agrees with the greedy count, each dependent
  // column gives one readable direction (itself minus its expansion on the kept columns before it);
  // otherwise (a borderline tolerance) the SVD basis is written as it is.
  int svd_rank = 0;
  for (int k = 0; k < sv.size(); ++k) svd_rank += sv[k] > threshold ? 1 : 0;
  const int null_dim = cols - svd_rank;
  std::vector<Eigen::VectorXd> null_vectors;
  if (null_dim == static_cast<int>(dependent.size())) {
    for (int c : dependent) {
      const std::vector<int>& before = kept;
      Eigen::VectorXd x = Eigen::VectorXd::Zero(cols);
      x[c] = 1.0;
      if (!before.empty() && !zero_column[c]) {
        Eigen::MatrixXd sub(rows, before.size());
        for (size_t k = 0; k < before.size(); ++k) sub.col(k) = normalized.col(before[k]);
        const Eigen::VectorXd a = sub.colPivHouseholderQr().solve(normalized.col(c));
        for (size_t k = 0; k < before.size(); ++k) x[before[k]] = -a[k];
      }
      null_vectors.push_back(x.normalized());
    }
  } else if (v_full.size() > 0) {
    for (int k = svd_rank; k < cols; ++k) null_vectors.push_back(v_full.col(k));
  }
  for (const Eigen::VectorXd& x : null_vectors) report.null_combinations.push_back(FormatCombination(x, names));
  return report;
}

}  // namespace selfcal::identification
