#include "planning/fisher_design.h"

#include <cmath>

#include <Eigen/Cholesky>

#include "base/status.h"
#include "planning/pose_twists.h"

namespace selfcal::planning {

namespace {

// Lower triangle of s += sign w w^T for a w of few columns (Eigen's rankUpdate goes through its blocked
// matrix product, several times slower at these sizes).
template <typename Matrix>
void AddOuterLower(double sign, const Matrix& w, Eigen::MatrixXd* s) {
  const int n = static_cast<int>(w.rows());
  for (int c = 0; c < n; ++c) {
    const int len = n - c;
    for (int k = 0; k < w.cols(); ++k) s->col(c).tail(len).noalias() += (sign * w(c, k)) * w.col(k).tail(len);
  }
}

}  // namespace

FisherDesign::FisherDesign(const PlanningProblem& problem, const std::vector<int>& free_columns,
                           const FisherDesignOptions& options)
    : problem_(problem), free_columns_(free_columns), options_(options) {
  SELFCAL_CHECK(problem.scene.dots_in_base.size() >= 3, "the scene needs at least 3 dots");
  SELFCAL_CHECK(options.pixel_noise_px > 0 && options.yardstick_sigma_m > 0, "noise and yardstick sigma must be > 0");
  num_global_ = static_cast<int>(free_columns.size()) + 1 + 6;
}

FisherDesign::Sums FisherDesign::ZeroSums() const {
  const int nf = static_cast<int>(free_columns_.size());
  const int dots = static_cast<int>(problem_.scene.dots_in_base.size());
  Sums zero;
  zero.h_gg = Eigen::MatrixXd::Zero(num_global_, num_global_);
  zero.h_jj.assign(dots - 2, Eigen::Matrix3d::Zero());
  zero.h_gj = Eigen::MatrixXd::Zero(nf + 1, 3 * (dots - 2));
  return zero;
}

int FisherDesign::AddCandidate(const Eigen::VectorXd& q) {
  SELFCAL_CHECK(q.size() == problem_.robot.num_joints(), "candidate has " << q.size() << " joints");
  const internal::CameraTwists<double> tw = internal::ComputeCameraTwists<double>(problem_.robot, q.data());
  const Eigen::Matrix3d rt = tw.base_from_cam.rotation.transpose();
  const Eigen::Vector3d c = tw.base_from_cam.translation;
  const CameraIntrinsics& cam = problem_.camera;
  const int nf = static_cast<int>(free_columns_.size());
  const int dots = static_cast<int>(problem_.scene.dots_in_base.size());
  Candidate out = ZeroSums();
  Eigen::Matrix<double, 2, Eigen::Dynamic> a(2, num_global_);
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
    if (j < 2) a.block<2, 3>(0, nf + 1 + 3 * j) = b;
    AddOuterLower(1.0, a.transpose(), &out.h_gg);  // lower triangle += a^T a
    if (j >= 2) {
      out.h_jj[j - 2].noalias() += b.transpose() * b;
      out.h_gj.middleCols<3>(3 * (j - 2)).noalias() += a.leftCols(nf + 1).transpose() * b;
    }
  }
  out.h_gg.triangularView<Eigen::StrictlyUpper>() = out.h_gg.transpose();
  candidates_.push_back(std::move(out));
  return static_cast<int>(candidates_.size()) - 1;
}

FisherDesign::Sums FisherDesign::Sum(const std::vector<int>& design, int skip_position) const {
  const int dots = static_cast<int>(problem_.scene.dots_in_base.size());
  Sums sums = ZeroSums();
  for (size_t k = 0; k < design.size(); ++k) {
    if (static_cast<int>(k) == skip_position) continue;
    const Candidate& c = candidates_.at(design[k]);
    sums.h_gg += c.h_gg;
    for (int j = 0; j < dots - 2; ++j) sums.h_jj[j] += c.h_jj[j];
    sums.h_gj += c.h_gj;
  }
  return sums;
}

FisherValue FisherDesign::Evaluate(const std::vector<int>& design) const {
  return EvaluateSums(Sum(design), -1, true);
}

