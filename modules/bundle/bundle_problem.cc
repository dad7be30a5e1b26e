#include "bundle/bundle_problem.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>

#include <Eigen/Dense>
#include <ceres/jet.h>

#include "geometry/rigid3.h"

namespace selfcal::bundle::internal {

namespace {

template <typename T>
Rigid3T<T> PointsFromCamOf(const BundleData& data, int pose, const T* rho, const T* q) {
  if (!data.base_from_flange.empty()) return PointsFromCamGivenFlange<T>(data.robot, rho, data.base_from_flange[pose]);
  return PointsFromCam<T>(data.robot, rho, q);
}

}  // namespace

Rigid3 PointsFromCamOfPose(const BundleData& data, int pose, const Eigen::VectorXd& rho) {
  return PointsFromCamOf<double>(data, pose, rho.data(), data.joints[pose].data());
}

namespace {

// The spatial twist (omega, v) of one parameter: d R / d rho = [omega]x R, d p / d rho = omega x p + v for
// the camera pose (R, p) = base_from_cam, in the base frame.
struct Twist {
  Eigen::Vector3d omega = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
};

// d Exp(r + delta) = Exp(r) [J_r(r) delta]x: the right Jacobian of SO(3).
Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& r) {
  const double theta2 = r.squaredNorm();
  const Eigen::Matrix3d k = Skew<double>(r);
  double a, b;  // (1 - cos t) / t^2, (t - sin t) / t^3
  if (theta2 < 1e-8) {
    a = 0.5 - theta2 / 24.0;
    b = 1.0 / 6.0 - theta2 / 120.0;
  } else {
    const double theta = std::sqrt(theta2);
    a = (1.0 - std::cos(theta)) / theta2;
    b = (theta - std::sin(theta)) / (theta2 * theta);
  }
  return Eigen::Matrix3d::Identity() - a * k + b * k * k;
}

// Appends a correction [Exp(r) | t] (rho[0..2] = t, rho[3..5] = r) to the chain `frame`, and the twists of its
// six parameters to twists[0..5].
void AppendCorrection(const double* rho, Rigid3* frame, Twist* twists) {
  for (int k = 0; k < 3; ++k) twists[k].v = frame->rotation.col(k);
  *frame = *frame * Rigid3::FromTranslation(Eigen::Vector3d(rho[0], rho[1], rho[2]));
  const Eigen::Vector3d r(rho[3], rho[4], rho[5]);
  const Eigen::Matrix3d exp_r = ExpSO3<double>(r);
  const Eigen::Matrix3d axes = frame->rotation * exp_r * RightJacobianSO3(r);
  for (int k = 0; k < 3; ++k) {
    twists[3 + k].omega = axes.col(k);
    twists[3 + k].v = frame->translation.cross(twists[3 + k].omega);
  }
  *frame = *frame * Rigid3::FromRotation(exp_r);
}

// Appends a rotation about the chain's current `axis` (0 x, 1 y, 2 z) by `angle`, its twist in *twist.
void AppendRotation(int axis, double angle, Rigid3* frame, Twist* twist) {
  twist->omega = frame->rotation.col(axis);
  twist->v = frame->translation.cross(twist->omega);
  const Eigen::Matrix3d r = axis == 0 ? RotX(angle) : axis == 1 ? RotY(angle) : RotZ(angle);
  *frame = *frame * Rigid3::FromRotation(r);
}

void AppendTranslation(int axis, double length, Rigid3* frame, Twist* twist) {
  twist->v = frame->rotation.col(axis);
  *frame = *frame * Rigid3::FromTranslation(length * Eigen::Vector3d::Unit(axis));
}

// The twist of every rho entry at one pose (zero for a link entry of a flange-pose set, which takes no
// part), composing base_from_flange (through the joints, or base_from_link0 * Exp(base) * the recorded flange
// pose) on the way. Returns that pose; the base and link twists are those of base_from_flange.
Rigid3 FlangePoseAndTwists(const BundleData& data, int pose, const double* rho, std::vector<Twist>* twists) {
  const RobotModel& model = data.robot;
  twists->assign(model.num_parameters(), Twist());
  Rigid3 frame = model.base_from_link0;
  AppendCorrection(rho, &frame, twists->data());
  if (!data.base_from_flange.empty()) return frame * data.base_from_flange[pose];
  const Eigen::VectorXd& q = data.joints[pose];
  for (int i = 0; i < model.num_joints(); ++i) {
    const int o = KinematicParameters::JointOffset(i);
    const double* p = rho + o;
    Twist* t = twists->data() + o;
    AppendRotation(0, p[0], &frame, &t[0]);
    AppendTranslation(0, p[1], &frame, &t[1]);
    AppendRotation(1, p[2], &frame, &t[2]);
    AppendRotation(2, q[i] + p[3], &frame, &t[3]);
    AppendTranslation(2, p[4], &frame, &t[4]);
  }
  return frame * model.link_n_from_flange;
}

// The adjoint of T^-1 for T = (R, p): Ad(omega, v) = (R^T omega, R^T (v - p x omega)).
Twist InverseAdjoint(const Rigid3& t, const Twist& xi) {
  Twist out;
  out.omega = t.rotation.transpose() * xi.omega;
  out.v = t.rotation.transpose() * (xi.v - t.translation.cross(xi.omega));
  return out;
}

// The twist of every rho entry at one pose, for points_from_cam (R, p) in the points' frame: dR = [omega]x R,
// dp = omega x p + v. Eye-in-hand that is base_from_cam in the base frame, the chain through the flange and
// the camera correction. Eye-to-hand, points_from_cam = F^-1 C with F = base_from_flange and C = base_from_cam
// * Exp(cam correction): a base or link twist xi of F gives -Ad(F^-1) xi, a camera twist xi_c of C gives
// Ad(F^-1) xi_c (both twists in the base frame, the result in the flange frame).
void CameraPoseAndTwists(const BundleData& data, int pose, const double* rho, std::vector<Twist>* twists) {
  const RobotModel& model = data.robot;
  Rigid3 frame = FlangePoseAndTwists(data, pose, rho, twists);
  const int cam = KinematicParameters(model.num_joints()).CamOffset();
  if (model.mount == CameraMount::kEyeInHand) {
    frame = frame * model.flange_from_cam;
    AppendCorrection(rho + cam, &frame, twists->data() + cam);
    return;
  }
  for (int k = 0; k < cam; ++k) {
    const Twist t = InverseAdjoint(frame, (*twists)[k]);
    (*twists)[k].omega = -t.omega;
    (*twists)[k].v = -t.v;
  }
  Rigid3 camera = model.base_from_cam;
  AppendCorrection(rho + cam, &camera, twists->data() + cam);
  for (int k = cam; k < cam + 6; ++k) (*twists)[k] = InverseAdjoint(frame, (*twists)[k]);
}

}  // namespace

