#include "planning/eq39.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <ceres/jet.h>

#include "base/status.h"
#include "planning/pose_twists.h"

namespace selfcal::planning {

namespace {

// Partials: slots [0, 7) the joints of pose i, [7, 14) those of the reference pose (robots up to 7 joints:
// the Panda). Unused slots stay zero, so a 6-joint robot's values and gradients are those of 12 slots.
constexpr int kSlots = 2 * kMaxJoints;
using Jet = ceres::Jet<double, kSlots>;
using JetMatrix = Eigen::Matrix<Jet, Eigen::Dynamic, Eigen::Dynamic>;

internal::CameraTwists<Jet> Twists(const RobotModel& model, const Eigen::VectorXd& q, int slot_offset) {
  std::vector<Jet> qj(model.num_joints());
  for (int j = 0; j < model.num_joints(); ++j) {
    qj[j] = Jet(q[j]);
    qj[j].v[slot_offset + j] = 1.0;
  }
  return internal::ComputeCameraTwists<Jet>(model, qj.data());
}

struct PoseTerms {
  std::vector<Jet> g;  // d log||t_i|| / d rho, every rho entry
  JetMatrix m;         // 6 x free: [d omega ; d omega x p_i + d v]
};

PoseTerms Terms(const internal::CameraTwists<Jet>& pose, const internal::CameraTwists<Jet>& ref,
                const std::vector<int>& free_columns) {
  const int p = static_cast<int>(pose.omega.size());
  PoseTerms out;
  out.g.resize(p);
  const Vec3T<Jet>& pi = pose.base_from_cam.translation;
  const Vec3T<Jet> d = pi - ref.base_from_cam.translation;
  const Jet inv_dd = Jet(1.0) / d.squaredNorm();
  std::vector<Vec3T<Jet>> dw(p), vel(p);
  for (int k = 0; k < p; ++k) {
    dw[k] = pose.omega[k] - ref.omega[k];
    vel[k] = dw[k].cross(pi) + (pose.v[k] - ref.v[k]);
    out.g[k] = d.dot(vel[k]) * inv_dd;
  }
  out.m.resize(6, free_columns.size());
  for (size_t c = 0; c < free_columns.size(); ++c) {
    const int k = free_columns[c];
    out.m.block(0, c, 3, 1) = dw[k];
    out.m.block(3, c, 3, 1) = vel[k];
  }
  return out;
}

// Values of J: the blocks of poses 1 .. m-1 stacked.
Eigen::MatrixXd StackJ(const std::vector<PoseTerms>& terms, int nf) {
  const int m = static_cast<int>(terms.size());
  Eigen::MatrixXd j(6 * (m - 1), nf);
  for (int i = 1; i < m; ++i) {
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < nf; ++c) j(6 * (i - 1) + r, c) = terms[i].m(r, c).a;
    }
  }
  return j;
}

void CheckArguments(const RobotModel& model, const std::vector<Eigen::VectorXd>& poses,
                    const std::vector<int>& free_columns) {
  SELFCAL_CHECK(model.num_joints() <= kMaxJoints, "eq. (39) supports up to " << kMaxJoints << " joints, the robot has "
                                                                              << model.num_joints());
  SELFCAL_CHECK(poses.size() >= 3, "eq. (39) needs at least 3 poses, got " << poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    SELFCAL_CHECK(poses[i].size() == model.num_joints() && poses[i].allFinite(),
                  "pose " << i << " must have " << model.num_joints() << " finite joint values");
  }
  for (int k : free_columns) {
    SELFCAL_CHECK(k >= 0 && k < model.num_parameters(), "free column " << k << " outside the parameters");
  }
  SELFCAL_CHECK(!free_columns.empty(), "no free columns");
}

}  // namespace

Eigen::MatrixXd TwistIdentificationJacobian(const RobotModel& model, const std::vector<Eigen::VectorXd>& poses,
                                            const std::vector<int>& free_columns) {
  CheckArguments(model, poses, free_columns);
  const int m = static_cast<int>(poses.size());
  const internal::CameraTwists<Jet> ref = Twists(model, poses[0], kMaxJoints);
  std::vector<PoseTerms> terms(m);
  for (int i = 1; i < m; ++i) terms[i] = Terms(Twists(model, poses[i], 0), ref, free_columns);
  return StackJ(terms, static_cast<int>(free_columns.size()));
}

