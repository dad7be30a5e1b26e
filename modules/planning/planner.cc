#include "planning/planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>
#include <ceres/iteration_callback.h>

#include "base/status.h"
#include "planning/barrier_objective.h"
#include "planning/candidate_pool.h"
#include "planning/view_geometry.h"
#include "planning/visit_order.h"

namespace selfcal::planning {

namespace {

// Robots up to 7 joints (the Panda): eq. (39) and its barrier carry the joints in fixed-size Jets.

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

FisherValue FisherOf(const PlanningProblem& problem, const std::vector<int>& free_columns,
                     const FisherDesignOptions& options, const std::vector<Eigen::VectorXd>& poses) {
  FisherDesign design(problem, free_columns, options);
  std::vector<int> all;
  for (int i = 0; i < problem.num_identification_poses; ++i) all.push_back(design.AddCandidate(poses[i]));
  return design.Evaluate(all);
}

// Lower is better for both exchange criteria.
double DesignScore(Criterion criterion, const FisherValue& v) {
  if (!v.ok) return std::numeric_limits<double>::infinity();
  return criterion == Criterion::kDOptimal ? -v.log_det : v.a_value;
}

// Pairwise and single-pose constraints of pose i within `poses` (the plan check's rules, in double).
bool PoseFits(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses, const std::vector<Rigid3>& views,
              int i, const Eigen::VectorXd& q, const Rigid3& view) {
  const PlanConstraints& c = problem.constraints;
  const int m = static_cast<int>(poses.size());
  if (!PoseFeasible(problem, q)) return false;
  for (int k = 0; k < m; ++k) {
    if (k != i && (views[k].translation - view.translation).norm() < c.min_spread_m) return false;
  }
  if (i > 0 && i < problem.num_identification_poses && AxisSine<double>(views[0], view) < c.min_axis_sine) return false;
  if (i > 0 && (q - poses[i - 1]).lpNorm<Eigen::Infinity>() > c.max_joint_travel_rad) return false;
  if (i + 1 < m && (q - poses[i + 1]).lpNorm<Eigen::Infinity>() > c.max_joint_travel_rad) return false;
  // The moves into and out of pose i within the image-motion bound.
  const std::vector<Eigen::Vector2d> here = DotImages(problem, q);
  for (int k : {i - 1, i + 1}) {
    if (k >= 0 && k < m &&
        !(ImageMotionBetween(DotImages(problem, poses[k]), here).median_px <= c.max_image_motion_px)) {
      return false;
    }
  }
  return true;
}

// Makes a start feasible for the barrier: every pose that breaks a constraint, the reference (pose 0) first, is
// replaced by the candidate of `pool` nearest to it in joint space (max norm) that satisfies them all. The
// reference too: the scene the planner is given sits a margin inside the true views, and the nominal model can
// put a dot of any pose a few px outside the image (a hand-eye rotation error of 0.5 deg alone shifts the image
// by about 9 px at f = 1000 px).
// Returns the number of poses replaced.
int RepairStart(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& pool,
                std::vector<Eigen::VectorXd>* poses) {
  const Eigen::VectorXd rho = KinematicParameters::Nominal(problem.robot);
  std::vector<Rigid3> views;
  for (const Eigen::VectorXd& q : *poses) views.push_back(PointsFromCam(problem.robot, rho, q));
  std::vector<Rigid3> pool_views;
  for (const Eigen::VectorXd& q : pool) pool_views.push_back(PointsFromCam(problem.robot, rho, q));
  std::vector<bool> used(pool.size(), false);
  int replaced = 0;
  for (int i = 0; i < static_cast<int>(poses->size()); ++i) {
    // The reference is replaced only when it breaks a single-pose constraint: a conflict with another pose
    // (spread, motion into pose 1) is that pose's to repair, as before the reference was repaired at all.
    const bool fits = i == 0 ? PoseFeasible(problem, (*poses)[0]) : PoseFits(problem, *poses, views, i, (*poses)[i], views[i]);
    if (fits) continue;
    int best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < pool.size(); ++k) {
      if (used[k]) continue;
      const double distance = (pool[k] - (*poses)[i]).lpNorm<Eigen::Infinity>();
      if (distance < best_distance && PoseFits(problem, *poses, views, i, pool[k], pool_views[k])) {
        best = static_cast<int>(k);
        best_distance = distance;
      }
    }
    if (best < 0) continue;  // left as is: the check after the repair says what is wrong
    used[best] = true;
    (*poses)[i] = pool[best];
    views[i] = pool_views[best];
    ++replaced;
  }
  return replaced;
}

// One progress unit per L-BFGS iteration, at most `share` (Ceres also reports the start as iteration 0).
class IterationProgress : public ceres::IterationCallback {
 public:
  IterationProgress(ProgressScope* progress, int share) : progress_(progress), share_(share) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& /*summary*/) override {
    if (iterations_ < share_) {
      progress_->Advance();
      ++iterations_;
    }
    return ceres::SOLVER_CONTINUE;
  }
  // The rest of the share, when the solve stopped early.
  void Complete() { progress_->Advance(share_ - iterations_); }

