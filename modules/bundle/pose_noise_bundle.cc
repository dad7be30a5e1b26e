#include "bundle/pose_noise_bundle.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/SparseCore>
#include <ceres/ceres.h>

#include "bundle/small_solve.h"
#include "camera/camera.h"

namespace selfcal::bundle {

namespace {

// x0 is the hand-eye transform: flange_from_cam (eye-in-hand: the points in the base frame) or base_from_cam
// (eye_to_hand: the points in the flange frame, points_from_cam = (base_from_flange Exp(delta))^-1 x0 Exp(c)).
struct FlangeReprojection {
  FlangeReprojection(const Rigid3* base_from_flange, const Rigid3* x0, bool eye_to_hand, Eigen::Vector2d pixel, double sigma)
      : base_from_flange(base_from_flange), x0(x0), eye_to_hand(eye_to_hand), pixel(std::move(pixel)),
        inv_sigma(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* delta, const T* c, const T* dot, const T* intrinsics, T* residual) const {
    const Rigid3T<T> flange = base_from_flange->Cast<T>() * RigidFromTranslationRotvec(delta);
    const Rigid3T<T> hand_eye = x0->Cast<T>() * RigidFromTranslationRotvec(c);
    const Rigid3T<T> points_from_cam = eye_to_hand ? flange.Inverse() * hand_eye : flange * hand_eye;
    const Vec3T<T> in_cam = points_from_cam.Inverse() * Vec3T<T>(dot[0], dot[1], dot[2]);
    return internal::WhitenedReprojection<T>(intrinsics, in_cam, pixel, inv_sigma, residual);
  }
  const Rigid3* base_from_flange;
  const Rigid3* x0;
  bool eye_to_hand;
  Eigen::Vector2d pixel;
  double inv_sigma;
};

struct PosePrior {
  PosePrior(double st, double sr) : inv_t(1.0 / st), inv_r(1.0 / sr) {}
  template <typename T>
  bool operator()(const T* delta, T* residual) const {
    for (int k = 0; k < 3; ++k) residual[k] = delta[k] * T(inv_t);
    for (int k = 3; k < 6; ++k) residual[k] = delta[k] * T(inv_r);
    return true;
  }
  double inv_t, inv_r;
};

struct Length {
  Length(double length_m, double sigma_m) : length_m(length_m), inv_sigma(1.0 / sigma_m) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    residual[0] = ((Vec3T<T>(a[0], a[1], a[2]) - Vec3T<T>(b[0], b[1], b[2])).norm() - T(length_m)) * T(inv_sigma);
    return true;
  }
  double length_m, inv_sigma;
};

// The yardsticks with both ends among the solved dots.
std::vector<KnownDistance> LengthsAmong(const std::vector<KnownDistance>& yardsticks,
                                        const std::map<int, Eigen::Vector3d>& dots) {
  std::vector<KnownDistance> out;
  for (const KnownDistance& y : yardsticks) {
    if (dots.count(y.dot_a) && dots.count(y.dot_b) && y.dot_a != y.dot_b) out.push_back(y);
  }
  return out;
}

struct PoseObs {
  int pose = -1;
  int dot = -1;
  Eigen::Vector2d pixel;
};

// The covariance of the hand-eye correction `c` and of the estimated entries of the intrinsics block at the
// stated noises, and the standard deviations with it scaled by the residual variance s2; left NaN (and the
// covariance empty) when the normal matrix is singular. `others`: every other free block of the problem (dots,
// flange corrections), marginalised. The inverse of the dense normal matrix J^T J: O(unknowns^3), where Ceres'
// dense SVD of the whole Jacobian was O(residuals x unknowns^2) and most of the solve's time.
void Covariances(ceres::Problem* problem, double* c, double* intrinsics, const IntrinsicsMask& estimated,
                 const std::vector<double*>& others, double s2, PoseNoiseReport* report) {
  const std::vector<int> free = EstimatedIntrinsics(estimated);
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = {c};
  if (!free.empty()) evaluate.parameter_blocks.push_back(intrinsics);  // its tangent: the free entries, in order
  evaluate.parameter_blocks.insert(evaluate.parameter_blocks.end(), others.begin(), others.end());
  ceres::CRSMatrix crs;
  double cost = 0;
  if (!problem->Evaluate(evaluate, &cost, nullptr, nullptr, &crs)) return;
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor, int>> jacobian(
      crs.num_rows, crs.num_cols, static_cast<int>(crs.values.size()), crs.rows.data(), crs.cols.data(),
      crs.values.data());
  const Eigen::MatrixXd normal = Eigen::MatrixXd(jacobian.transpose() * jacobian);
  const int n = 6 + static_cast<int>(free.size());
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
  const Eigen::VectorXd d = ldlt.vectorD();
  if (ldlt.info() != Eigen::Success || normal.rows() < n || !(d.minCoeff() > 1e-14 * d.maxCoeff())) return;
  const Eigen::MatrixXd columns = ldlt.solve(Eigen::MatrixXd::Identity(normal.rows(), n));
  const Eigen::MatrixXd full = 0.5 * (columns.topRows(n) + columns.topRows(n).transpose());
  report->covariance = full;
  report->variance_factor = s2;
  for (int k = 0; k < 6; ++k) report->stddev[k] = std::sqrt(s2 * full(k, k));
  for (size_t a = 0; a < free.size(); ++a) report->intrinsics_stddev[free[a]] = std::sqrt(s2 * full(6 + a, 6 + a));
}

// The dots' and the flange corrections' blocks that are in `problem`.
std::vector<double*> OtherBlocks(const ceres::Problem& problem, std::map<int, Eigen::Vector3d>* dots,
                                 std::vector<std::array<double, 6>>* deltas) {
  std::vector<double*> others;
  for (auto& entry : *dots) {
    if (problem.HasParameterBlock(entry.second.data())) others.push_back(entry.second.data());
  }
  for (auto& delta : *deltas) {
    if (problem.HasParameterBlock(delta.data())) others.push_back(delta.data());
  }
  return others;
}

}  // namespace

