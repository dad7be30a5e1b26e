#include "calibration/predicted_error.h"

#include <cmath>
#include <sstream>

#include <Eigen/Dense>

#include "identification/triangulation.h"
#include "kinematics/autodiff_jacobian.h"

namespace selfcal::calibration {

namespace {

// One verification camera at the model: its pose and the derivative of the pose's 12 numbers (rotation
// row-major, then translation) with respect to the free entries of rho (forward-mode autodiff, exact).
struct ViewModel {
  Rigid3 base_from_cam;
  Eigen::MatrixXd d_pose;  // 12 x free
};

std::vector<ViewModel> Views(const ObservationSet& obs, const std::vector<int>& pose_indices, const RobotModel& robot,
                             const Eigen::VectorXd& rho, const std::vector<int>& free_indices) {
  const int nf = static_cast<int>(free_indices.size());
  Eigen::VectorXd x(nf);
  for (int t = 0; t < nf; ++t) x[t] = rho[free_indices[t]];
  std::vector<ViewModel> views;
  views.reserve(pose_indices.size());
  for (int p : pose_indices) {
    const PoseObservation& pose = obs.poses[p];
    auto f = [&](const auto* free, auto* y) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(free)>>;
      std::vector<T> r(rho.size());
      for (int i = 0; i < rho.size(); ++i) r[i] = T(rho[i]);
      for (int t = 0; t < nf; ++t) r[free_indices[t]] = free[t];
      Rigid3T<T> c;
      if (pose.base_from_flange) {
        c = PointsFromCamGivenFlange<T>(robot, r.data(), *pose.base_from_flange);
      } else {
        std::vector<T> q(pose.joints_rad.size());
        for (size_t j = 0; j < q.size(); ++j) q[j] = T(pose.joints_rad[j]);
        c = PointsFromCam<T>(robot, r.data(), q.data());
      }
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) y[3 * a + b] = c.rotation(a, b);
        y[9 + a] = c.translation[a];
      }
    };
    ViewModel v;
    v.base_from_cam = PointsFromCamAt(robot, rho, pose);  // the same bits as the triangulation has always used
    v.d_pose = AutodiffJacobian<8>(f, x, 12);
    views.push_back(std::move(v));
  }
  return views;
}

// One end of a distance: the verification views that see the dot (index into the views) and the pixels.
struct EndViews {
  std::vector<int> views;
  std::vector<Eigen::Vector2d> pixels;
};

EndViews EndViewsOf(const ObservationSet& obs, const std::vector<int>& pose_indices, int dot) {
  EndViews end;
  for (size_t k = 0; k < pose_indices.size(); ++k) {
    const auto& dots = obs.poses[pose_indices[k]].dots_px;
    auto it = dots.find(dot);
    if (it == dots.end()) continue;
    end.views.push_back(static_cast<int>(k));
    end.pixels.push_back(it->second);
  }
  return end;
}

// A triangulated end and its first-order sensitivities. The point minimises E = sum_k |r_k|^2 with
// r_k = pi(R_k^T (X - t_k); f_x) - m_k, i.e. solves F = sum_k J_X,k^T r_k = 0, so (implicit function
// theorem) dX/dq = -H^-1 dF/dq with H = dF/dX = sum_k (J_X,k^T J_X,k + R_k M_k R_k^T), where
// M_k = sum_c r_kc d2pi_c/dp2 is the residual curvature. For the pixels dF/dm_k = -J_X,k^T; for theta
// dF/dtheta = sum_k (J_X,k^T J_theta,k + dR_k (Jpi_k^T r_k) + R_k M_k dp_k/dtheta) (f_x: Jpi/f_x for
// dR M dp). O(views x parameters) per end.
struct EndPoint {
  Eigen::Vector3d point;
  Eigen::MatrixXd d_theta;   // 3 x (free + 1): free entries of rho, then f_x
  Eigen::MatrixXd d_pixels;  // 3 x (2 views): u, v of each view in order
};

// d(u, v)/d(p_in_cam) and d(u, v)/d(f_x) of the projection of camera.h (f_x, mu, c, lens held), and
// the pixel.
Eigen::Vector2d ProjectionJacobian(const CameraIntrinsics& cam, double fx, const Eigen::Vector3d& p,
                                   Eigen::Matrix<double, 2, 3>* d_p, Eigen::Vector2d* d_fx = nullptr) {
  const double inv_z = 1.0 / p.z();
  const Eigen::Vector2d xy(p.x() * inv_z, p.y() * inv_z);
  Eigen::Matrix2d d_xy;
  const Eigen::Vector2d xd = Distort(cam, xy, &d_xy);
  Eigen::Matrix<double, 2, 3> d_norm;
  d_norm << inv_z, 0, -xy.x() * inv_z, 0, inv_z, -xy.y() * inv_z;
  const Eigen::Matrix2d scale = Eigen::Vector2d(fx, fx * cam.mu).asDiagonal();
  *d_p = scale * d_xy * d_norm;
  if (d_fx != nullptr) *d_fx = Eigen::Vector2d(xd.x(), cam.mu * xd.y());
  return Eigen::Vector2d(fx * xd.x() + cam.cx_px, fx * cam.mu * xd.y() + cam.cy_px);
}