 private:
  ProgressScope* progress_;
  int share_;
  int iterations_ = 0;
};

void PlanEq39(const PlanningProblem& problem, const PlannerOptions& options, PlanResult* result) {
  const int n = problem.robot.num_joints(), m_id = problem.num_identification_poses;
  internal::BarrierObjective* objective = new internal::BarrierObjective(problem, result->poses, result->free_columns, options.lambda);
  double barrier = 0;
  int num_constraints = 0;
  objective->Barrier(result->poses, &barrier, nullptr, &num_constraints);
  double mu = options.barrier_start * std::max(result->eq39_start.total, 1e-12) / std::max(num_constraints, 1);
  ceres::GradientProblem gradient_problem(objective);
  Eigen::VectorXd x(m_id * n);
  for (int i = 0; i < m_id; ++i) x.segment(i * n, n) = result->poses[i];
  ceres::GradientProblemSolver::Options solver_options;
  solver_options.line_search_direction_type = ceres::LBFGS;
  solver_options.max_num_iterations = options.max_iterations_per_round;
  // The stated test (planner.h): an iteration that lowers eq. (39) plus the barrier by less than
  // relative_decrease_tolerance of its value ends the round (Ceres' function tolerance).
  solver_options.function_tolerance = options.relative_decrease_tolerance;
  solver_options.gradient_tolerance = 1e-10;
  solver_options.parameter_tolerance = 0;
  solver_options.logging_type = ceres::SILENT;
  // The most iterations the rounds can take; a round that converges early skips the rest of its share.
  ProgressScope progress(options.progress, static_cast<int64_t>(options.barrier_rounds) * options.max_iterations_per_round,
                         "planner iterations");
  for (int round = 0; round < options.barrier_rounds; ++round) {
    objective->set_mu(mu);
    ceres::GradientProblemSolver::Summary summary;
    IterationProgress counter(&progress, options.max_iterations_per_round);
    solver_options.callbacks = {&counter};
    ceres::Solve(solver_options, gradient_problem, x.data(), &summary);
    solver_options.callbacks.clear();
    counter.Complete();
    result->iterations += static_cast<int>(summary.iterations.size());
    result->solver_message = summary.message;
    result->converged = summary.termination_type == ceres::CONVERGENCE &&
                        summary.message.find("Function tolerance") != std::string::npos;
    mu /= options.barrier_decrease;
  }
  result->evaluations = objective->evaluations();
  std::ostringstream stop;
  stop << (result->converged ? "converged: " : "not converged: ") << "the stated test is a relative decrease of eq. (39) "
       << "plus the barrier below " << options.relative_decrease_tolerance << " over an iteration";
  result->stop_rule = stop.str();
  for (int i = 0; i < m_id; ++i) result->poses[i] = x.segment(i * n, n);
}