void ComputePoseCache(const BundleData& data, int pose, const double* rho, const std::vector<int>& columns,
                      bool derivatives, PoseCache* out) {
  const Eigen::VectorXd& q = data.joints[pose];
  const int m = static_cast<int>(columns.size());
  if (!derivatives || m == 0) {
    const Rigid3 cam_from_points = PointsFromCamOf<double>(data, pose, rho, q.data()).Inverse();
    out->rotation = cam_from_points.rotation;
    out->translation = cam_from_points.translation;
    out->omega.assign(derivatives ? m : 0, Eigen::Vector3d::Zero());
    out->v.assign(derivatives ? m : 0, Eigen::Vector3d::Zero());
    return;
  }
  // The pose itself as the cost's evaluation computes it, to the bit (the chain of the twists composes it
  // in another order).
  std::vector<Twist> twists;
  CameraPoseAndTwists(data, pose, rho, &twists);
  const Rigid3 cam_from_points = PointsFromCamOf<double>(data, pose, rho, q.data()).Inverse();
  out->rotation = cam_from_points.rotation;
  out->translation = cam_from_points.translation;
  out->omega.resize(m);
  out->v.resize(m);
  for (int k = 0; k < m; ++k) {
    out->omega[k] = twists[columns[k]].omega;
    out->v[k] = twists[columns[k]].v;
  }
}