// M = sum_c r_c d2pi_c/dp2: central differences of the analytic d(pi)/dp (step 1e-5 |p|; this term is
// itself a small correction, of the order of the residual over f_x, so their 1e-6 relative error is
// far below round-off in dX/dq).
Eigen::Matrix3d ResidualCurvature(const CameraIntrinsics& cam, double fx, const Eigen::Vector3d& p,
                                  const Eigen::Vector2d& residual) {
  const double h = 1e-5 * p.norm();
  Eigen::Matrix3d m;
  for (int j = 0; j < 3; ++j) {
    Eigen::Vector3d plus = p, minus = p;
    plus[j] += h;
    minus[j] -= h;
    Eigen::Matrix<double, 2, 3> j_plus, j_minus;
    ProjectionJacobian(cam, fx, plus, &j_plus);
    ProjectionJacobian(cam, fx, minus, &j_minus);
    m.col(j) = (j_plus - j_minus).transpose() * residual / (2 * h);
  }
  return 0.5 * (m + m.transpose());
}

bool TriangulateEnd(const CameraIntrinsics& camera, double fx_px, const std::vector<ViewModel>& views,
                    const EndViews& end, EndPoint* out) {
  identification::PointTrack track;
  for (size_t k = 0; k < end.views.size(); ++k) {
    track.base_from_cam.push_back(views[end.views[k]].base_from_cam);
    track.pixels.push_back(end.pixels[k]);
  }
  const identification::TriangulationResult r = identification::TriangulatePoint(camera, fx_px, track, 1.0);
  if (!r.ok) return false;
  out->point = r.point;
  const int nv = static_cast<int>(end.views.size());
  const int nf = static_cast<int>(views.front().d_pose.cols());
  Eigen::MatrixXd j_x(2 * nv, 3);
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
  Eigen::MatrixXd d_f_theta = Eigen::MatrixXd::Zero(3, nf + 1);
  for (int k = 0; k < nv; ++k) {
    const ViewModel& v = views[end.views[k]];
    const Eigen::Matrix3d& rot = v.base_from_cam.rotation;
    const Eigen::Vector3d rel = r.point - v.base_from_cam.translation;
    const Eigen::Vector3d p = rot.transpose() * rel;
    Eigen::Matrix<double, 2, 3> d_p;
    Eigen::Vector2d d_fx;
    const Eigen::Vector2d residual = ProjectionJacobian(camera, fx_px, p, &d_p, &d_fx) - end.pixels[k];
    const Eigen::Matrix3d curvature = ResidualCurvature(camera, fx_px, p, residual);
    const Eigen::Matrix<double, 3, 2> j_xk = (d_p * rot.transpose()).transpose();
    const Eigen::Vector3d jr = d_p.transpose() * residual;
    j_x.middleRows<2>(2 * k) = j_xk.transpose();
    hessian += j_xk * j_xk.transpose() + rot * curvature * rot.transpose();
    // p = R^T (X - t): dp/dtheta = dR^T (X - t) - R^T dt.
    for (int t = 0; t < nf; ++t) {
      const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> d_rot(v.d_pose.col(t).data());
      const Eigen::Vector3d d_t = v.d_pose.col(t).tail<3>();
      const Eigen::Vector3d dp = d_rot.transpose() * rel - rot.transpose() * d_t;
      d_f_theta.col(t) += j_xk * (d_p * dp) + d_rot * jr + rot * (curvature * dp);
    }
    d_f_theta.col(nf) += j_xk * d_fx + rot * jr / fx_px;
  }
  const Eigen::LDLT<Eigen::Matrix3d> h(hessian);
  if (h.info() != Eigen::Success || !(h.vectorD().minCoeff() > 0)) return false;
  out->d_theta = -h.solve(d_f_theta);
  out->d_pixels = h.solve(j_x.transpose());
  return out->d_theta.allFinite() && out->d_pixels.allFinite();
}

