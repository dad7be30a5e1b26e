#include "bundle/error_model.h"

#include <algorithm>
#include <cstdio>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace selfcal::bundle {

Eigen::Matrix<double, 6, 6> PoseErrorCovariance(double translation_m, double rotation_rad, double joint_rad,
                                                const Eigen::MatrixXd& camera_motion_per_joint) {
  const auto variance = [](double sd) { return sd > 0 ? sd * sd : 0.0; };
  Eigen::Matrix<double, 6, 6> theta = Eigen::Matrix<double, 6, 6>::Zero();
  theta.diagonal() << Eigen::Vector3d::Constant(variance(translation_m)), Eigen::Vector3d::Constant(variance(rotation_rad));
  if (joint_rad > 0 && camera_motion_per_joint.rows() == 6) {
    theta += variance(joint_rad) * camera_motion_per_joint * camera_motion_per_joint.transpose();
  }
  return theta;
}

namespace internal {

namespace {

// Below these the pose error moves no dot by a thousandth of a pixel: the component is taken as absent.
constexpr double kTranslationFloorM = 1e-6;
constexpr double kRotationFloorRad = 1e-6;
constexpr int kMaxIterations = 40;
constexpr int kFreezeAfter = 3;
constexpr double kFreezeRedundancy = 0.1;
constexpr double kRelativeTolerance = 1e-3;  // on the standard deviations
constexpr double kMinRedundancy = 1.0;

// The inverse of a symmetric positive definite matrix, Jacobi-scaled (the prior's weights and the
// pixels' differ by many orders of magnitude). False when it is not positive definite.
bool InverseSpd(const Eigen::MatrixXd& s, Eigen::MatrixXd* inverse) {
  const Eigen::VectorXd scale = s.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = scale.asDiagonal() * s * scale.asDiagonal();
  const Eigen::LLT<Eigen::MatrixXd> llt(scaled);
  if (llt.info() != Eigen::Success) return false;
  *inverse = scale.asDiagonal() * llt.solve(Eigen::MatrixXd::Identity(s.rows(), s.cols())) * scale.asDiagonal();
  return inverse->allFinite();
}

// The joint component's columns beside the pose columns, pose i's pose columns times A_i, and their
// gradient; false (nothing added) when joint_motion does not hold one 6 x n matrix per pose.
bool AddJointColumns(const Eigen::MatrixXd& reduced, int num_global, const Eigen::VectorXd& gradient,
                     const std::vector<Eigen::MatrixXd>& joint_motion, Eigen::MatrixXd* work, Eigen::VectorXd* work_gradient) {
  const int num_poses = (static_cast<int>(reduced.cols()) - num_global) / 6;
  if (static_cast<int>(joint_motion.size()) != num_poses || num_poses == 0) return false;
  const Eigen::Index n = joint_motion.front().cols();
  for (const Eigen::MatrixXd& a : joint_motion) {
    if (a.rows() != 6 || a.cols() != n || !a.allFinite()) return false;
  }
  if (n == 0) return false;
  const Eigen::Index width = reduced.cols();
  work->resize(reduced.rows(), width + n * num_poses);
  work->leftCols(width) = reduced;
  work_gradient->resize(width - num_global + n * num_poses);
  work_gradient->head(width - num_global) = gradient;
  for (int i = 0; i < num_poses; ++i) {
    work->middleCols(width + n * i, n) = reduced.middleCols(num_global + 6 * i, 6) * joint_motion[i];
    work_gradient->segment(width - num_global + n * i, n) = joint_motion[i].transpose() * gradient.segment<6>(6 * i);
  }
  return true;
}

// The pose part S_ge Theta S_eg of a covariance from cross = the columns' products with the pose columns,
// Theta_i per pose (6 columns each).
Eigen::MatrixXd PosePart(const Eigen::MatrixXd& cross, const ErrorModel& model,
                         const std::vector<Eigen::MatrixXd>& joint_motion) {
  const int num_poses = static_cast<int>(cross.cols()) / 6;
  const bool joints = static_cast<int>(joint_motion.size()) == num_poses;
  Eigen::MatrixXd part = Eigen::MatrixXd::Zero(cross.rows(), cross.rows());
  for (int i = 0; i < num_poses; ++i) {
    const Eigen::Matrix<double, 6, 6> theta = PoseErrorCovariance(
        model.pose_translation_m, model.pose_rotation_rad, joints ? model.joint_rad : 0.0,
        joints ? joint_motion[i] : Eigen::MatrixXd());
    part.noalias() += cross.middleCols<6>(6 * i) * theta * cross.middleCols<6>(6 * i).transpose();
  }
  return part;
}

// ErrorModel::relative_covariance from the last iteration's normal matrix s (pixel weight w on `normal`, the
// priors 1 / var[g] on the extra columns) and its inverse q; rows: residual rows with the dots eliminated.
// With W = Sigma^-1 - Sigma^-1 A q A^T Sigma^-1 over the pixels and the pose errors' pseudo-observations,
// every trace reduces to the unknowns' space: M = w normal,
//   S_pp = w^2 (rows - 2 tr(q M) + tr(q M q M)),   S_pg = w p_g^2 tr(q_g. M q_.g),
//   S_gg = p_g^2 (n_g - 2 p_g tr(q_gg) + p_g^2 |q_gg|^2),   S_gh = p_g^2 p_h^2 |q_gh|^2.
Eigen::Matrix4d RelativeVarianceCovariance(const Eigen::MatrixXd& normal, int num_global, const std::vector<int>& group,
                                           double var_px, const double var[3], const bool active[3], double rows,
                                           const Eigen::MatrixXd& q) {
  const double w = 1.0 / var_px;
  const Eigen::MatrixXd m = w * normal;
  const Eigen::MatrixXd qm = q * m;
  std::vector<int> members[3];
  for (size_t c = 0; c < group.size(); ++c) members[group[c]].push_back(num_global + static_cast<int>(c));
  const auto block = [&](const Eigen::MatrixXd& a, int g, int h) {
    Eigen::MatrixXd b(members[g].size(), members[h].size());
    for (size_t i = 0; i < members[g].size(); ++i) {
      for (size_t j = 0; j < members[h].size(); ++j) b(i, j) = a(members[g][i], members[h][j]);
    }
    return b;
  };
  Eigen::Matrix4d s = Eigen::Matrix4d::Zero();
  s(0, 0) = w * w * (rows - 2 * qm.trace() + (qm * qm).trace());
  const Eigen::MatrixXd qmq = qm * q;
  std::vector<int> used = {0};
  for (int g = 0; g < 3; ++g) {
    if (!active[g] || members[g].empty()) continue;
    const double p = 1.0 / var[g];
    s(0, g + 1) = s(g + 1, 0) = w * p * p * block(qmq, g, g).trace();
    const Eigen::MatrixXd qgg = block(q, g, g);
    s(g + 1, g + 1) = p * p * (members[g].size() - 2 * p * qgg.trace() + p * p * qgg.squaredNorm());
    for (int h : used) {
      if (h == 0) continue;
      s(g + 1, h) = s(h, g + 1) = p * p * std::pow(1.0 / var[h - 1], 2) * block(q, g, h - 1).squaredNorm();
    }
    used.push_back(g + 1);
  }
  const double value[4] = {var_px, var[0], var[1], var[2]};
  Eigen::MatrixXd sub(used.size(), used.size());
  for (size_t i = 0; i < used.size(); ++i) {
    for (size_t j = 0; j < used.size(); ++j) sub(i, j) = s(used[i], used[j]) * value[used[i]] * value[used[j]];
  }
  Eigen::MatrixXd inverse;
  Eigen::Matrix4d relative = Eigen::Matrix4d::Zero();
  if (!InverseSpd(sub, &inverse)) return relative;
  for (size_t i = 0; i < used.size(); ++i) {
    for (size_t j = 0; j < used.size(); ++j) relative(used[i], used[j]) = 2 * inverse(i, j);
  }
  return relative;
}

}  // namespace

ErrorModel EstimateErrorModel(const Eigen::MatrixXd& reduced, int num_global, const Eigen::VectorXd& gradient,
                              double residual_sq, int dof, double sigma_px, const Eigen::VectorXd& global_gradient,
                              const std::vector<Eigen::MatrixXd>& joint_motion) {
  ErrorModel model;
  const int num_poses = (static_cast<int>(reduced.cols()) - num_global) / 6;
  if (num_poses < 2 || dof <= 0 || gradient.size() != 6 * num_poses || !(residual_sq > 0)) {
    model.message = "no redundancy to estimate a pose error from";
    return model;
  }
  // Unknowns after the globals: 6 per pose (group 0 translation, 1 rotation), then a joint set's n per pose
  // (group 2).
  Eigen::MatrixXd work;
  Eigen::VectorXd work_gradient;
  const bool joints = AddJointColumns(reduced, num_global, gradient, joint_motion, &work, &work_gradient);
  const Eigen::MatrixXd& columns = joints ? work : reduced;
  const Eigen::VectorXd& extra_gradient = joints ? work_gradient : gradient;
  const int width = static_cast<int>(columns.cols()), num_extra = width - num_global;
  std::vector<int> group(num_extra);
  for (int c = 0; c < num_extra; ++c) group[c] = c >= 6 * num_poses ? 2 : c % 6 < 3 ? 0 : 1;
  const Eigen::MatrixXd normal = columns.transpose() * columns;
  // Variances: pixels in units of sigma_px^2, translations m^2, rotations and joints rad^2 (starts: the
  // residuals' own pixel variance, 0.1 mm, 0.01 deg, 0.01 deg).
  double var_px = residual_sq / dof;
  double var[3] = {1e-8, 3e-8, 3e-8};
  const double floor[3] = {kTranslationFloorM * kTranslationFloorM, kRotationFloorRad * kRotationFloorRad,
                           kRotationFloorRad * kRotationFloorRad};
  const int num_groups = joints ? 3 : 2;
  double red[3] = {0, 0, 0};
  Eigen::MatrixXd s, inverse;
  for (model.iterations = 1; model.iterations <= kMaxIterations; ++model.iterations) {
    const double w = 1.0 / var_px;
    s = w * normal;
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(width);
    rhs.tail(num_extra) = w * extra_gradient;
    if (global_gradient.size() == num_global) rhs.head(num_global) = w * global_gradient;
    for (int c = 0; c < num_extra; ++c) s(num_global + c, num_global + c) += 1.0 / var[group[c]];
    if (!InverseSpd(s, &inverse)) {
      model.message = "the pose-error normal matrix is not positive definite";
      return model;
    }
    const Eigen::VectorXd step = inverse * rhs;
    double sum[3] = {0, 0, 0}, trace[3] = {0, 0, 0}, count[3] = {0, 0, 0};
    for (int c = 0; c < num_extra; ++c) {
      const int k = num_global + c;
      sum[group[c]] += step[k] * step[k];
      trace[group[c]] += inverse(k, k);
      count[group[c]] += 1;
    }
    double energy_px = w * residual_sq - step.dot(rhs), red_px = dof;
    for (int g = 0; g < num_groups; ++g) {
      energy_px -= sum[g] / var[g];
      red[g] = count[g] - trace[g] / var[g];
      red_px -= red[g];
    }
    model.pixel_redundancy = red_px;
    if (!(red_px > 0) || !(energy_px > 0)) {
      model.message = "the pixel residuals have no redundancy left beside the pose errors";
      return model;
    }
    const double new_px = var_px * energy_px / red_px;
    const auto settled = [](double a, double b, double floor) {
      return (a <= floor && b <= floor) || std::abs(std::sqrt(a) - std::sqrt(b)) <= kRelativeTolerance * std::sqrt(b);
    };
    bool done = settled(new_px, var_px, 0);
    var_px = new_px;
    // A component whose redundancy has fallen far below one is absent (it only drifts further towards zero,
    // iteration after iteration): held at its floor from then on.
    const bool freeze = model.iterations >= kFreezeAfter;
    for (int g = 0; g < num_groups; ++g) {
      const double next = red[g] > (freeze ? kFreezeRedundancy : 1e-9) ? std::max(sum[g] / red[g], floor[g]) : floor[g];
      done = done && settled(next, var[g], floor[g]);
      var[g] = next;
    }
    if (done) break;
  }
  model.iterations = std::min(model.iterations, kMaxIterations);
  model.estimated = true;
  {
    bool active[3];
    for (int g = 0; g < 3; ++g) active[g] = g < num_groups && var[g] > floor[g] && red[g] >= kMinRedundancy;
    model.relative_covariance = RelativeVarianceCovariance(normal, num_global, group, var_px, var, active,
                                                           static_cast<double>(dof) + num_global, inverse);
  }
  model.pixel_px = sigma_px * std::sqrt(var_px);
  model.translation_redundancy = red[0];
  model.rotation_redundancy = red[1];
  // A component resting on less than one degree of freedom is not seen in the data (without pose error the
  // iteration drifts towards zero with redundancies of a few hundredths): absent.
  const auto size = [&](int g) { return var[g] > floor[g] && red[g] >= kMinRedundancy ? std::sqrt(var[g]) : 0.0; };
  model.pose_translation_m = size(0);
  model.pose_rotation_rad = size(1);
  if (joints) {
    model.joint_redundancy = red[2];
    model.joint_rad = size(2);
  }
  return model;
}

Eigen::MatrixXd ModelCovariance(const Eigen::MatrixXd& reduced, int num_global, const Eigen::MatrixXd& inverse,
                                const ErrorModel& model, double sigma_px, Eigen::MatrixXd* pose_part,
                                const std::vector<Eigen::MatrixXd>& joint_motion) {
  const double ratio = model.pixel_px / sigma_px;
  Eigen::MatrixXd covariance = ratio * ratio * inverse;
  const int num_pose_columns = static_cast<int>(reduced.cols()) - num_global;
  *pose_part = Eigen::MatrixXd::Zero(inverse.rows(), inverse.cols());
  if (num_pose_columns <= 0) return covariance;
  const Eigen::MatrixXd cross =
      inverse * (reduced.leftCols(num_global).transpose() * reduced.rightCols(num_pose_columns));
  *pose_part = PosePart(cross, model, joint_motion);
  covariance += *pose_part;
  return covariance;
}

HeldValueTest TestHeldValues(const Eigen::MatrixXd& reduced, int num_free, const std::vector<std::string>& names,
                             const Eigen::VectorXd& gradient, const Eigen::VectorXd& norm_sq, const ErrorModel& model,
                             double sigma_px, double pixel_variance, const std::vector<Eigen::MatrixXd>& joint_motion) {
  HeldValueTest test;
  const int num_held = static_cast<int>(names.size());
  const int num_pose = static_cast<int>(reduced.cols()) - num_free - num_held;
  if (num_held == 0 || num_pose < 0 || gradient.size() != num_held || norm_sq.size() != num_held) return test;
  const Eigen::MatrixXd a = reduced.transpose() * reduced;
  const Eigen::MatrixXd a_ff = a.topLeftCorner(num_free, num_free);
  Eigen::MatrixXd a_ff_inverse;
  if (num_free > 0 && !InverseSpd(a_ff, &a_ff_inverse)) return test;
  // The held and pose columns with the free ones projected out.
  const Eigen::MatrixXd rest = a.block(num_free, num_free, num_held + num_pose, num_held + num_pose) -
                               (num_free > 0 ? Eigen::MatrixXd(a.block(num_free, 0, num_held + num_pose, num_free) *
                                                               a_ff_inverse * a.block(0, num_free, num_free, num_held + num_pose))
                                             : Eigen::MatrixXd::Zero(num_held + num_pose, num_held + num_pose));
  const Eigen::MatrixXd s_hh = rest.topLeftCorner(num_held, num_held);
  const Eigen::MatrixXd s_he = rest.topRightCorner(num_held, num_pose);
  const double var_px = model.estimated ? (model.pixel_px / sigma_px) * (model.pixel_px / sigma_px) : pixel_variance;
  Eigen::MatrixXd covariance = var_px * s_hh;
  if (model.estimated && num_pose > 0) covariance += PosePart(s_he, model, joint_motion);
  // A held column in the span of the free ones and the dots (the gauge's, or one the poses cannot see)
  // carries no information: left out.
  // (Its squared norm after the eliminations is then ~1e-15 of its norm before them.)
  constexpr double kSeenFraction = 1e-8;
  std::vector<int> seen;
  for (int h = 0; h < num_held; ++h) {
    if (s_hh(h, h) > kSeenFraction * norm_sq[h] && covariance(h, h) > 0) seen.push_back(h);
  }
  if (seen.empty()) return test;
  const int n = static_cast<int>(seen.size());
  Eigen::MatrixXd c(n, n);
  Eigen::VectorXd g(n), scale(n);
  for (int i = 0; i < n; ++i) {
    scale[i] = 1.0 / std::sqrt(covariance(seen[i], seen[i]));
    g[i] = gradient[seen[i]] * scale[i];
    for (int j = 0; j < n; ++j) c(i, j) = covariance(seen[i], seen[j]) * scale[i] * scale[j];
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(c);
  const double top = eigen.eigenvalues().maxCoeff();
  test.chi_square = 0;
  for (int k = 0; k < n; ++k) {
    if (!(eigen.eigenvalues()[k] > 1e-10 * top)) continue;
    const double projection = eigen.eigenvectors().col(k).dot(g);
    test.chi_square += projection * projection / eigen.eigenvalues()[k];
    ++test.dof;
  }
  int worst = 0;
  for (int i = 0; i < n; ++i) {
    test.names.push_back(names[seen[i]]);
    if (std::abs(g[i]) > std::abs(g[worst])) worst = i;
  }
  char words[160];
  std::snprintf(words, sizeof words, "%s (its own score %.1f sigma)", names[seen[worst]].c_str(), std::abs(g[worst]));
  test.largest = words;
  test.tested = test.dof > 0;
  return test;
}

}  // namespace internal
}  // namespace selfcal::bundle