bool EvaluateReprojection(const IntrinsicsVector& in, double sigma_px, const PoseCache& cache, const Eigen::Vector3d& dot,
                          const Eigen::Vector2d& pixel, double* residual, double* d_columns, double* d_intrinsics,
                          double* d_dot) {
  const Eigen::Vector3d p = cache.rotation * dot + cache.translation;
  if (!(p.z() > 0) || !p.allFinite()) return false;
  const double inv_z = 1.0 / p.z();
  const double x = p.x() * inv_z, y = p.y() * inv_z;
  const double fx = in[kFx], mu = in[kMu];
  const double k1 = in[kK1], k2 = in[kK2], p1 = in[kP1], p2 = in[kP2], k3 = in[kK3];
  // camera.h's DistortNormalized and ProjectWithIntrinsics term for term, so that zero coefficients add
  // exact zeros: a k1-only camera gives the bits of fx x (1 + k1 r^2) + c_x, as before the full lens.
  const double r2 = x * x + y * y;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
  const double tx = 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
  const double ty = p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
  const double inv_sigma = 1.0 / sigma_px;
  const double u = fx * x * radial + fx * tx + in[kCx];
  const double v = fx * mu * y * radial + fx * mu * ty + in[kCy];
  const double r0 = (u - pixel.x()) * inv_sigma, r1 = (v - pixel.y()) * inv_sigma;
  if (!std::isfinite(r0) || !std::isfinite(r1)) return false;
  residual[0] = r0;
  residual[1] = r1;
  if (d_intrinsics != nullptr) {
    double* du = d_intrinsics;
    double* dv = d_intrinsics + kNumIntrinsics;
    du[kFx] = (x * radial + tx) * inv_sigma;
    dv[kFx] = (mu * y * radial + mu * ty) * inv_sigma;
    du[kMu] = 0.0;
    dv[kMu] = fx * (y * radial + ty) * inv_sigma;
    du[kCx] = inv_sigma;
    dv[kCx] = 0.0;
    du[kCy] = 0.0;
    dv[kCy] = inv_sigma;
    du[kK1] = fx * x * r2 * inv_sigma;
    dv[kK1] = fx * mu * y * r2 * inv_sigma;
    du[kK2] = fx * x * r2 * r2 * inv_sigma;
    dv[kK2] = fx * mu * y * r2 * r2 * inv_sigma;
    du[kK3] = fx * x * r2 * r2 * r2 * inv_sigma;
    dv[kK3] = fx * mu * y * r2 * r2 * r2 * inv_sigma;
    du[kP1] = fx * 2.0 * x * y * inv_sigma;
    dv[kP1] = fx * mu * (r2 + 2.0 * y * y) * inv_sigma;
    du[kP2] = fx * (r2 + 2.0 * x * x) * inv_sigma;
    dv[kP2] = fx * mu * 2.0 * x * y * inv_sigma;
  }
  if (d_columns == nullptr && d_dot == nullptr) return true;
  const double dr = k1 + 2.0 * k2 * r2 + 3.0 * k3 * r2 * r2;  // d radial / d r^2
  const double dtx_dx = 2.0 * p1 * y + 6.0 * p2 * x, dtx_dy = 2.0 * p1 * x + 2.0 * p2 * y;
  const double dty_dx = 2.0 * p1 * x + 2.0 * p2 * y, dty_dy = 6.0 * p1 * y + 2.0 * p2 * x;
  Eigen::Matrix2d d_uv_d_xy;
  d_uv_d_xy << fx * (radial + 2 * dr * x * x + dtx_dx), fx * 2 * dr * x * y + fx * dtx_dy,
      fx * mu * 2 * dr * x * y + fx * mu * dty_dx, fx * mu * (radial + 2 * dr * y * y + dty_dy);
  Eigen::Matrix<double, 2, 3> d_xy_d_p;
  d_xy_d_p << inv_z, 0, -x * inv_z, 0, inv_z, -y * inv_z;
  const Eigen::Matrix<double, 2, 3> d_p = inv_sigma * d_uv_d_xy * d_xy_d_p;
  if (d_dot != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> out(d_dot);
    out = d_p * cache.rotation;
  }
  if (d_columns != nullptr) {
    // With A = d_p R: d(R p + t) = -R (omega x p + v), so the column is (A [p]x) omega - A v.
    const int m = static_cast<int>(cache.omega.size());
    const Eigen::Matrix<double, 2, 3> a = d_p * cache.rotation;
    const Eigen::Matrix<double, 2, 3> g = a * Skew<double>(dot);
    for (int c = 0; c < m; ++c) {
      const Eigen::Vector2d d = g * cache.omega[c] - a * cache.v[c];
      d_columns[c] = d[0];
      d_columns[m + c] = d[1];
    }
  }
  return true;
}

