// The order in which a session visits the planned poses, chosen so that it can track the dots through
// every move (issue: plans the session can run). The criteria the planner optimises do not depend on the
// order (pose 0 stays the reference of the relative measurements, and the identification poses stay
// before the verification ones); the session's identities do: a move that shifts the dots by more than
// the plan's image-motion bound, or a joint by more than its travel bound, loses them.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "planning/plan_problem.h"

namespace selfcal::planning {

struct VisitOrder {
  std::vector<int> order;       // order[k]: the index (in the given poses) visited k-th; order[0] = 0
  int moves_over_bounds = 0;    // moves beyond the image-motion or the joint-travel bound
  double max_image_motion_px = 0;  // the largest median image motion over the moves
};

// The order of `poses` (the first problem.num_identification_poses identify, the rest verify) that keeps
// pose 0 first, every identification pose before every verification pose, and minimises first the number
// of moves over the bounds and then the sum over the moves of (median image motion / bound)^4 (which
// drives the largest move down): a nearest-neighbour tour improved by segment reversals and single-pose
// moves inside each group until none helps. Deterministic.
VisitOrder OrderForTracking(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses);

}  // namespace selfcal::planning