FisherValue FisherDesign::EvaluateSums(const Sums& sums, int extra, bool with_variances) const {
  FisherValue value;
  const int nf = static_cast<int>(free_columns_.size());
  const int dots = static_cast<int>(problem_.scene.dots_in_base.size());
  const Candidate* add = extra >= 0 ? &candidates_.at(extra) : nullptr;
  Eigen::MatrixXd h = sums.h_gg;
  if (add != nullptr) h += add->h_gg;
  // The yardstick: (|X0 - X1| - L) / sigma_y, in units where the pixel residuals have unit variance.
  const Eigen::Vector3d d = problem_.scene.dots_in_base[0] - problem_.scene.dots_in_base[1];
  Eigen::VectorXd g = Eigen::VectorXd::Zero(num_global_);
  g.segment<3>(nf + 1) = d.normalized();
  g.segment<3>(nf + 4) = -d.normalized();
  const double w = options_.pixel_noise_px / options_.yardstick_sigma_m;
  h.noalias() += (w * w) * g * g.transpose();
  // s: the information of (free rho, f_x) with every dot eliminated (lower triangle), the yardstick dots last.
  Eigen::MatrixXd s = h.topLeftCorner(nf + 1, nf + 1);
  // sum_j h_gj h_jj^-1 h_gj^T = W W^T, W's 3 columns per dot h_gj L_j^-T (h_jj = L_j L_j^T).
  Eigen::MatrixXd w_dots(nf + 1, 3 * (dots - 2));
  Eigen::Matrix<double, Eigen::Dynamic, 3> h_gj(nf + 1, 3);
  for (int j = 0; j < dots - 2; ++j) {
    const Eigen::Matrix3d h_jj = add != nullptr ? Eigen::Matrix3d(sums.h_jj[j] + add->h_jj[j]) : sums.h_jj[j];
    const Eigen::LLT<Eigen::Matrix3d> llt(h_jj);
    const Eigen::Matrix3d l = llt.matrixL();
    if (llt.info() != Eigen::Success || !(l.diagonal().array().square().minCoeff() > 1e-12 * h_jj.trace())) {
      w_dots.middleCols<3>(3 * j).setZero();  // a dot seen from fewer than two poses: no information on the globals
      continue;
    }
    const Eigen::Matrix3d l_inv_t = l.triangularView<Eigen::Lower>().solve(Eigen::Matrix3d::Identity()).transpose();
    h_gj = sums.h_gj.middleCols<3>(3 * j);
    if (add != nullptr) h_gj += add->h_gj.middleCols<3>(3 * j);
    w_dots.middleCols<3>(3 * j).noalias() = h_gj.lazyProduct(l_inv_t);
  }
  s.selfadjointView<Eigen::Lower>().rankUpdate(w_dots, -1.0);
  // The yardstick dots: the Schur complement of their 6 x 6 block.
  const Eigen::LLT<Eigen::MatrixXd> yard(h.bottomRightCorner(6, 6));
  if (yard.info() != Eigen::Success) return value;
  const Eigen::MatrixXd w_y = yard.matrixU().solve<Eigen::OnTheRight>(h.topRightCorner(nf + 1, 6));
  AddOuterLower(-1.0, w_y, &s);
  const Eigen::LLT<Eigen::MatrixXd> llt(s.selfadjointView<Eigen::Lower>());
  if (llt.info() != Eigen::Success) return value;
  const Eigen::MatrixXd l = llt.matrixL();
  if (!(l.diagonal().minCoeff() > 0)) return value;
  const double sigma2 = options_.pixel_noise_px * options_.pixel_noise_px;
  // cov = sigma^2 s^-1: log det(cov^-1) = log det s - (nf + 1) log sigma^2.
  value.ok = true;
  value.log_det = 2.0 * l.diagonal().array().log().sum() - (nf + 1) * std::log(sigma2);
  if (!with_variances) return value;
  // diag(s^-1)_k = |L^-1 e_k|^2.
  const Eigen::MatrixXd l_inv = llt.matrixL().solve(Eigen::MatrixXd::Identity(nf + 1, nf + 1));
  const Eigen::VectorXd variance = sigma2 * l_inv.colwise().squaredNorm().transpose();
  value.stddev = variance.cwiseSqrt();
  const KinematicParameters params(problem_.robot.num_joints());
  value.a_value = 0;
  for (int k = 0; k <= nf; ++k) {
    const double prior = k == nf ? options_.prior_fx_px
                                 : (params.kind(free_columns_[k]) == ParameterKind::kLength ? options_.prior_length_m
                                                                                            : options_.prior_angle_rad);
    value.a_value += variance[k] / (prior * prior);
  }
  return value;
}

}  // namespace selfcal::planning
