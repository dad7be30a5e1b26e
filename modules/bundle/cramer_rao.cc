// Cramer-Rao bound of the kinematic bundle adjustment (bundle_adjustment.h).
//
// The Fisher information of the free globals with the dots as nuisance parameters is the Schur
// complement J_g^T (I - P_dots) J_g of the whitened Jacobian, which internal::ReducedJacobian forms
// exactly as the solver's covariance does; only the point (the truth) and the absence of the a-posteriori
// factor s^2 differ.
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Dense>

#include "bundle/bundle_adjustment.h"
#include "bundle/bundle_problem.h"
#include "kinematics/autodiff_jacobian.h"

namespace selfcal::bundle {

namespace {

// Derivative of cam_ref_from_cam_v (the cameras relative to the points: PointsFromCam, eye-to-hand the
// flange's motion seen from the fixed camera) with respect to the free entries of rho: rows 0-2 the
// small-angle rotation vector (in the cam_v frame, R0^T dR), rows 3-5 the translation (m).
Eigen::MatrixXd RelativePoseJacobian(const RobotModel& robot, const Eigen::VectorXd& rho, const std::vector<int>& free,
                                     const Eigen::VectorXd& q_ref, const Eigen::VectorXd& q_v) {
  Eigen::VectorXd x(free.size());
  for (size_t k = 0; k < free.size(); ++k) x[k] = rho[free[k]];
  auto relative = [&](const auto* values, auto* out) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(values)>>;
    std::vector<T> r(rho.size()), qr(q_ref.size()), qv(q_v.size());
    for (int i = 0; i < rho.size(); ++i) r[i] = T(rho[i]);
    for (size_t k = 0; k < free.size(); ++k) r[free[k]] = values[k];
    for (int j = 0; j < q_ref.size(); ++j) qr[j] = T(q_ref[j]);
    for (int j = 0; j < q_v.size(); ++j) qv[j] = T(q_v[j]);
    const Rigid3T<T> rel = PointsFromCam<T>(robot, r.data(), qr.data()).Inverse() * PointsFromCam<T>(robot, r.data(), qv.data());
    for (int e = 0; e < 9; ++e) out[e] = rel.rotation(e % 3, e / 3);
    for (int e = 0; e < 3; ++e) out[9 + e] = rel.translation[e];
  };
  Eigen::VectorXd value;
  const Eigen::MatrixXd d = AutodiffJacobian<8>(relative, x, 12, &value);
  Eigen::Matrix3d r0;
  for (int e = 0; e < 9; ++e) r0(e % 3, e / 3) = value[e];
  Eigen::MatrixXd out(6, free.size());
  for (size_t k = 0; k < free.size(); ++k) {
    Eigen::Matrix3d dr;
    for (int e = 0; e < 9; ++e) dr(e % 3, e / 3) = d(e, k);
    const Eigen::Matrix3d w = r0.transpose() * dr;  // skew-symmetric to first order
    out.col(k).head<3>() = Eigen::Vector3d(w(2, 1) - w(1, 2), w(0, 2) - w(2, 0), w(1, 0) - w(0, 1)) / 2;
    out.col(k).tail<3>() = d.block<3, 1>(9, k);
  }
  return out;
}

}  // namespace

