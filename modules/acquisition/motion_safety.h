// Motion safety before the first move (../shared/RELIABILITY.md C5, C6, R1-R3, design rule 3): the plan is checked
// by planning::CheckPlanFor, the same check and words as `selfcal plan --check` (robot name, limits of the
// config and of the controller less the margin, per-move travel, velocity limits, and the plan's
// geometry when its file records `planned_for`); the first move from where the arm is is bounded too, the
// moves are timed within the velocity limits times the scaling, and the operator gets a preview to
// confirm. Pure functions: no robot is touched here.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "kinematics/robot_model.h"
#include "observations/observation_set.h"
#include "planning/plan_check.h"
#include "robot/robot.h"
#include "session/planned_pose.h"

namespace selfcal::acquisition {

// A pose of the plan: the session's type (session/planned_pose.h), the same for the loop and the journal.
using session::PlannedPose;

struct MotionSafetyOptions {
  double velocity_scaling = 0.1;                 // R1: real robots start slow; (0, 1]
  double max_joint_travel_rad = 1.5707963267948966;  // R2: per joint per move (easy_handeye's 90 deg)
  double limit_margin_rad = 0.0;                 // kept clear of each joint limit
  double start_tolerance_rad = 0.01;             // R4: actual vs expected joints before a move
  std::string Validate() const;                  // empty when valid
};

// The whole plan as its file gave it and the robot config: what CheckPlanFor checks.
struct PlanToCheck {
  RobotModel robot;
  planning::PlanSubject plan;
};

struct MoveSummary {
  int pose = -1;                  // the target pose (index in the plan)
  double max_travel_rad = 0;      // largest joint travel of the move
  int limiting_joint = -1;        // the joint that sets the duration
  double duration_s = 0;          // at the scaling: robot::QuinticMoveDuration
};

struct PreflightReport {
  std::vector<std::string> problems;  // each names the pose, joint, value and bound; empty = go
  planning::PlanCheck check;          // the plan check's verdict, figures and scope
  std::vector<MoveSummary> moves;     // start -> pose 0 -> pose 1 ...
  double total_motion_s = 0;
  bool ok() const { return problems.empty(); }
  // The dry-run preview: one line per move (pose id, max travel deg, limiting joint, seconds), totals.
  std::string Preview(const std::vector<PlannedPose>& plan, double velocity_scaling) const;
};

// "preflight refused the plan:" and one line per problem: the words of every refusal of a plan by run.
std::string PreflightRefusal(const std::vector<std::string>& problems);
// The plan check's problems as the preflight lists them ("joint_limit: pose p03 joint 2 = ...").
std::vector<std::string> PreflightProblems(const planning::PlanCheck& check);

// With `whole_plan`: planning::CheckPlanFor of the whole plan against its robot config and the
// controller's `limits`; without: the same check of the route `plan` (from `first_pose`, named by its
// ids) against the controller's limits alone. Then the move from `start_rad` to the first pose (travel
// bound [R2]) and the timing of every move. `first_pose` skips the poses before it (a resumed session).
PreflightReport Preflight(const std::vector<PlannedPose>& plan, const robot::JointLimits& limits,
                          const Eigen::VectorXd& start_rad, const MotionSafetyOptions& options, int first_pose = 0,
                          const PlanToCheck* whole_plan = nullptr);

}  // namespace selfcal::acquisition
