// Checks a measurement plan before the robot moves (issue 4 item 3; RELIABILITY.md C5-C7): every
// constraint of PlanConstraints, pose by pose, each violation with the pose(s) and the value, and the
// observability of the identification poses (rank against generic poses, condition number).
//
// The planner (planning/planner.h) keeps its plans strictly inside the same constraints; a plan written by
// hand is checked here, and `selfcal plan --check PLAN` prints the problems.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "planning/plan_problem.h"

namespace selfcal::planning {

enum class PlanIssue {
  kJointCount,          // C5: a pose with the wrong number of joint values
  kNonFinite,           // C5: NaN or Inf
  kJointLimit,          // C6: outside the limits less the margin
  kTooFewPoses,         // C7: fewer identification poses than required, or no verification pose
  kTooClose,            // C7: two camera centres closer than min_spread_m (duplicates)
  kOutOfImage,          // a scene point outside the image less the margin
  kDepth,               // a scene point behind the camera, or nearer/farther than the depth range
  kAxesIntersect,       // f_x unobservable from the pair (reference, i)
  kJointTravel,         // a joint moves more than max_joint_travel_rad between consecutive poses
  kInsufficientExcitation,  // C7: rank below generic poses', or condition number above the bound
};
const char* PlanIssueName(PlanIssue issue);

struct PlanProblemItem {
  PlanIssue issue;
  int pose = -1;        // 0-based; -1 for the whole plan
  int other_pose = -1;  // the second pose of a pair, else -1
  std::string message;  // names the pose(s), the quantity, its value and the bound
};

struct PlanCheck {
  bool ok = false;  // no problem found
  std::vector<PlanProblemItem> problems;
  // Figures of the plan (when the joint values were usable).
  double min_spread_m = 0;          // smallest camera-centre distance between two poses
  double min_axis_sine = 0;         // smallest axis sine over the pairs (reference, i)
  double min_image_margin_px = 0;   // smallest distance of a scene point to the image border
  double max_joint_travel_rad = 0;  // largest joint change between consecutive poses
  int identifiable = 0, generic_identifiable = 0;
  double condition_number = 0;      // column-normalised identification Jacobian (identification poses)
  std::string Summary() const;      // one line per problem, or "plan ok"
};

// Checks `poses` (rad; the first problem.num_identification_poses identify, the rest verify; the first
// is the reference of the relative measurements). Never throws on bad pose data: that is what it reports.
PlanCheck CheckPlan(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses);

}  // namespace selfcal::planning