namespace {

int FindRoot(std::vector<int>* parent, int i) {
  while ((*parent)[i] != i) i = (*parent)[i] = (*parent)[(*parent)[i]];
  return i;
}

// Rows added block by block; Finish() gives a matrix with the same Gram matrix as all of them stacked: the
// stack itself while it has at most `width` rows, otherwise the upper triangle of its Householder QR. The
// rows are folded into that triangle whenever the buffer (the triangle and eight times `width` rows) is
// full, so the memory is O(width^2) whatever the number of rows.
class RowFolder {
 public:
  explicit RowFolder(int width) : width_(width), buffer_(9 * std::max(width, 1), width) {}

  void Add(const Eigen::Ref<const Eigen::MatrixXd>& rows) {
    if (used_ + rows.rows() > buffer_.rows()) Fold();
    if (used_ + rows.rows() > buffer_.rows()) buffer_.conservativeResize(used_ + rows.rows(), Eigen::NoChange);
    buffer_.middleRows(used_, rows.rows()) = rows;
    used_ += static_cast<int>(rows.rows());
  }

  Eigen::MatrixXd Finish() {
    if (used_ > width_) Fold();
    return buffer_.topRows(used_);
  }

 private:
  void Fold() {
    if (used_ <= width_) return;
    Eigen::Ref<Eigen::MatrixXd> rows = buffer_.topRows(used_);
    Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(rows);  // in place
    buffer_.topRows(width_).triangularView<Eigen::StrictlyLower>().setZero();
    used_ = width_;
  }

  int width_;
  Eigen::MatrixXd buffer_;
  int used_ = 0;
};

}  // namespace

namespace {

// The rows of one observation in the columns of its pose's camera motion (v, omega): d r / d p_cam =
// d_dot R^T (d_dot is d r / d p_base, p_cam = R p_base + t), d p_cam / d v = I, d p_cam / d omega =
// -[p_cam]x.
void AddPoseErrorColumns(const PoseCache& cache, const Eigen::Vector3d& dot, const double* d_dot,
                         const double* residual, int num_global, int pose, int row, Eigen::MatrixXd* b,
                         PoseErrorColumns* pose_errors) {
  const Eigen::Matrix<double, 2, 3, Eigen::RowMajor> d_base(d_dot);
  const Eigen::Matrix<double, 2, 6> j =
      d_base * cache.rotation.transpose() * SmallMotionJacobian(cache.rotation * dot + cache.translation);
  b->block<2, 6>(row, num_global + 6 * pose) = j;
  const Eigen::Vector2d r(residual[0], residual[1]);
  pose_errors->gradient.segment<6>(6 * pose) += j.transpose() * r;
  pose_errors->residual_sq += r.squaredNorm();
}

}  // namespace