void PlanExchange(const PlanningProblem& problem, const PlannerOptions& options, PlanResult* result) {
  const int m_id = problem.num_identification_poses;
  const int m = static_cast<int>(result->poses.size());
  PoolOptions pool_options;
  pool_options.count = options.pool_size;
  pool_options.seed = options.seed;
  const std::vector<Eigen::VectorXd> pool = MakeCandidatePool(problem, result->poses, pool_options);
  result->pool_size = static_cast<int>(pool.size());
  FisherDesign design(problem, result->free_columns, options.fisher);
  std::vector<Eigen::VectorXd> candidates;
  for (int i = 0; i < m_id; ++i) candidates.push_back(result->poses[i]);
  candidates.insert(candidates.end(), pool.begin(), pool.end());
  const int num_candidates = static_cast<int>(candidates.size());
  const Eigen::VectorXd rho = KinematicParameters::Nominal(problem.robot);
  std::vector<Rigid3> views;
  std::vector<std::vector<Eigen::Vector2d>> images;  // the dots' pixels: image motion between candidates
  for (const Eigen::VectorXd& q : candidates) {
    views.push_back(PointsFromCam(problem.robot, rho, q));
    images.push_back(DotImages(problem, q));
  }
  // A candidate's Fisher contribution is computed when it is first evaluated (many never pass the
  // pairwise constraints); the designs below index candidates, the FisherDesign its own order.
  std::vector<int> fisher_index(num_candidates, -1);
  auto fisher = [&](int cand) {
    if (fisher_index[cand] < 0) fisher_index[cand] = design.AddCandidate(candidates[cand]);
    return fisher_index[cand];
  };
  auto fisher_design = [&](const std::vector<int>& cands) {
    std::vector<int> out;
    for (int cand : cands) out.push_back(fisher(cand));
    return out;
  };
  const std::vector<Eigen::Vector2d> first_verification =
      m > m_id ? DotImages(problem, result->poses[m_id]) : std::vector<Eigen::Vector2d>();
  // Median image motion between candidates (index num_candidates: the first verification pose), each pair
  // computed once.
  std::vector<double> motion_cache(static_cast<size_t>(num_candidates) * (num_candidates + 1),
                                   std::numeric_limits<double>::quiet_NaN());
  auto motion = [&](int a, int b) {
    const int lo = std::min(a, b), hi = std::max(a, b);
    double& cached = motion_cache[static_cast<size_t>(lo) * (num_candidates + 1) + hi];
    if (std::isnan(cached)) {
      cached = ImageMotionBetween(images[lo], hi < num_candidates ? images[hi] : first_verification).median_px;
    }
    return cached;
  };
  std::vector<Rigid3> verification;
  for (int i = m_id; i < m; ++i) verification.push_back(PointsFromCam(problem.robot, rho, result->poses[i]));
  const PlanConstraints& c = problem.constraints;
  std::vector<int> chosen(m_id);
  for (int i = 0; i < m_id; ++i) chosen[i] = i;
  // Pairwise constraints of candidate `cand` at position `slot` against the rest of the design.
  auto compatible = [&](int cand, int slot) {
    for (int s = 0; s < m_id; ++s) {
      if (s == slot) continue;
      if (chosen[s] == cand) return false;
      if ((views[cand].translation - views[chosen[s]].translation).norm() < c.min_spread_m) return false;
      // Pairwise joint travel within the bound: any visit order then respects it.
      if ((candidates[cand] - candidates[chosen[s]]).lpNorm<Eigen::Infinity>() > c.max_joint_travel_rad) return false;
    }
    if (m > m_id && (candidates[cand] - result->poses[m_id]).lpNorm<Eigen::Infinity>() > c.max_joint_travel_rad) {
      return false;
    }
    // Image motion of the moves into and out of the slot (the visit order is the slots'): every exchange
    // keeps each move within the bound.
    if (!(motion(chosen[slot - 1], cand) <= c.max_image_motion_px)) return false;
    const int next = slot + 1 < m_id ? chosen[slot + 1] : m > m_id ? num_candidates : -1;
    if (next >= 0 && !(motion(cand, next) <= c.max_image_motion_px)) return false;
    for (const Rigid3& v : verification) {
      if ((views[cand].translation - v.translation).norm() < c.min_spread_m) return false;
    }
    if (slot > 0 && AxisSine<double>(views[chosen[0]], views[cand]) < c.min_axis_sine) return false;
    return true;
  };
  double best = DesignScore(options.criterion, design.Evaluate(fisher_design(chosen)));
  ++result->evaluations;
  // One unit per slot of a pass; a design that stops changing ends the step early.
  ProgressScope progress(options.progress, static_cast<int64_t>(options.max_exchange_sweeps) * std::max(m_id - 1, 0),
                         "exchange passes");
  // A slot exchanged with the design as it is now would keep its pose (same rest, candidates, best): skipped.
  int changes = 0;  // exchanges made so far; each slot records the count after its own exchange
  std::vector<int> changes_when_exchanged(m_id, -1);
  for (int sweep = 0; sweep < options.max_exchange_sweeps; ++sweep) {
    ++result->iterations;
    bool changed = false;
    for (int slot = 1; slot < m_id; ++slot) {  // pose 0 stays: it is the reference of every pair
      if (changes_when_exchanged[slot] == changes && (progress.Advance(), true)) continue;
      const int current = chosen[slot];
      int best_candidate = current;
      // Every pose but the slot's summed and its dots eliminated once; each candidate then costs one
      // EvaluateWithRest.
      const FisherDesign::Rest rest = design.PrepareRest(design.Sum(fisher_design(chosen), slot));
      for (int cand = 0; cand < num_candidates; ++cand) {
        if (cand == current || !compatible(cand, slot)) continue;
        chosen[slot] = cand;
        const double score = DesignScore(
            options.criterion, design.EvaluateWithRest(rest, fisher(cand), options.criterion == Criterion::kAOptimal));
        ++result->evaluations;
        if (score < best - 1e-9 * std::abs(best)) {
          best = score;
          best_candidate = cand;
        }
      }
      chosen[slot] = best_candidate;
      if (best_candidate != current) {
        changed = true;
        ++changes;
      }
      changes_when_exchanged[slot] = changes;
      progress.Advance();
    }
    if (!changed) {
      result->converged = true;
      break;
    }
  }
  result->stop_rule = std::string(result->converged ? "converged: " : "not converged (the pass limit): ") +
                      "the stated test is a full pass over the slots that changes no pose";
  for (int i = 0; i < m_id; ++i) result->poses[i] = candidates[chosen[i]];
}