CramerRaoReport BundleCramerRao(const ObservationSet& geometry, const BundleTruth& truth, double sigma_px,
                                const BundleOptions& options) {
  CramerRaoReport report;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  report.stddev = Eigen::VectorXd::Constant(std::max<Eigen::Index>(truth.rho.size(), 0), nan);
  report.fx_stddev = nan;
  report.intrinsics_stddev.fill(nan);
  std::ostringstream problems;
  problems << options.Validate();
  if (truth.rho.size() != geometry.robot.num_parameters() || !truth.rho.allFinite()) {
    problems << "truth.rho must be finite with " << geometry.robot.num_parameters() << " entries\n";
  }
  if (const std::string invalid = truth.camera.Validate(); !invalid.empty()) problems << "truth camera: " << invalid;
  if (!(sigma_px > 0) || !std::isfinite(sigma_px)) problems << "sigma_px = " << sigma_px << " must be > 0\n";
  internal::BundleData data = internal::MakeBundleData(geometry, options.yardstick_sigma_m);
  data.sigma_px = sigma_px;
  internal::BundleState state;
  state.rho = truth.rho;
  state.intrinsics = IntrinsicsOf(truth.camera);
  for (int id : data.dot_ids) {
    auto it = truth.dots_in_base.find(id);
    if (it == truth.dots_in_base.end()) {
      problems << "dot " << id << " has no true position\n";
    } else {
      state.dots.push_back(it->second);
    }
  }
  if (data.yardsticks.empty()) problems << "no yardstick seen twice: the scale is unobservable\n";
  if (!problems.str().empty()) {
    report.message = problems.str();
    return report;
  }

  // The free set as the solve chooses it: at the nominal model (bundle_adjustment.cc says why).
  const IntrinsicsMask estimated = EstimatedIntrinsicsOf(options, data.robot.num_joints());
  internal::Gauge gauge;
  internal::BundleState nominal = state;
  nominal.rho = KinematicParameters::Nominal(data.robot);
  if (!internal::AnalyzeGauge(data, nominal, estimated, options.rank_tolerance, &gauge)) {
    report.message = "a dot is behind a camera";
    return report;
  }
  report.free_indices = gauge.free_kinematic;
  report.fixed_names = gauge.fixed_names;
  internal::GlobalColumns columns;
  columns.kinematic = gauge.free_kinematic;
  columns.intrinsics = EstimatedIntrinsics(estimated);
  for (int k : columns.intrinsics) {
    if (gauge.intrinsics_identifiable[k]) continue;
    report.message = std::string(IntrinsicName(k)) + " is not identifiable: the information is singular";
    return report;
  }
  Eigen::MatrixXd reduced;
  if (!internal::ReducedJacobian(data, state, columns, &reduced) ||
      !internal::CovarianceFromJacobian(reduced, internal::GlobalNames(columns, data.robot.num_joints()),
                                        &report.covariance_free, &report.message)) {
    if (report.message.empty()) report.message = "the information cannot be evaluated at the truth";
    return report;
  }
  const int nk = static_cast<int>(columns.kinematic.size());
  for (int k = 0; k < nk; ++k) report.stddev[columns.kinematic[k]] = std::sqrt(report.covariance_free(k, k));
  for (size_t k = 0; k < columns.intrinsics.size(); ++k) {
    const int i = nk + static_cast<int>(k);
    report.intrinsics_stddev[columns.intrinsics[k]] = std::sqrt(report.covariance_free(i, i));
  }
  report.fx_stddev = report.intrinsics_stddev[kFx];

  // Propagation to the held-out poses.
  const std::vector<int> id_poses = geometry.PosesWithRole(PoseRole::kIdentification);
  const Eigen::MatrixXd c_kin = report.covariance_free.topLeftCorner(nk, nk);
  double sum_p2 = 0, sum_o2 = 0;
  for (int v : geometry.PosesWithRole(PoseRole::kVerification)) {
    const Eigen::MatrixXd g = RelativePoseJacobian(data.robot, truth.rho, columns.kinematic,
                                                   geometry.poses[id_poses.front()].joints_rad,
                                                   geometry.poses[v].joints_rad);
    const Eigen::MatrixXd cov = g * c_kin * g.transpose();
    const double orientation = std::sqrt(cov.topLeftCorner<3, 3>().trace());
    const double position = std::sqrt(cov.bottomRightCorner<3, 3>().trace());
    report.verification_pose_ids.push_back(geometry.poses[v].id);
    report.orientation_bound_rad.push_back(orientation);
    report.position_bound_m.push_back(position);
    sum_p2 += position * position;
    sum_o2 += orientation * orientation;
  }
  if (!report.verification_pose_ids.empty()) {
    const double count = static_cast<double>(report.verification_pose_ids.size());
    report.rms_position_bound_m = std::sqrt(sum_p2 / count);
    report.rms_orientation_bound_rad = std::sqrt(sum_o2 / count);
  }
  report.ok = true;
  report.message = "ok";
  return report;
}

}  // namespace selfcal::bundle
