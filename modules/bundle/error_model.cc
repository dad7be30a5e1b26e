#include "bundle/error_model.h"

#include <algorithm>
#include <cstdio>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace selfcal::bundle::internal {

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

// Theta's diagonal over `num_columns` pose columns (v, omega per pose): the model's variances.
Eigen::VectorXd PoseVariances(const ErrorModel& model, int num_columns) {
  Eigen::VectorXd theta(num_columns);
  for (int c = 0; c < num_columns; ++c) {
    const double sd = c % 6 < 3 ? model.pose_translation_m : model.pose_rotation_rad;
    theta[c] = sd * sd;
  }
  return theta;
}

}  // namespace

ErrorModel EstimateErrorModel(const Eigen::MatrixXd& reduced, int num_global, const Eigen::VectorXd& gradient,
                              double residual_sq, int dof, double sigma_px, const Eigen::VectorXd& global_gradient) {
  ErrorModel model;
  const int width = static_cast<int>(reduced.cols());
  const int num_poses = (width - num_global) / 6;
  if (num_poses < 2 || dof <= 0 || gradient.size() != 6 * num_poses || !(residual_sq > 0)) {
    model.message = "no redundancy to estimate a pose error from";
    return model;
  }
  const Eigen::MatrixXd normal = reduced.transpose() * reduced;
  // Variances: pixels in units of sigma_px^2, translations m^2, rotations rad^2 (starts: the residuals'
  // own pixel variance, 0.1 mm and 0.01 deg).
  double var_px = residual_sq / dof, var_t = 1e-8, var_r = 3e-8;
  const double floor_t = kTranslationFloorM * kTranslationFloorM, floor_r = kRotationFloorRad * kRotationFloorRad;
  Eigen::MatrixXd s, inverse;
  for (model.iterations = 1; model.iterations <= kMaxIterations; ++model.iterations) {
    const double w = 1.0 / var_px;
    s = w * normal;
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(width);
    rhs.tail(6 * num_poses) = w * gradient;
    if (global_gradient.size() == num_global) rhs.head(num_global) = w * global_gradient;
    for (int i = 0; i < num_poses; ++i) {
      for (int k = 0; k < 6; ++k) s(num_global + 6 * i + k, num_global + 6 * i + k) += 1.0 / (k < 3 ? var_t : var_r);
    }
    if (!InverseSpd(s, &inverse)) {
      model.message = "the pose-error normal matrix is not positive definite";
      return model;
    }
    const Eigen::VectorXd step = inverse * rhs;
    double sum_t = 0, sum_r = 0, trace_t = 0, trace_r = 0;
    for (int i = 0; i < num_poses; ++i) {
      for (int k = 0; k < 6; ++k) {
        const int c = num_global + 6 * i + k;
        (k < 3 ? sum_t : sum_r) += step[c] * step[c];
        (k < 3 ? trace_t : trace_r) += inverse(c, c);
      }
    }
    const double energy_px = w * residual_sq - step.dot(rhs) - sum_t / var_t - sum_r / var_r;
    const double red_t = 3.0 * num_poses - trace_t / var_t, red_r = 3.0 * num_poses - trace_r / var_r;
    const double red_px = dof - red_t - red_r;
    model.pixel_redundancy = red_px;
    model.translation_redundancy = red_t;
    model.rotation_redundancy = red_r;
    if (!(red_px > 0) || !(energy_px > 0)) {
      model.message = "the pixel residuals have no redundancy left beside the pose errors";
      return model;
    }
    const double new_px = var_px * energy_px / red_px;
    // A component whose redundancy has fallen far below one is absent (it only drifts further towards zero,
    // iteration after iteration): held at its floor from then on.
    const bool freeze = model.iterations >= kFreezeAfter;
    const double new_t = red_t > (freeze ? kFreezeRedundancy : 1e-9) ? std::max(sum_t / red_t, floor_t) : floor_t;
    const double new_r = red_r > (freeze ? kFreezeRedundancy : 1e-9) ? std::max(sum_r / red_r, floor_r) : floor_r;
    const auto settled = [](double a, double b, double floor) {
      return (a <= floor && b <= floor) || std::abs(std::sqrt(a) - std::sqrt(b)) <= kRelativeTolerance * std::sqrt(b);
    };
    const bool done = settled(new_px, var_px, 0) && settled(new_t, var_t, floor_t) && settled(new_r, var_r, floor_r);
    var_px = new_px;
    var_t = new_t;
    var_r = new_r;
    if (done) break;
  }
  model.iterations = std::min(model.iterations, kMaxIterations);
  model.estimated = true;
  model.pixel_px = sigma_px * std::sqrt(var_px);
  // A component resting on less than one degree of freedom is not seen in the data (without pose error the
  // iteration drifts towards zero with redundancies of a few hundredths): absent.
  model.pose_translation_m = var_t > floor_t && model.translation_redundancy >= kMinRedundancy ? std::sqrt(var_t) : 0.0;
  model.pose_rotation_rad = var_r > floor_r && model.rotation_redundancy >= kMinRedundancy ? std::sqrt(var_r) : 0.0;
  return model;
}

Eigen::MatrixXd ModelCovariance(const Eigen::MatrixXd& reduced, int num_global, const Eigen::MatrixXd& inverse,
                                const ErrorModel& model, double sigma_px, Eigen::MatrixXd* pose_part) {
  const double ratio = model.pixel_px / sigma_px;
  Eigen::MatrixXd covariance = ratio * ratio * inverse;
  const int num_pose_columns = static_cast<int>(reduced.cols()) - num_global;
  *pose_part = Eigen::MatrixXd::Zero(inverse.rows(), inverse.cols());
  if (num_pose_columns <= 0) return covariance;
  const Eigen::MatrixXd cross =
      inverse * (reduced.leftCols(num_global).transpose() * reduced.rightCols(num_pose_columns));
  *pose_part = cross * PoseVariances(model, num_pose_columns).asDiagonal() * cross.transpose();
  covariance += *pose_part;
  return covariance;
}

HeldValueTest TestHeldValues(const Eigen::MatrixXd& reduced, int num_free, const std::vector<std::string>& names,
                             const Eigen::VectorXd& gradient, const Eigen::VectorXd& norm_sq, const ErrorModel& model,
                             double sigma_px, double pixel_variance) {
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
  if (model.estimated && num_pose > 0) covariance += s_he * PoseVariances(model, num_pose).asDiagonal() * s_he.transpose();
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

}  // namespace selfcal::bundle::internal