bool ReducedJacobian(const BundleData& data, const BundleState& state, const GlobalColumns& columns,
                     Eigen::MatrixXd* reduced, PoseErrorColumns* pose_errors) {
  const int num_poses = static_cast<int>(data.joints.size());
  const int num_dots = static_cast<int>(data.dot_ids.size());
  const int num_kinematic = static_cast<int>(columns.kinematic.size());
  const int num_global = columns.size();
  const int width = num_global + (pose_errors != nullptr ? 6 * num_poses : 0);
  if (pose_errors != nullptr) {
    pose_errors->gradient = Eigen::VectorXd::Zero(6 * num_poses);
    pose_errors->global_gradient = Eigen::VectorXd::Zero(num_global);
    pose_errors->global_norm_sq = Eigen::VectorXd::Zero(num_global);
    pose_errors->residual_sq = 0;
  }
  std::vector<PoseCache> caches(num_poses);
  for (int p = 0; p < num_poses; ++p) {
    ComputePoseCache(data, p, state.rho.data(), columns.kinematic, true, &caches[p]);
  }
  // Dots joined by a yardstick share a residual, so they are eliminated together.
  std::vector<int> parent(num_dots);
  std::iota(parent.begin(), parent.end(), 0);
  for (const Yardstick& y : data.yardsticks) parent[FindRoot(&parent, y.dot_a)] = FindRoot(&parent, y.dot_b);
  std::vector<int> group_of(num_dots, -1), slot_of(num_dots, -1);
  std::vector<int> group_size;
  for (int d = 0; d < num_dots; ++d) {
    const int root = FindRoot(&parent, d);
    if (group_of[root] < 0) {
      group_of[root] = static_cast<int>(group_size.size());
      group_size.push_back(0);
    }
    group_of[d] = group_of[root];
    slot_of[d] = group_size[group_of[d]]++;
  }
  const int num_groups = static_cast<int>(group_size.size());
  std::vector<std::vector<int>> group_observations(num_groups), group_yardsticks(num_groups);
  for (size_t k = 0; k < data.observations.size(); ++k) {
    group_observations[group_of[data.observations[k].dot]].push_back(static_cast<int>(k));
  }
  for (size_t k = 0; k < data.yardsticks.size(); ++k) {
    group_yardsticks[group_of[data.yardsticks[k].dot_a]].push_back(static_cast<int>(k));
  }

  // The groups' rows are folded into one triangular factor as they come (RowFolder): the stacked matrix of
  // every group's rows, 3 x dots + yardsticks by the globals, was tens of megabytes at 2000 dots.
  RowFolder folder(width);
  std::vector<double> d_columns(2 * std::max(num_kinematic, 1));
  for (int g = 0; g < num_groups; ++g) {
    const int rows = 2 * static_cast<int>(group_observations[g].size()) + static_cast<int>(group_yardsticks[g].size());
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(rows, 3 * group_size[g]);
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(rows, width);
    int row = 0;
    for (int k : group_observations[g]) {
      const Observation& o = data.observations[k];
      double residual[2], d_intrinsics[2 * kNumIntrinsics], d_dot[6];
      if (!EvaluateReprojection(state.intrinsics, data.sigma_px, caches[o.pose], state.dots[o.dot], o.pixel, residual,
                                d_columns.data(), d_intrinsics, d_dot)) {
        return false;
      }
      for (int r = 0; r < 2; ++r) {
        for (int c = 0; c < num_kinematic; ++c) b(row + r, c) = d_columns[r * num_kinematic + c];
        int col = num_kinematic;
        for (int i : columns.intrinsics) b(row + r, col++) = d_intrinsics[r * kNumIntrinsics + i];
        for (int c = 0; c < 3; ++c) a(row + r, 3 * slot_of[o.dot] + c) = d_dot[3 * r + c];
      }
      if (pose_errors != nullptr) {
        AddPoseErrorColumns(caches[o.pose], state.dots[o.dot], d_dot, residual, num_global, o.pose, row, &b, pose_errors);
        pose_errors->global_gradient += b.block(row, 0, 2, num_global).transpose() * Eigen::Vector2d(residual[0], residual[1]);
        pose_errors->global_norm_sq += b.block(row, 0, 2, num_global).colwise().squaredNorm().transpose();
      }
      row += 2;
    }
    for (int k : group_yardsticks[g]) {
      const Yardstick& y = data.yardsticks[k];
      const Eigen::Vector3d diff = state.dots[y.dot_a] - state.dots[y.dot_b];
      const double norm = diff.norm();
      if (!(norm > 0)) return false;
      const Eigen::Vector3d d = diff / (norm * data.yardstick_sigma_m);
      a.block<1, 3>(row, 3 * slot_of[y.dot_a]) += d.transpose();
      a.block<1, 3>(row, 3 * slot_of[y.dot_b]) -= d.transpose();
      ++row;
    }
    // (I - P_a) b in the coordinates of Q: the rows of Q^T b below the rank of a.
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
    const int rank = static_cast<int>(qr.rank());
    if (rows <= rank) continue;
    b.applyOnTheLeft(qr.householderQ().adjoint());
    folder.Add(b.bottomRows(rows - rank));
  }
  *reduced = folder.Finish();
  return true;
}

