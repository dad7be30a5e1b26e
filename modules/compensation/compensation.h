// Module compensation (ARCHITECTURE.md): Compensate, this header only. Uses kinematics, geometry, base.
//
// Compensation (docs/compensation.md): the joint angles that put the flange or the camera at target poses
// on the calibrated arm, for a controller that takes joint angles and no model.
//
// Per target: the nominal solution first (what a controller with the nominal model would command: inverse
// kinematics on `nominal`, seeded from the target's seed, else the previous target's nominal solution, else
// the middle of the joint limits), then the compensated one, inverse kinematics on `calibrated` seeded from
// the nominal solution. Both by Levenberg-Marquardt (damped least squares) on the pose error
//   [translation of target^-1 * reached (m); rotation vector of it (rad) * rotation_scale_m]
// with autodiff Jacobians through the model, damping (J^T J + lambda I) (kinematics/robot_model.h). A 7-joint arm's extra freedom is
// taken by the damping: the step nearest the seed.
// Outcomes per target: converged or not (residual above the tolerances after max_iterations), and the
// joints outside the calibrated model's limits, named by number.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "geometry/rigid3.h"
#include "kinematics/robot_model.h"

namespace selfcal::compensation {

enum class TargetFrame { kFlange, kCamera };

struct Target {
  Rigid3 base_from_target;             // the flange's or the camera's pose in the base frame (m)
  std::optional<Eigen::VectorXd> seed;  // rad, one per joint
};

struct IkOptions {
  int max_iterations = 200;
  double position_tolerance_m = 1e-9;     // converged: residual at or below both
  double rotation_tolerance_rad = 1e-9;
  double rotation_scale_m = 0.1;          // 1 rad of rotation error weighs as much as this many m
  std::string Validate() const;           // empty when valid
};

struct IkResult {
  Eigen::VectorXd q;        // rad
  bool converged = false;
  int iterations = 0;
  double position_residual_m = 0;   // |translation of target^-1 * reached|
  double rotation_residual_rad = 0;  // angle of its rotation
};

// Inverse kinematics on `model` (at its own parameters: Nominal(model)) from `seed`.
IkResult SolveIk(const RobotModel& model, TargetFrame frame, const Rigid3& base_from_target,
                 const Eigen::VectorXd& seed, const IkOptions& options = {});

struct TargetSolution {
  IkResult nominal;      // on the nominal model
  IkResult compensated;  // on the calibrated model, from the nominal solution
  std::vector<int> joints_outside_limits;  // 1-based, of the compensated solution against the limits
  bool ok() const { return compensated.converged && joints_outside_limits.empty(); }
};

struct CompensationReport {
  std::vector<TargetSolution> targets;
  int not_converged = 0;
  int outside_limits = 0;
  bool ok() const { return not_converged == 0 && outside_limits == 0; }
};

// `nominal` and `calibrated` must have the same joint count (checked). The limits are the calibrated
// model's.
CompensationReport Compensate(const RobotModel& nominal, const RobotModel& calibrated, TargetFrame frame,
                              const std::vector<Target>& targets, const IkOptions& options = {});

}  // namespace selfcal::compensation