// The visit order that lets the session track the dots through every move (visit_order.h): kept when
// the check accepts it or the given order fails too. Returns the check of the order kept.
PlanCheck OrderAsTour(const PlanningProblem& problem, int generic_identifiable, std::vector<Eigen::VectorXd>* poses) {
  const VisitOrder visit = OrderForTracking(problem, *poses);
  std::vector<Eigen::VectorXd> reordered;
  reordered.reserve(poses->size());
  for (int i : visit.order) reordered.push_back((*poses)[i]);
  PlanCheck check = CheckPlan(problem, reordered, generic_identifiable);
  if (!check.ok) {
    PlanCheck as_given = CheckPlan(problem, *poses, generic_identifiable);
    if (as_given.ok) return as_given;
  }
  *poses = std::move(reordered);
  return check;
}

}  // namespace

const char* CriterionName(Criterion criterion) {
  switch (criterion) {
    case Criterion::kEq39: return "eq39";
    case Criterion::kDOptimal: return "d-optimal";
    case Criterion::kAOptimal: return "a-optimal";
  }
  return "unknown";
}

bool ParseCriterion(const std::string& name, Criterion* criterion) {
  for (Criterion c : {Criterion::kEq39, Criterion::kDOptimal, Criterion::kAOptimal}) {
    if (name == CriterionName(c)) {
      *criterion = c;
      return true;
    }
  }
  return false;
}

std::string PlannerOptions::Validate() const {
  std::ostringstream out;
  if (!(std::isfinite(lambda) && lambda >= 0)) out << "lambda = " << lambda << " must be >= 0\n";
  if (barrier_rounds < 1) out << "barrier_rounds = " << barrier_rounds << " must be >= 1\n";
  if (!(relative_decrease_tolerance >= 0 && relative_decrease_tolerance < 1)) {
    out << "relative_decrease_tolerance = " << relative_decrease_tolerance << " must lie in [0, 1)\n";
  }
  if (!(barrier_start > 0)) out << "barrier_start = " << barrier_start << " must be > 0\n";
  if (!(barrier_decrease > 1)) out << "barrier_decrease = " << barrier_decrease << " must exceed 1\n";
  if (max_iterations_per_round < 1) out << "max_iterations_per_round must be >= 1\n";
  if (pool_size < 1) out << "pool_size = " << pool_size << " must be >= 1\n";
  if (max_exchange_sweeps < 1) out << "max_exchange_sweeps must be >= 1\n";
  std::string s = out.str();
  if (!s.empty()) s.pop_back();
  return s;
}

