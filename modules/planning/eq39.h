// The paper's cost for optimal measurement configurations, eq. (39), with its gradient with respect to the
// joint angles of the identification poses.
//
//   E(Theta) = || G ||_F + lambda * Cond(J),
//   G = rows g_i - g_{i-1}, i = 2 .. m-1,   g_i = tbar_i^T Rbar_i (df/drho)(rho, theta_i) / ||tbar_i||^2.
//
// Reading of the paper (documented in docs/planning.md):
// - t_i is the position of pose i relative to the first (reference) pose, i = 1 .. m-1 (section 3.2,
//   Fig. 2), i.e. the translation of cam_0_from_cam_i. Then g_i = d log||t_i|| / d rho: eq. (38) asks
//   that the log of every ratio ||t_i|| / ||t_{i-1}||, the quantity eq. (21) takes from the nominal model,
//   be insensitive to parameter errors, to first order. (Rbar_i of eq. (35) maps the differential error to
//   the frame of t_i; we differentiate t_i in the reference camera frame directly, the same quantity.)
// - The sum in eq. (39) read literally telescopes to g_{m-1} - g_1, which would constrain two poses only.
//   The paper minimised it with a nonlinear least-squares solver, i.e. one residual per term: we take the
//   Frobenius norm of the matrix G whose rows are the terms, ||G||_F = sqrt(sum_i ||g_i - g_{i-1}||^2).
// - rho: every kinematic parameter (SI: m and rad); the columns that cannot move t_i (base, joint 1) are
//   zero. J: the identification Jacobian of the relative poses (rows rad and m, columns m and rad: SI, as
//   the paper's lambda = 1e-7 presumes) over the identifiable parameters.
// - lambda = 1e-7 by default: the paper's value (section 4.2, chosen from 1e-4 .. 1e-9); it makes the Cond
//   term nearly negligible, as the paper says. The planner's constraints (planning/plan_problem.h), not
//   lambda, keep the poses apart.
//
// Gradient: the rho-derivatives are spatial twists (planning/pose_twists.h) computed with Jets over the
// joint angles of pose i and of the reference pose, so dG/dtheta is exact (autodiff), and
// d sigma / dtheta = u^T (dJ/dtheta) v for the extreme singular values (simple ones).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "kinematics/robot_model.h"

namespace selfcal::planning {

struct Eq39Value {
  double ratio_term = 0;        // ||G||_F (1/m for lengths, 1/rad for angles: SI)
  double condition_number = 0;  // Cond(J), J in SI units over the free columns
  double lambda = 0;
  double total = 0;             // ratio_term + lambda * condition_number
  // d total / d theta, pose-major (pose 0's joints first), when asked for; size m * n.
  Eigen::VectorXd gradient;
};

// `poses`: the identification poses (rad), pose 0 the reference; `free_columns`: rho indices kept in J.
Eq39Value EvaluateEq39(const RobotModel& model, const std::vector<Eigen::VectorXd>& poses,
                       const std::vector<int>& free_columns, double lambda, bool with_gradient);

// J of eq. (39) (6 (m-1) rows: per pose i, rotation rows then translation rows, in the base frame; see
// planning/pose_twists.h), for tests and reports.
Eigen::MatrixXd TwistIdentificationJacobian(const RobotModel& model, const std::vector<Eigen::VectorXd>& poses,
                                            const std::vector<int>& free_columns);

}  // namespace selfcal::planning
