#include "planning/planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>
#include <ceres/iteration_callback.h>
#include <ceres/jet.h>

#include "base/status.h"
#include "identification/identifiability.h"
#include "planning/candidate_pool.h"
#include "planning/view_geometry.h"
#include "planning/visit_order.h"

namespace selfcal::planning {

namespace {

// Robots up to 7 joints (the Panda); unused derivative slots stay zero.
constexpr int kMaxJoints = 7;
using JointJet = ceres::Jet<double, kMaxJoints>;
using PairJet = ceres::Jet<double, 2 * kMaxJoints>;

// A pose's camera centre and optical axis with their derivatives with respect to its own joints.
struct ViewJets {
  Vec3T<JointJet> centre, axis;
};

PairJet Promote(const JointJet& x, int offset) {
  PairJet y(x.a);
  for (int k = 0; k < kMaxJoints; ++k) y.v[offset + k] = x.v[k];
  return y;
}

Vec3T<PairJet> Promote(const Vec3T<JointJet>& x, int offset) {
  return Vec3T<PairJet>(Promote(x[0], offset), Promote(x[1], offset), Promote(x[2], offset));
}

// Eq. (39) plus the log barrier of every constraint that involves an optimised (identification) pose.
class BarrierObjective final : public ceres::FirstOrderFunction {
 public:
  BarrierObjective(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses,
                   const std::vector<int>& free_columns, double lambda)
      : problem_(problem), poses_(poses), free_columns_(free_columns), lambda_(lambda) {
    const Eigen::VectorXd rho = KinematicParameters::Nominal(problem.robot);
    rho_.resize(rho.size());
    for (int k = 0; k < rho.size(); ++k) rho_[k] = JointJet(rho[k]);
  }

  void set_mu(double mu) { mu_ = mu; }
  int evaluations() const { return evaluations_; }
  int NumParameters() const override { return problem_.num_identification_poses * problem_.robot.num_joints(); }

