#include "planning/barrier_objective.h"

#include <cmath>

#include <ceres/jet.h>

#include "planning/eq39.h"
#include "planning/pose_twists.h"
#include "planning/view_geometry.h"

namespace selfcal::planning::internal {

namespace {

// Robots up to 7 joints (the Panda); unused derivative slots stay zero.
using JointJet = ceres::Jet<double, kMaxJoints>;
using PairJet = ceres::Jet<double, 2 * kMaxJoints>;
using PointJet = ceres::Jet<double, 3>;  // a camera-frame point's coordinates

// A pose's camera, its centre and optical axis with their derivatives with respect to its own joints, and
// the joints' spatial twists (planning/pose_twists.h; zero for a pose that is not optimised).
struct View {
  Rigid3 base_from_cam;
  Vec3T<JointJet> centre, axis;
  Eigen::Matrix<double, 3, kMaxJoints> omega = Eigen::Matrix<double, 3, kMaxJoints>::Zero();
  Eigen::Matrix<double, 3, kMaxJoints> v = Eigen::Matrix<double, 3, kMaxJoints>::Zero();
};

// d R / d q_j = [omega_j]x R and d c / d q_j = omega_j x c + v_j, from the twist of theta_j (which moves the
// camera as q_j does): the derivatives in double, no Jets through the chain.
View ViewOf(const RobotModel& robot, const Eigen::VectorXd& q, bool with_derivatives) {
  View view;
  if (!with_derivatives) {
    view.base_from_cam = PointsFromCam(robot, KinematicParameters::Nominal(robot), q);
  } else {
    Eigen::Matrix<double, 3, Eigen::Dynamic> omega, v;
    view.base_from_cam = ComputeJointTwists<double>(robot, q.data(), &omega, &v);
    view.omega.leftCols(robot.num_joints()) = omega;
    view.v.leftCols(robot.num_joints()) = v;
  }
  const Eigen::Vector3d c = view.base_from_cam.translation, z = view.base_from_cam.rotation.col(2);
  for (int r = 0; r < 3; ++r) {
    view.centre[r] = JointJet(c[r]);
    view.axis[r] = JointJet(z[r]);
  }
  for (int j = 0; with_derivatives && j < robot.num_joints(); ++j) {
    const Eigen::Vector3d w = view.omega.col(j);
    const Eigen::Vector3d dc = w.cross(c) + view.v.col(j), dz = w.cross(z);
    for (int r = 0; r < 3; ++r) {
      view.centre[r].v[j] = dc[r];
      view.axis[r].v[j] = dz[r];
    }
  }
  return view;
}

PairJet Promote(const JointJet& x, int offset) {
  PairJet y(x.a);
  for (int k = 0; k < kMaxJoints; ++k) y.v[offset + k] = x.v[k];
  return y;
}

Vec3T<PairJet> Promote(const Vec3T<JointJet>& x, int offset) {
  return Vec3T<PairJet>(Promote(x[0], offset), Promote(x[1], offset), Promote(x[2], offset));
}

}  // namespace

BarrierObjective::BarrierObjective(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses,
                                   const std::vector<int>& free_columns, double lambda)
    : problem_(problem), poses_(poses), free_columns_(free_columns), lambda_(lambda) {}

int BarrierObjective::NumParameters() const {
  return problem_.num_identification_poses * problem_.robot.num_joints();
}

bool BarrierObjective::Barrier(const std::vector<Eigen::VectorXd>& poses, double* value, Eigen::VectorXd* gradient,
                               int* num_constraints) const {
  const RobotModel& robot = problem_.robot;
  const PlanConstraints& c = problem_.constraints;
  const int n = robot.num_joints(), m = static_cast<int>(poses.size()), m_id = problem_.num_identification_poses;
  double sum = 0;
  int count = 0;
  Eigen::VectorXd grad = Eigen::VectorXd::Zero(m_id * n);
  auto term = [&](double slack) {
    ++count;
    if (!(slack > 0)) return false;
    sum -= std::log(slack);
    return true;
  };
  // Adds -d log(slack) = -d slack / slack for the joints of pose `pose` (an identification pose).
  auto push = [&](int pose, double slack, const double* d_slack) {
    if (pose >= m_id) return;
    for (int j = 0; j < n; ++j) grad[pose * n + j] -= d_slack[j] / slack;
  };
  // Joint limits less the margin (identification poses).
  for (int i = 0; i < m_id; ++i) {
    for (int j = 0; j < n; ++j) {
      const double lo = poses[i][j] - (robot.limits[j].min_rad + c.joint_margin_rad);
      const double hi = (robot.limits[j].max_rad - c.joint_margin_rad) - poses[i][j];
      if (!term(lo) || !term(hi)) return false;
      grad[i * n + j] += -1.0 / lo + 1.0 / hi;
    }
  }
  // Every scene point in every identification image, in the depth range: p = R^T (x - c) with
  // d p / d q_j = -R^T (omega_j x x + v_j) (planning/fisher_design.h's derivative), the projection
  // differentiated with respect to p only.
  std::vector<View> views(m);
  double d[kMaxJoints];
  for (int i = 0; i < m; ++i) {
    views[i] = ViewOf(robot, poses[i], i < m_id);
    if (i >= m_id) continue;
    const Eigen::Matrix3d rt = views[i].base_from_cam.rotation.transpose();
    const Eigen::Vector3d centre = views[i].base_from_cam.translation;
    Eigen::Matrix<double, 3, kMaxJoints> dp_dq;
    for (const Eigen::Vector3d& x : problem_.scene.extent_in_base) {
      const Eigen::Vector3d p = rt * (x - centre);
      for (int j = 0; j < n; ++j) dp_dq.col(j) = -(rt * (views[i].omega.col(j).cross(x) + views[i].v.col(j)));
      // A slack's derivative with respect to the joints from its derivative with respect to p.
      auto push_slack = [&](const PointJet& s) {
        if (!term(s.a)) return false;
        for (int j = 0; j < n; ++j) d[j] = s.v.dot(dp_dq.col(j));
        push(i, s.a, d);
        return true;
      };
      const Vec3T<PointJet> pj(PointJet(p.x(), 0), PointJet(p.y(), 1), PointJet(p.z(), 2));
      if (!push_slack(pj.z() - PointJet(c.min_depth_m)) || !push_slack(PointJet(c.max_depth_m) - pj.z())) return false;
      PointJet u, v;
      if (!ProjectPoint<PointJet>(problem_.camera, PointJet(problem_.camera.fx_px), PointJet(problem_.camera.k1), pj, &u, &v)) {
        return false;
      }
      const PointJet margin(c.image_margin_px);
      const PointJet image[4] = {u - margin, PointJet(problem_.camera.width_px - 1) - margin - u, v - margin,
                                 PointJet(problem_.camera.height_px - 1) - margin - v};
      for (const PointJet& s : image) {
        if (!push_slack(s)) return false;
      }
    }
  }
  // Camera centres apart: |c_a - c_b|^2 - d_min^2 > 0 for pairs with an identification pose.
  const double d2 = c.min_spread_m * c.min_spread_m;
  for (int a = 0; a < m_id; ++a) {
    for (int b = a + 1; b < m; ++b) {
      const Vec3T<PairJet> diff = Promote(views[a].centre, 0) - Promote(views[b].centre, kMaxJoints);
      const PairJet s = diff.squaredNorm() - PairJet(d2);
      if (!term(s.a)) return false;
      push(a, s.a, s.v.data());
      push(b, s.a, s.v.data() + kMaxJoints);
    }
  }
  // Optical axes of (reference, i) apart: tau^2 - s^2 |d x z|^2 > 0 for both axes, over |d|^2.
  const double s2 = c.min_axis_sine * c.min_axis_sine;
  for (int i = 1; c.min_axis_sine > 0 && i < m_id; ++i) {
    const Vec3T<PairJet> c0 = Promote(views[0].centre, kMaxJoints), z0 = Promote(views[0].axis, kMaxJoints);
    const Vec3T<PairJet> ci = Promote(views[i].centre, 0), zi = Promote(views[i].axis, 0);
    const Vec3T<PairJet> dd = ci - c0;
    const PairJet tau = zi.dot(dd.cross(z0));
    const PairJet inv = PairJet(1.0) / dd.squaredNorm();
    const PairJet slacks[2] = {(tau * tau - PairJet(s2) * dd.cross(z0).squaredNorm()) * inv,
                             (tau * tau - PairJet(s2) * dd.cross(zi).squaredNorm()) * inv};
    for (const PairJet& s : slacks) {
      if (!term(s.a)) return false;
      push(i, s.a, s.v.data());
      push(0, s.a, s.v.data() + kMaxJoints);
    }
  }
  // Joint travel between consecutive poses.
  for (int i = 1; i < m && i <= m_id; ++i) {
    for (int j = 0; j < n; ++j) {
      const double delta = poses[i][j] - poses[i - 1][j];
      const double up = c.max_joint_travel_rad - delta, down = c.max_joint_travel_rad + delta;
      if (!term(up) || !term(down)) return false;
      // d(-log up)/d q_i = 1/up, d/d q_{i-1} = -1/up; d(-log down)/d q_i = -1/down, d/d q_{i-1} = 1/down.
      if (i < m_id) grad[i * n + j] += 1.0 / up - 1.0 / down;
      grad[(i - 1) * n + j] += -1.0 / up + 1.0 / down;
    }
  }
  *value = sum;
  if (gradient) *gradient = grad;
  if (num_constraints) *num_constraints = count;
  return true;
}

bool BarrierObjective::Evaluate(const double* x, double* cost, double* gradient) const {
  ++evaluations_;
  const int n = problem_.robot.num_joints(), m_id = problem_.num_identification_poses;
  std::vector<Eigen::VectorXd> poses = poses_;
  for (int i = 0; i < m_id; ++i) poses[i] = Eigen::Map<const Eigen::VectorXd>(x + i * n, n);
  double barrier = 0;
  Eigen::VectorXd barrier_gradient;
  if (!Barrier(poses, &barrier, gradient ? &barrier_gradient : nullptr, nullptr)) return false;
  const std::vector<Eigen::VectorXd> id(poses.begin(), poses.begin() + m_id);
  const Eq39Value e = EvaluateEq39(problem_.robot, id, free_columns_, lambda_, gradient != nullptr);
  if (!std::isfinite(e.total)) return false;
  *cost = e.total + mu_ * barrier;
  if (gradient) {
    for (int k = 0; k < m_id * n; ++k) gradient[k] = e.gradient[k] + mu_ * barrier_gradient[k];
  }
  return true;
}

}  // namespace selfcal::planning::internal