// What is wrong with the inputs, one line each; empty when they are valid.
std::string CheckInputs(const ObservationSet& obs, const std::vector<int>& pose_indices, const RobotModel& robot,
                        const Eigen::VectorXd& rho, double fx_px, const std::vector<int>& free_indices,
                        const Eigen::MatrixXd& covariance, double sigma_px) {
  const int nt = static_cast<int>(free_indices.size()) + 1;
  std::ostringstream problems;
  if (rho.size() != robot.num_parameters() || !rho.allFinite()) problems << "rho must be finite with " << robot.num_parameters() << " entries\n";
  for (int i : free_indices) {
    if (i < 0 || i >= rho.size()) problems << "free index " << i << " out of range\n";
  }
  if (!(std::isfinite(fx_px) && fx_px > 0)) problems << "f_x must be finite and > 0\n";
  if (covariance.rows() < nt || covariance.cols() != covariance.rows() || !covariance.allFinite()) {
    problems << "covariance must be square, finite, with at least free + 1 (f_x) = " << nt << " rows\n";
  }
  if (!(std::isfinite(sigma_px) && sigma_px >= 0)) problems << "sigma_px must be finite and >= 0\n";
  for (int p : pose_indices) {
    if (p < 0 || p >= static_cast<int>(obs.poses.size())) problems << "pose index " << p << " out of range\n";
  }
  if (pose_indices.empty()) problems << "no verification poses\n";
  return problems.str();
}

// The variances of every distance that is ok and their quadratic means.
void CombineVariances(const Eigen::MatrixXd& sigma, double sigma_px, PredictedDistanceErrors* out) {
  double sum2 = 0, sum2_a = 0, sum2_b = 0;
  for (PredictedDistanceError& e : out->distances) {
    if (!e.ok) continue;
    const double var_a = std::max(0.0, e.gradient_theta.dot(sigma * e.gradient_theta));
    const double var_b = sigma_px * sigma_px * e.gradient_px.squaredNorm();
    e.parameters_std_m = std::sqrt(var_a);
    e.pixels_std_m = std::sqrt(var_b);
    e.std_m = std::sqrt(var_a + var_b);
    ++out->num_ok;
    sum2 += var_a + var_b;
    sum2_a += var_a;
    sum2_b += var_b;
  }
  if (out->num_ok > 0) {
    out->rms_std_m = std::sqrt(sum2 / out->num_ok);
    out->rms_parameters_std_m = std::sqrt(sum2_a / out->num_ok);
    out->rms_pixels_std_m = std::sqrt(sum2_b / out->num_ok);
    out->ok = true;
    out->message = "ok";
  } else {
    out->message = "no check distance triangulated from the given poses";
  }
}

}  // namespace

PredictedDistanceErrors PredictDistanceErrors(const ObservationSet& obs, const std::vector<int>& pose_indices,
                                              const RobotModel& robot, const Eigen::VectorXd& rho, double fx_px,
                                              const std::vector<int>& free_indices, const Eigen::MatrixXd& covariance,
                                              double sigma_px, const std::vector<KnownDistance>& distances) {
  PredictedDistanceErrors out;
  const int nt = static_cast<int>(free_indices.size()) + 1;
  const std::string problems = CheckInputs(obs, pose_indices, robot, rho, fx_px, free_indices, covariance, sigma_px);
  if (!problems.empty()) {
    out.message = problems;
    return out;
  }
  const Eigen::MatrixXd sigma = covariance.topLeftCorner(nt, nt);
  const std::vector<ViewModel> views = Views(obs, pose_indices, robot, rho, free_indices);
  out.distances.resize(distances.size());
  for (size_t d = 0; d < distances.size(); ++d) {
    PredictedDistanceError& e = out.distances[d];
    e.known = distances[d];
    const EndViews end_a = EndViewsOf(obs, pose_indices, distances[d].dot_a);
    const EndViews end_b = EndViewsOf(obs, pose_indices, distances[d].dot_b);
    e.gradient_theta = Eigen::VectorXd::Zero(nt);
    e.gradient_px = Eigen::VectorXd::Zero(2 * (end_a.views.size() + end_b.views.size()));
    EndPoint a, b;
    if (!TriangulateEnd(obs.camera, fx_px, views, end_a, &a) || !TriangulateEnd(obs.camera, fx_px, views, end_b, &b)) {
      continue;
    }
    const Eigen::Vector3d stick = a.point - b.point;
    e.measured_m = stick.norm();
    if (!(e.measured_m > 0)) continue;
    const Eigen::RowVector3d u = stick.transpose() / e.measured_m;
    e.gradient_theta = (u * (a.d_theta - b.d_theta)).transpose();
    const Eigen::Index na = a.d_pixels.cols();
    e.gradient_px.head(na) = (u * a.d_pixels).transpose();
    e.gradient_px.tail(b.d_pixels.cols()) = -(u * b.d_pixels).transpose();
    e.ok = true;
  }
  CombineVariances(sigma, sigma_px, &out);
  return out;
}

}  // namespace selfcal::calibration