std::vector<std::string> GlobalNames(const GlobalColumns& columns, int num_joints) {
  const KinematicParameters params(num_joints);
  std::vector<std::string> names;
  for (int i : columns.kinematic) names.push_back(params.name(i));
  for (int i : columns.intrinsics) names.push_back(IntrinsicName(i));
  return names;
}

std::vector<int> SelectionOrder(int num_joints, int num_intrinsics) {
  const int n = KinematicParameters(num_joints).size();
  std::vector<int> order;
  for (int k = 0; k < num_intrinsics; ++k) order.push_back(n + k);
  for (int c : identification::PreferredParameterOrder(num_joints)) order.push_back(c);
  return order;
}

bool CovarianceFromJacobian(const Eigen::MatrixXd& jacobian, const std::vector<std::string>& names,
                            Eigen::MatrixXd* covariance, std::string* message) {
  // Tighter than the rank selection's tolerance: a column kept there may still be too weak to invert.
  constexpr double kTolerance = 1e-10;
  const int cols = static_cast<int>(jacobian.cols());
  if (jacobian.rows() < cols || cols == 0) {
    *message = "uncertainty unavailable (fewer reduced rows than unknowns)";
    return false;
  }
  Eigen::VectorXd norms;
  std::vector<bool> zero;
  const Eigen::MatrixXd normalized = identification::NormalizeColumns(jacobian, kTolerance, &norms, &zero);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(normalized, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  std::vector<bool> involved(cols, false);
  for (int k = 0; k < cols; ++k) {
    if (sv[k] > kTolerance * sv[0]) continue;
    for (int j = 0; j < cols; ++j) involved[j] = involved[j] || std::abs(svd.matrixV()(j, k)) > 0.05;
  }
  std::string deficient;
  for (int j = 0; j < cols; ++j) {
    if (involved[j] || zero[j]) deficient += (deficient.empty() ? "" : ", ") + names[j];
  }
  if (!deficient.empty()) {
    *message = "uncertainty unavailable (rank deficient: " + deficient + ")";
    return false;
  }
  const Eigen::MatrixXd v = svd.matrixV();
  const Eigen::VectorXd inv_sv2 = sv.array().square().inverse();
  const Eigen::VectorXd inv_norms = norms.array().inverse();
  *covariance = inv_norms.asDiagonal() * (v * inv_sv2.asDiagonal() * v.transpose()) * inv_norms.asDiagonal();
  if (!covariance->allFinite()) {
    *message = "uncertainty unavailable (non-finite covariance)";
    return false;
  }
  *message = "ok";
  return true;
}

BundleData MakeBundleData(const ObservationSet& observations, double yardstick_sigma_m) {
  BundleData data;
  data.robot = observations.robot;
  data.camera = observations.camera;
  data.sigma_px = observations.pixel_noise_px;
  data.yardstick_sigma_m = yardstick_sigma_m;
  std::map<int, int> views;
  for (int p : observations.PosesWithRole(PoseRole::kIdentification)) {
    data.pose_ids.push_back(observations.poses[p].id);
    data.joints.push_back(observations.poses[p].joints_rad);
    if (observations.UsesFlangePoses()) data.base_from_flange.push_back(*observations.poses[p].base_from_flange);
    for (const auto& entry : observations.poses[p].dots_px) ++views[entry.first];
  }
  std::map<int, int> index_of;
  for (const auto& [dot, count] : views) {
    if (count < 2) continue;
    index_of[dot] = static_cast<int>(data.dot_ids.size());
    data.dot_ids.push_back(dot);
  }
  int pose = 0;
  for (int p : observations.PosesWithRole(PoseRole::kIdentification)) {
    for (const auto& [dot, pixel] : observations.poses[p].dots_px) {
      auto it = index_of.find(dot);
      if (it != index_of.end()) data.observations.push_back({pose, it->second, pixel});
    }
    ++pose;
  }
  // A flange-pose set is metric through its flange translations too: its yardsticks (when the caller left
  // any) are length constraints beside them.
  for (const KnownDistance& k : observations.yardsticks) {
    auto a = index_of.find(k.dot_a);
    auto b = index_of.find(k.dot_b);
    if (a != index_of.end() && b != index_of.end()) data.yardsticks.push_back({a->second, b->second, k.length_m});
  }
  return data;
}

bool AnalyzeGauge(const BundleData& data, const BundleState& state, const IntrinsicsMask& estimate,
                  double rank_tolerance, Gauge* gauge, const std::vector<int>& held) {
  const int num_joints = data.robot.num_joints();
  const int n = data.robot.num_parameters();
  GlobalColumns columns;
  columns.kinematic.resize(n);
  std::iota(columns.kinematic.begin(), columns.kinematic.end(), 0);
  columns.intrinsics = EstimatedIntrinsics(estimate);
  // The gauge is a property of the poses, the dots and the yardsticks, not of the stated pixel noise: the
  // pixel rows are weighted as at 1 px, so that a noise of 1e-150 px neither overflows the Jacobian (a
  // crash in the QR) nor makes the yardstick's rows vanish below the rank tolerance (scale then looked
  // unobservable and a length parameter was fixed: a false "insufficient excitation").
  BundleData unit_weights = data;
  unit_weights.sigma_px = 1.0;
  Eigen::MatrixXd reduced;
  if (!ReducedJacobian(unit_weights, state, columns, &reduced)) return false;
  const std::vector<std::string> names = GlobalNames(columns, num_joints);
  std::vector<int> order;
  for (int c : SelectionOrder(num_joints, static_cast<int>(columns.intrinsics.size()))) {
    if (std::find(held.begin(), held.end(), c) == held.end()) order.push_back(c);
  }
  const identification::RankSelection selection = identification::SelectColumns(reduced, order, rank_tolerance, names);
  *gauge = Gauge();
  for (int c : held) gauge->held_names.push_back(names[c]);
  for (int c : selection.kept) {
    if (c < n) {
      gauge->free_kinematic.push_back(c);
      gauge->free_names.push_back(names[c]);
    } else {
      gauge->intrinsics_identifiable[columns.intrinsics[c - n]] = true;
    }
  }
  for (int c : selection.dependent) {
    if (c < n) gauge->fixed_names.push_back(names[c]);
  }
  gauge->null_combinations = selection.null_combinations;
  gauge->condition_number = selection.condition_number;
  return true;
}

}  // namespace selfcal::bundle::internal