Eq39Value EvaluateEq39(const RobotModel& model, const std::vector<Eigen::VectorXd>& poses,
                       const std::vector<int>& free_columns, double lambda, bool with_gradient) {
  CheckArguments(model, poses, free_columns);
  const int m = static_cast<int>(poses.size());
  const int n = model.num_joints();
  const int p = model.num_parameters();
  const int nf = static_cast<int>(free_columns.size());
  SELFCAL_CHECK(6 * (m - 1) >= nf, "J has " << 6 * (m - 1) << " rows for " << nf << " free parameters");

  const internal::CameraTwists<Jet> ref = Twists(model, poses[0], kMaxJoints);
  std::vector<PoseTerms> terms(m);
  for (int i = 1; i < m; ++i) terms[i] = Terms(Twists(model, poses[i], 0), ref, free_columns);

  Eq39Value value;
  value.lambda = lambda;
  // ||G||_F over the rows g_i - g_{i-1}, i = 2 .. m-1.
  double sum = 0;
  for (int i = 2; i < m; ++i) {
    for (int k = 0; k < p; ++k) {
      const double r = terms[i].g[k].a - terms[i - 1].g[k].a;
      sum += r * r;
    }
  }
  value.ratio_term = std::sqrt(sum);

  const Eigen::MatrixXd j = StackJ(terms, nf);
  // Extreme singular values and vectors from the eigen-decomposition of J^T J (nf x nf, much cheaper than an
  // SVD of J; Cond(J) of a few thousand loses nothing in the squaring): sigma^2 = eigenvalue, u = J v / sigma.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(j.transpose() * j);
  const double s_max = std::sqrt(std::max(eigen.eigenvalues()(nf - 1), 0.0));
  const double s_min = std::sqrt(std::max(eigen.eigenvalues()(0), 0.0));
  value.condition_number = s_min > 0 ? s_max / s_min : std::numeric_limits<double>::infinity();
  value.total = value.ratio_term + lambda * value.condition_number;
  if (!with_gradient) return value;

  value.gradient = Eigen::VectorXd::Zero(m * n);
  auto add = [&](int pose, const Jet& x, double coefficient, int slot_offset) {
    for (int j2 = 0; j2 < n; ++j2) value.gradient[pose * n + j2] += coefficient * x.v[slot_offset + j2];
  };
  if (value.ratio_term > 0) {
    for (int i = 2; i < m; ++i) {
      for (int k = 0; k < p; ++k) {
        const double c = (terms[i].g[k].a - terms[i - 1].g[k].a) / value.ratio_term;
        if (c == 0) continue;
        add(i, terms[i].g[k], c, 0);
        add(0, terms[i].g[k], c, kMaxJoints);
        add(i - 1, terms[i - 1].g[k], -c, 0);
        add(0, terms[i - 1].g[k], -c, kMaxJoints);
      }
    }
  }
  if (lambda != 0 && std::isfinite(value.condition_number)) {
    const Eigen::VectorXd v_max = eigen.eigenvectors().col(nf - 1), v_min = eigen.eigenvectors().col(0);
    const Eigen::VectorXd u_max = j * v_max / s_max, u_min = j * v_min / s_min;
    // d Cond = (d s_max - Cond d s_min) / s_min,  d s = u^T dJ v.
    for (int i = 1; i < m; ++i) {
      for (int r = 0; r < 6; ++r) {
        const int row = 6 * (i - 1) + r;
        for (int c = 0; c < nf; ++c) {
          const double w = (u_max[row] * v_max[c] - value.condition_number * u_min[row] * v_min[c]) / s_min;
          if (w == 0) continue;
          add(i, terms[i].m(r, c), lambda * w, 0);
          add(0, terms[i].m(r, c), lambda * w, kMaxJoints);
        }
      }
    }
  }
  return value;
}

}  // namespace selfcal::planning