  // Sum of -log(slack) over the constraints (and its gradient when asked); false when one is violated.
  bool Barrier(const std::vector<Eigen::VectorXd>& poses, double* value, Eigen::VectorXd* gradient,
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
    // Every scene point in every identification image, in the depth range.
    std::vector<ViewJets> views(m);
    double d[kMaxJoints];
    for (int i = 0; i < m; ++i) {
      std::vector<JointJet> q(n);
      for (int j = 0; j < n; ++j) {
        q[j] = JointJet(poses[i][j]);
        if (i < m_id) q[j].v[j] = 1.0;
      }
      const Rigid3T<JointJet> base_from_cam = BaseFromCam<JointJet>(robot, rho_.data(), q.data());
      views[i].centre = base_from_cam.translation;
      views[i].axis = base_from_cam.rotation.col(2);
      if (i >= m_id) continue;
      const Rigid3T<JointJet> cam_from_base = base_from_cam.Inverse();
      for (const Eigen::Vector3d& x : problem_.scene.extent_in_base) {
        const Vec3T<JointJet> p = cam_from_base * x.cast<JointJet>();
        const JointJet slacks[2] = {p.z() - JointJet(c.min_depth_m), JointJet(c.max_depth_m) - p.z()};
        for (const JointJet& s : slacks) {
          if (!term(s.a)) return false;
          for (int j = 0; j < n; ++j) d[j] = s.v[j];
          push(i, s.a, d);
        }
        JointJet u, v;
        if (!ProjectPoint<JointJet>(problem_.camera, JointJet(problem_.camera.fx_px), JointJet(problem_.camera.k1), p, &u, &v)) {
          return false;
        }
        const JointJet margin(c.image_margin_px);
        const JointJet image[4] = {u - margin, JointJet(problem_.camera.width_px - 1) - margin - u, v - margin,
                               JointJet(problem_.camera.height_px - 1) - margin - v};
        for (const JointJet& s : image) {
          if (!term(s.a)) return false;
          for (int j = 0; j < n; ++j) d[j] = s.v[j];
          push(i, s.a, d);
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

  bool Evaluate(const double* x, double* cost, double* gradient) const override {
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

 private:
  const PlanningProblem& problem_;
  std::vector<Eigen::VectorXd> poses_;
  std::vector<int> free_columns_;
  double lambda_;
  std::vector<JointJet> rho_;
  double mu_ = 0;
  mutable int evaluations_ = 0;
};

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

// Makes a start feasible for the barrier: every pose after the reference that breaks a constraint is replaced
// by the candidate of `pool` nearest to it in joint space (max norm) that satisfies them all. Returns the
// number of poses replaced.
int RepairStart(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& pool,
                std::vector<Eigen::VectorXd>* poses) {
  const Eigen::VectorXd rho = KinematicParameters::Nominal(problem.robot);
  std::vector<Rigid3> views;
  for (const Eigen::VectorXd& q : *poses) views.push_back(BaseFromCam(problem.robot, rho, q));
  std::vector<Rigid3> pool_views;
  for (const Eigen::VectorXd& q : pool) pool_views.push_back(BaseFromCam(problem.robot, rho, q));
  std::vector<bool> used(pool.size(), false);
  int replaced = 0;
  for (int i = 1; i < static_cast<int>(poses->size()); ++i) {
    if (PoseFits(problem, *poses, views, i, (*poses)[i], views[i])) continue;
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
  BarrierObjective* objective = new BarrierObjective(problem, result->poses, result->free_columns, options.lambda);
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
  // No relative-cost test: near an active constraint the barrier makes the first steps tiny, which a cost
  // tolerance would take for convergence.
  solver_options.function_tolerance = 0;
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
    mu /= options.barrier_decrease;
  }
  result->evaluations = objective->evaluations();
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
    views.push_back(BaseFromCam(problem.robot, rho, q));
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
  for (int i = m_id; i < m; ++i) verification.push_back(BaseFromCam(problem.robot, rho, result->poses[i]));
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
  for (int sweep = 0; sweep < options.max_exchange_sweeps; ++sweep) {
    ++result->iterations;
    bool changed = false;
    for (int slot = 1; slot < m_id; ++slot) {  // pose 0 stays: it is the reference of every pair
      const int current = chosen[slot];
      int best_candidate = current;
      // Every pose but the slot's summed once; each candidate then costs one EvaluateSums.
      const FisherDesign::Sums rest = design.Sum(fisher_design(chosen), slot);
      for (int cand = 0; cand < num_candidates; ++cand) {
        if (cand == current || !compatible(cand, slot)) continue;
        chosen[slot] = cand;
        const double score = DesignScore(
            options.criterion, design.EvaluateSums(rest, fisher(cand), options.criterion == Criterion::kAOptimal));
        ++result->evaluations;
        if (score < best - 1e-9 * std::abs(best)) {
          best = score;
          best_candidate = cand;
        }
      }
      chosen[slot] = best_candidate;
      changed = changed || best_candidate != current;
      progress.Advance();
    }
    if (!changed) break;
  }
  for (int i = 0; i < m_id; ++i) result->poses[i] = candidates[chosen[i]];
}

// The visit order that lets the session track the dots through every move (visit_order.h): kept when
// the check accepts it or the given order fails too. Returns the check of the order kept.
PlanCheck OrderAsTour(const PlanningProblem& problem, std::vector<Eigen::VectorXd>* poses) {
  const VisitOrder visit = OrderForTracking(problem, *poses);
  std::vector<Eigen::VectorXd> reordered;
  reordered.reserve(poses->size());
  for (int i : visit.order) reordered.push_back((*poses)[i]);
  PlanCheck check = CheckPlan(problem, reordered);
  if (!check.ok) {
    PlanCheck as_given = CheckPlan(problem, *poses);
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
  result.check_start = CheckPlan(problem, start);
  const int m_id = problem.num_identification_poses;
  const bool usable = std::none_of(result.check_start.problems.begin(), result.check_start.problems.end(),
                                   [](const PlanProblemItem& p) {
                                     return p.issue == PlanIssue::kJointCount || p.issue == PlanIssue::kNonFinite ||
                                            p.issue == PlanIssue::kTooFewPoses;
                                   });
  if (!usable || !PoseFeasible(problem, start[0])) {
    result.message = "the start plan cannot be used (its reference pose 0 must be feasible):\n" +
                     result.check_start.Summary();
    result.seconds = Seconds(t0);
    return result;
  }
  if (!result.check_start.ok) {
    // Repair: poses that break a constraint are replaced by the nearest feasible candidate of a seeded pool.
    PoolOptions pool_options;
    pool_options.count = options.pool_size;
    pool_options.seed = options.seed;
    const std::vector<Eigen::VectorXd> pool = MakeCandidatePool(problem, start, pool_options);
    result.repaired_poses = RepairStart(problem, pool, &result.poses);
    const PlanCheck repaired = CheckPlan(problem, result.poses);
    if (!repaired.ok) {
      result.message = "the start plan is not feasible and could not be repaired from " + std::to_string(pool.size()) +
                       " candidates:\n" + repaired.Summary();
      result.seconds = Seconds(t0);
      return result;
    }
  }
  const Eigen::VectorXd rho = KinematicParameters::Nominal(problem.robot);
  const std::vector<Eigen::VectorXd> id_start(result.poses.begin(), result.poses.begin() + m_id);
  const identification::IdentifiabilityReport id =
      identification::AnalyzeIdentifiability(problem.robot, rho, id_start, 0, identification::IdentifiabilityOptions());
  result.free_columns = id.free_indices;
  result.free_names = id.free_names;
  result.eq39_start = EvaluateEq39(problem.robot, id_start, result.free_columns, options.lambda, false);
  result.fisher_start = FisherOf(problem, result.free_columns, options.fisher, result.poses);

  if (options.criterion == Criterion::kEq39) {
    PlanEq39(problem, options, &result);
  } else {
    PlanExchange(problem, options, &result);
  }
  result.check_final = OrderAsTour(problem, &result.poses);

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