PoseNoiseReport RunPoseNoiseBundle(const ObservationSet& obs, const Rigid3& x0,
                                   const std::map<int, Eigen::Vector3d>& dots_start, const PoseNoiseOptions& options) {
  PoseNoiseReport report;
  if (!obs.UsesFlangePoses() || !(options.translation_sigma_m > 0) || !(options.rotation_sigma_rad > 0)) {
    report.message = "needs a flange-pose set and a positive pose noise";
    return report;
  }
  const bool eye_to_hand = obs.robot.mount == CameraMount::kEyeToHand;
  const std::vector<int> poses = obs.PosesWithRole(PoseRole::kIdentification);
  std::vector<Rigid3> flanges;
  std::vector<PoseObs> all;
  std::map<int, int> views;
  for (size_t i = 0; i < poses.size(); ++i) {
    const PoseObservation& pose = obs.poses[poses[i]];
    report.pose_ids.push_back(pose.id);
    flanges.push_back(*pose.base_from_flange);
    for (const auto& [id, pixel] : pose.dots_px) {
      if (!dots_start.count(id)) continue;
      all.push_back({static_cast<int>(i), id, pixel});
      ++views[id];
    }
  }
  std::map<int, Eigen::Vector3d> dots;
  for (const auto& [id, n] : views) {
    if (n >= 2) dots[id] = dots_start.at(id);
  }
  const std::vector<KnownDistance> lengths = LengthsAmong(obs.yardsticks, dots);
  std::vector<std::array<double, 6>> deltas(poses.size(), std::array<double, 6>{0, 0, 0, 0, 0, 0});
  std::array<double, 6> c{0, 0, 0, 0, 0, 0};
  IntrinsicsVector intrinsics = IntrinsicsOf(obs.camera);
  const int num_estimated = static_cast<int>(EstimatedIntrinsics(options.intrinsics).size());
  const double sigma = obs.pixel_noise_px;
  ceres::HuberLoss huber(options.huber_px / sigma);
  std::vector<bool> keep(all.size(), true);
  ceres::Solver::Summary summary;
  for (int round = 0; round < 2; ++round) {
    ceres::Problem problem;
    for (size_t k = 0; k < all.size(); ++k) {
      if (!keep[k] || !dots.count(all[k].dot)) continue;
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<FlangeReprojection, 2, 6, 6, 3, kNumIntrinsics>(
                                   new FlangeReprojection(&flanges[all[k].pose], &x0, eye_to_hand, all[k].pixel, sigma)),
                               round == 0 ? new ceres::LossFunctionWrapper(&huber, ceres::DO_NOT_TAKE_OWNERSHIP) : nullptr,
                               deltas[all[k].pose].data(), c.data(), dots[all[k].dot].data(), intrinsics.data());
    }
    for (auto& delta : deltas) {
      if (!problem.HasParameterBlock(delta.data())) continue;
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PosePrior, 6, 6>(
                                   new PosePrior(options.translation_sigma_m, options.rotation_sigma_rad)),
                               nullptr, delta.data());
    }
    for (const KnownDistance& y : lengths) {
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Length, 1, 3, 3>(
                                   new Length(y.length_m, options.yardstick_sigma_m)),
                               nullptr, dots[y.dot_a].data(), dots[y.dot_b].data());
    }
    summary = internal::SolveWithIntrinsics(&problem, intrinsics.data(), options.intrinsics, options.max_iterations);
    if (internal::SolverFailed(summary, &report.message)) return report;
    std::vector<double> errors;
    for (const PoseObs& o : all) {
      double r[2] = {NAN, NAN};
      if (dots.count(o.dot)) {
        FlangeReprojection f(&flanges[o.pose], &x0, eye_to_hand, o.pixel, 1.0);
        if (!f(deltas[o.pose].data(), c.data(), dots[o.dot].data(), intrinsics.data(), r)) r[0] = NAN;
      }
      errors.push_back(std::hypot(r[0], r[1]));
    }
    const double limit = internal::ScreenLimit(errors, sigma, options.screen_sigma);
    if (!std::isfinite(limit)) break;
    if (round == 0) {
      for (size_t k = 0; k < all.size(); ++k) keep[k] = errors[k] <= limit;
      continue;
    }
    double sum2 = 0;
    for (size_t k = 0; k < all.size(); ++k) {
      if (!keep[k] || !std::isfinite(errors[k])) continue;
      sum2 += errors[k] * errors[k];
      ++report.num_observations;
    }
    report.rms_reprojection_px = report.num_observations > 0 ? std::sqrt(sum2 / report.num_observations) : 0.0;
    // Covariance of the hand-eye correction and the estimated intrinsics, scaled by the residual variance.
    const int unknowns = 6 + num_estimated + 3 * static_cast<int>(dots.size()) + 6 * static_cast<int>(deltas.size());
    const int residuals =
        2 * report.num_observations + 6 * static_cast<int>(deltas.size()) + static_cast<int>(lengths.size());
    const int dof = residuals - unknowns;
    if (dof > 0) {
      Covariances(&problem, c.data(), intrinsics.data(), options.intrinsics, OtherBlocks(problem, &dots, &deltas),
                  2.0 * summary.final_cost / dof, &report);
    }
  }
  report.num_removed = static_cast<int>(std::count(keep.begin(), keep.end(), false));
  for (size_t k = 0; k < all.size(); ++k) {
    if (!keep[k]) report.removed.push_back({report.pose_ids[all[k].pose], all[k].dot});
  }
  report.dots = dots;
  report.intrinsics_estimated = options.intrinsics;
  for (const KnownDistance& y : lengths) {
    report.yardstick_lengths_m.push_back((dots[y.dot_a] - dots[y.dot_b]).norm());
  }
  (eye_to_hand ? report.base_from_cam : report.flange_from_cam) = x0 * RigidFromTranslationRotvec(c.data());
  report.intrinsics = intrinsics;
  for (const auto& delta : deltas) {
    report.corrections.push_back(Eigen::Map<const Eigen::Matrix<double, 6, 1>>(delta.data()));
    report.correction_translation_m.push_back(Eigen::Vector3d(delta[0], delta[1], delta[2]).norm());
    report.correction_rotation_rad.push_back(Eigen::Vector3d(delta[3], delta[4], delta[5]).norm());
  }
  report.ok = summary.termination_type == ceres::CONVERGENCE || summary.termination_type == ceres::NO_CONVERGENCE;
  const double max_t = *std::max_element(report.correction_translation_m.begin(), report.correction_translation_m.end());
  const double max_r = *std::max_element(report.correction_rotation_rad.begin(), report.correction_rotation_rad.end());
  std::ostringstream msg;
  msg << ceres::TerminationTypeToString(summary.termination_type) << ": " << report.num_observations
      << " observations, " << lengths.size() << " yardstick constraint(s), " << report.num_removed
      << " removed, RMS " << report.rms_reprojection_px
      << " px; flange pose corrections up to " << max_t * 1e3 << " mm and " << max_r * 180 / kPi << " deg";
  report.message = msg.str();
  return report;
}

}  // namespace selfcal::bundle
