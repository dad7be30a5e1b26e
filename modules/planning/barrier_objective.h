// Eq. (39) plus a logarithmic barrier of every constraint that involves an optimised (identification) pose:
// the objective the eq. (39) planner (planning/planner.h) minimises by L-BFGS. Parameters: the joint
// angles of the identification poses, pose-major. An infeasible point evaluates to false (Ceres' line
// search then shortens the step), so every accepted iterate stays strictly feasible.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <ceres/gradient_problem.h>

#include "planning/plan_problem.h"

namespace selfcal::planning::internal {

class BarrierObjective final : public ceres::FirstOrderFunction {
 public:
  BarrierObjective(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses,
                   const std::vector<int>& free_columns, double lambda);

  void set_mu(double mu) { mu_ = mu; }
  double mu() const { return mu_; }
  int evaluations() const { return evaluations_; }
  int NumParameters() const override;

  // Sum of -log(slack) over the constraints (and its gradient, size m_id * n, when asked); false when one
  // is violated. *num_constraints (if given): how many slacks were summed.
  bool Barrier(const std::vector<Eigen::VectorXd>& poses, double* value, Eigen::VectorXd* gradient,
               int* num_constraints) const;

  bool Evaluate(const double* x, double* cost, double* gradient) const override;

 private:
  const PlanningProblem& problem_;
  std::vector<Eigen::VectorXd> poses_;
  std::vector<int> free_columns_;
  double lambda_;
  double mu_ = 0;
  mutable int evaluations_ = 0;
};

}  // namespace selfcal::planning::internal
