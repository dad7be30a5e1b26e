#include "planning/fisher_design.h"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "base/status.h"
#include "planning/pose_twists.h"

namespace selfcal::planning {

FisherDesign::FisherDesign(const PlanningProblem& problem, const std::vector<int>& free_columns,
                           const FisherDesignOptions& options)
    : problem_(problem), free_columns_(free_columns), options_(options) {
  SELFCAL_CHECK(problem.scene.dots_in_base.size() >= 3, "the scene needs at least 3 dots");
  SELFCAL_CHECK(options.pixel_noise_px > 0 && options.yardstick_sigma_m > 0, "noise and yardstick sigma must be > 0");
  num_global_ = static_cast<int>(free_columns.size()) + 1 + 6;
}

int FisherDesign::AddCandidate(const Eigen::VectorXd& q) {
  SELFCAL_CHECK(q.size() == problem_.robot.num_joints(), "candidate has " << q.size() << " joints");
  const internal::CameraTwists<double> tw = internal::ComputeCameraTwists<double>(problem_.robot, q.data());
  const Eigen::Matrix3d rt = tw.base_from_cam.rotation.transpose();
  const Eigen::Vector3d c = tw.base_from_cam.translation;
  const CameraIntrinsics& cam = problem_.camera;
  const int nf = static_cast<int>(free_columns_.size());
  const int dots = static_cast<int>(problem_.scene.dots_in_base.size());
  Candidate out;
  out.h_gg = Eigen::MatrixXd::Zero(num_global_, num_global_);
  out.h_jj.assign(dots - 2, Eigen::Matrix3d::Zero());
  out.h_gj.assign(dots - 2, Eigen::MatrixXd::Zero(num_global_, 3));
  Eigen::MatrixXd a(2, num_global_);
  for (int j = 0; j < dots; ++j) {
    const Eigen::Vector3d x = problem_.scene.dots_in_base[j];
    const Eigen::Vector3d p = rt * (x - c);
    if (!(p.z() > 0)) continue;
    const double xn = p.x() / p.z(), yn = p.y() / p.z();
    const double u = cam.cx_px + cam.fx_px * xn, v = cam.cy_px + cam.fx_px * cam.mu * yn;
    if (u < 0 || v < 0 || u > cam.width_px - 1 || v > cam.height_px - 1) continue;  // not seen
    Eigen::Matrix<double, 2, 3> dpi;
    dpi << cam.fx_px / p.z(), 0, -cam.fx_px * xn / p.z(), 0, cam.fx_px * cam.mu / p.z(), -cam.fx_px * cam.mu * yn / p.z();
    a.setZero();
    for (int k = 0; k < nf; ++k) {
      const int col = free_columns_[k];
      a.col(k) = dpi * (-(rt * (tw.omega[col].cross(x) + tw.v[col])));
    }
    a(0, nf) = xn;
    a(1, nf) = cam.mu * yn;
    const Eigen::Matrix<double, 2, 3> b = dpi * rt;
    if (j < 2) {
      a.block<2, 3>(0, nf + 1 + 3 * j) = b;
      out.h_gg.noalias() += a.transpose() * a;
    } else {
      out.h_gg.noalias() += a.transpose() * a;
      out.h_jj[j - 2].noalias() += b.transpose() * b;
      out.h_gj[j - 2].noalias() += a.transpose() * b;
    }
  }
  candidates_.push_back(std::move(out));
  return static_cast<int>(candidates_.size()) - 1;
}

FisherValue FisherDesign::Evaluate(const std::vector<int>& design) const {
  FisherValue value;
  const int nf = static_cast<int>(free_columns_.size());
  const int dots = static_cast<int>(problem_.scene.dots_in_base.size());
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(num_global_, num_global_);
  for (int c : design) h += candidates_.at(c).h_gg;
  // The yardstick: (|X0 - X1| - L) / sigma_y, in units where the pixel residuals have unit variance.
  const Eigen::Vector3d d = problem_.scene.dots_in_base[0] - problem_.scene.dots_in_base[1];
  Eigen::VectorXd g = Eigen::VectorXd::Zero(num_global_);
  g.segment<3>(nf + 1) = d.normalized();
  g.segment<3>(nf + 4) = -d.normalized();
  const double w = options_.pixel_noise_px / options_.yardstick_sigma_m;
  h.noalias() += (w * w) * g * g.transpose();
  Eigen::Matrix3d h_jj;
  Eigen::MatrixXd h_gj(num_global_, 3);
  for (int j = 0; j < dots - 2; ++j) {
    h_jj.setZero();
    h_gj.setZero();
    for (int c : design) {
      h_jj += candidates_[c].h_jj[j];
      h_gj += candidates_[c].h_gj[j];
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(h_jj);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12 * h_jj.trace())) {
      continue;  // a dot seen from fewer than two poses carries no information on the globals
    }
    h.noalias() -= h_gj * ldlt.solve(h_gj.transpose());
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(h);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return value;
  const Eigen::MatrixXd cov_all = ldlt.solve(Eigen::MatrixXd::Identity(num_global_, num_global_));
  const Eigen::MatrixXd cov = cov_all.topLeftCorner(nf + 1, nf + 1) * (options_.pixel_noise_px * options_.pixel_noise_px);
  const Eigen::LDLT<Eigen::MatrixXd> cov_ldlt(cov);
  if (cov_ldlt.info() != Eigen::Success || !(cov_ldlt.vectorD().minCoeff() > 0)) return value;
  value.ok = true;
  value.log_det = -cov_ldlt.vectorD().array().log().sum();
  value.stddev = cov.diagonal().cwiseSqrt();
  const KinematicParameters params(problem_.robot.num_joints());
  value.a_value = 0;
  for (int k = 0; k <= nf; ++k) {
    const double prior = k == nf ? options_.prior_fx_px
                                 : (params.kind(free_columns_[k]) == ParameterKind::kLength ? options_.prior_length_m
                                                                                            : options_.prior_angle_rad);
    value.a_value += cov(k, k) / (prior * prior);
  }
  return value;
}

}  // namespace selfcal::planning
