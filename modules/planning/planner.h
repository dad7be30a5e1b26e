// Module planning (ARCHITECTURE.md; docs/planning.md): eq. (39) with exact gradients (pose_twists.h:
// spatial twists of every parameter, Jets in the joints) by L-BFGS in a log barrier (barrier_objective.h);
// robots up to 7 joints; D-/A-optimal exchange designs on the bundle's Fisher information (fisher_design.h,
// exchange_kernels.h) over a seeded candidate pool (candidate_pool.h); repair of infeasible starts; the visit
// order the session can track (visit_order.h: every move within the image-motion and travel bounds where an
// order allows it); CheckPlan (plan_check.h: C5-C7, every constraint named by pose); observability indices
// and predicted parameter std (observability.h). Uses identification, kinematics, camera, geometry, base;
// Ceres private.
//
// Measurement-configuration planning (issue 4): from a feasible start plan, m poses (the first
// num_identification_poses identify, the rest verify) that minimise a criterion under the constraints of
// planning/plan_problem.h.
//
// Criteria:
// - kEq39: the paper's eq. (39) (planning/eq39.h), minimised over the joint angles of the identification
//   poses by L-BFGS (Ceres GradientProblemSolver) on eq. (39) plus a logarithmic barrier for every
//   constraint (joint limits less the margin, every scene point in the image and in the depth range, camera
//   centres apart, optical axes of (reference, i) not intersecting, joint travel between consecutive
//   poses). The barrier keeps every iterate strictly feasible (an infeasible trial point is rejected and the
//   line search shortens the step); its weight falls by barrier_decrease each round, so the result
//   approaches the constrained minimum of eq. (39). Gradients: exact (Jets), see eq39.h. Deterministic.
// - kDOptimal, kAOptimal: the Fisher information of the kinematic bundle adjustment
//   (planning/fisher_design.h): identification poses exchanged with the poses of a seeded candidate pool
//   (Fedorov exchange) to maximise log det of the information of (identifiable parameters, f_x) with the
//   dots marginalised (D), or to minimise the sum of their variances relative to their prior spread (A).
// The verification poses of the start are kept: every criterion is judged on the same held-out poses.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/progress.h"
#include "planning/eq39.h"
#include "planning/fisher_design.h"
#include "planning/plan_check.h"
#include "planning/plan_problem.h"

namespace selfcal::planning {

enum class Criterion { kEq39, kDOptimal, kAOptimal };
const char* CriterionName(Criterion criterion);
// "eq39", "d-optimal", "a-optimal"; false for anything else.
bool ParseCriterion(const std::string& name, Criterion* criterion);

struct PlannerOptions {
  Criterion criterion = Criterion::kEq39;
  double lambda = 1e-7;            // eq. (39)'s weight of Cond(J): the paper's value (section 4.2)
  // Barrier continuation for eq. (39): the weight starts at barrier_start * E(start) / (number of
  // constraints) and is divided by barrier_decrease after each of barrier_rounds L-BFGS solves.
  // One round by default: further rounds moved no pose of the shipped problems (their first line search
  // step failed at once).
  int barrier_rounds = 1;
  double barrier_start = 1e-3;
  double barrier_decrease = 10.0;
  int max_iterations_per_round = 200;
  // The stated test of each L-BFGS round: an iteration that lowers eq. (39) plus the barrier by less than
  // this fraction of its value ends it. Deliberately loose: minimised to a tight tolerance, eq. (39) gave
  // plans the bundle calibrates much worse from (PUMA held-out 3-D RMS 1.09 mm against 0.06 mm, seeds 1-3;
  // docs/planning.md).
  double relative_decrease_tolerance = 1e-3;
  // Exchange designs (D, A): the pool and its seed.
  int pool_size = 200;
  uint64_t seed = 1;
  int max_exchange_sweeps = 6;
  FisherDesignOptions fisher;
  // Told the L-BFGS iterations (eq. (39)) or the exchange passes over the slots (D, A), for a person
  // watching; null: nothing reported.
  ProgressSink* progress = nullptr;
  std::string Validate() const;
};

struct PlanResult {
  bool ok = false;
  std::string message;
  Criterion criterion = Criterion::kEq39;
  std::vector<Eigen::VectorXd> poses;  // rad; the first num_identification_poses identify
  int num_identification_poses = 0;
  std::vector<int> free_columns;       // identifiable rho indices (J's columns)
  std::vector<std::string> free_names;
  // A start that breaks a constraint is repaired first: each offending pose, the reference (pose 0) included,
  // is replaced by the nearest (joint space) feasible candidate of the seeded pool. The "start" figures are of the repaired
  // start; check_start is of the start as given.
  int repaired_poses = 0;
  int pool_size = 0;                   // candidates generated for the exchange designs
  // Every criterion at the start and at the result, whichever was optimised.
  Eq39Value eq39_start, eq39_final;
  FisherValue fisher_start, fisher_final;
  PlanCheck check_start, check_final;
  int iterations = 0;    // L-BFGS iterations, or exchange sweeps
  std::string solver_message;  // the last L-BFGS round's termination message
  // Whether the stated test stopped the planner (eq. (39): the relative decrease, in the last round; D, A: a
  // pass that changed nothing), and that test in words, for the person reading the output.
  bool converged = false;
  std::string stop_rule;
  int evaluations = 0;   // cost evaluations
  double seconds = 0;
};

// Plans from `start` (its size is m). Every pose must have the robot's joint count and finite values; other
// violations, the reference pose's (pose 0) included, are repaired (above) or the result says why not.
PlanResult PlanMeasurements(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& start,
                            const PlannerOptions& options);

}  // namespace selfcal::planning