PlanResult PlanMeasurements(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& start,
                            const PlannerOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string invalid = problem.Validate();
  SELFCAL_CHECK(invalid.empty(), "planning problem: " << invalid);
  const std::string bad_options = options.Validate();
  SELFCAL_CHECK(bad_options.empty(), "planner options: " << bad_options);
  SELFCAL_CHECK(problem.robot.num_joints() <= kMaxJoints, "the planner supports up to " << kMaxJoints << " joints");
  PlanResult result;
  result.criterion = options.criterion;
  result.num_identification_poses = problem.num_identification_poses;
  result.poses = start;
  const int generic_identifiable = GenericIdentifiable(problem.robot);  // the same for every check below
  result.check_start = CheckPlan(problem, start, generic_identifiable);
  const int m_id = problem.num_identification_poses;
  const bool usable = std::none_of(result.check_start.problems.begin(), result.check_start.problems.end(),
                                   [](const PlanProblemItem& p) {
                                     return p.issue == PlanIssue::kJointCount || p.issue == PlanIssue::kNonFinite ||
                                            p.issue == PlanIssue::kTooFewPoses;
                                   });
  if (!usable) {
    result.message = "the start plan cannot be used:\n" +
                     result.check_start.Summary();
    result.seconds = Seconds(t0);
    return result;
  }
  PlanCheck repaired;
  if (!result.check_start.ok) {
    // Repair: poses that break a constraint are replaced by the nearest feasible candidate of a seeded pool.
    PoolOptions pool_options;
    pool_options.count = options.pool_size;
    pool_options.seed = options.seed;
    const std::vector<Eigen::VectorXd> pool = MakeCandidatePool(problem, start, pool_options);
    result.repaired_poses = RepairStart(problem, pool, &result.poses);
    repaired = CheckPlan(problem, result.poses, generic_identifiable);
    if (!repaired.ok) {
      result.message = "the start plan is not feasible and could not be repaired from " + std::to_string(pool.size()) +
                       " candidates:\n" + repaired.Summary();
      result.seconds = Seconds(t0);
      return result;
    }
  }
  // The identifiable parameters of the (repaired) start: its check's identifiability analysis.
  const ObservabilityReport& start_observability =
      result.check_start.ok ? result.check_start.observability : repaired.observability;
  const std::vector<Eigen::VectorXd> id_start(result.poses.begin(), result.poses.begin() + m_id);
  result.free_columns = start_observability.free_indices;
  result.free_names = start_observability.free_names;
  result.eq39_start = EvaluateEq39(problem.robot, id_start, result.free_columns, options.lambda, false);
  result.fisher_start = FisherOf(problem, result.free_columns, options.fisher, result.poses);

  if (options.criterion == Criterion::kEq39) {
    PlanEq39(problem, options, &result);
  } else {
    PlanExchange(problem, options, &result);
  }
  result.check_final = OrderAsTour(problem, generic_identifiable, &result.poses);

  const std::vector<Eigen::VectorXd> id_final(result.poses.begin(), result.poses.begin() + m_id);
  result.eq39_final = EvaluateEq39(problem.robot, id_final, result.free_columns, options.lambda, false);
  result.fisher_final = FisherOf(problem, result.free_columns, options.fisher, result.poses);
  result.ok = result.check_final.ok;
  std::ostringstream message;
  if (result.ok) {
    message << CriterionName(options.criterion) << ": eq. (39) " << result.eq39_start.total << " -> "
            << result.eq39_final.total << ", D " << result.fisher_start.log_det << " -> " << result.fisher_final.log_det
            << ", A " << result.fisher_start.a_value << " -> " << result.fisher_final.a_value;
  } else {
    message << "the planned poses fail the check:\n" << result.check_final.Summary();
  }
  result.message = message.str();
  result.seconds = Seconds(t0);
  return result;
}

}  // namespace selfcal::planning
