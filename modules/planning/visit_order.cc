#include "planning/visit_order.h"

#include <algorithm>
#include <cmath>

#include "planning/plan_check.h"

namespace selfcal::planning {
namespace {

// A move over a bound costs more than any sum of in-bound moves can (at most 10^4 per move below).
constexpr double kOverBound = 1e6;
// A move's motion enters the smooth term clipped at this many bounds (an unseen scene is "very far").
constexpr double kMotionClip = 10.0;

struct Moves {
  Eigen::MatrixXd motion_px;  // median image motion of the move i -> j (symmetric; infinite: no common dot)
  Eigen::MatrixXd cost;       // the move's cost
  Eigen::MatrixXi over;       // 1 when the move breaks the image-motion or the joint-travel bound
};

Moves MovesOf(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses) {
  const int n = static_cast<int>(poses.size());
  const PlanConstraints& c = problem.constraints;
  std::vector<std::vector<Eigen::Vector2d>> images;
  images.reserve(poses.size());
  for (const Eigen::VectorXd& q : poses) images.push_back(DotImages(problem, q));
  Moves m{Eigen::MatrixXd::Zero(n, n), Eigen::MatrixXd::Zero(n, n), Eigen::MatrixXi::Zero(n, n)};
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const double motion = ImageMotionBetween(images[i], images[j]).median_px;
      const bool travel_ok = (poses[i] - poses[j]).lpNorm<Eigen::Infinity>() <= c.max_joint_travel_rad;
      const bool over = !(motion <= c.max_image_motion_px) || !travel_ok;
      const double ratio = std::min(motion / c.max_image_motion_px, kMotionClip);
      const double cost = (over ? kOverBound : 0.0) + std::pow(std::isfinite(ratio) ? ratio : kMotionClip, 4);
      m.motion_px(i, j) = m.motion_px(j, i) = motion;
      m.cost(i, j) = m.cost(j, i) = cost;
      m.over(i, j) = m.over(j, i) = over ? 1 : 0;
    }
  }
  return m;
}

double PathCost(const Moves& m, const std::vector<int>& order) {
  double total = 0;
  for (size_t k = 1; k < order.size(); ++k) total += m.cost(order[k - 1], order[k]);
  return total;
}

// Nearest neighbour from pose 0 through the identification poses, then through the verification ones.
std::vector<int> NearestNeighbourTour(const Moves& m, int m_id, int n) {
  std::vector<int> order = {0};
  auto visit = [&](int from, int to) {
    std::vector<int> rest;
    for (int i = from; i < to; ++i) rest.push_back(i);
    while (!rest.empty()) {
      const int last = order.back();
      const auto best = std::min_element(rest.begin(), rest.end(),
                                         [&](int a, int b) { return m.cost(last, a) < m.cost(last, b); });
      order.push_back(*best);
      rest.erase(best);
    }
  };
  visit(1, m_id);
  visit(m_id, n);
  return order;
}

// One improving segment reversal or single-pose move inside a group [first, last] of positions; false
// when none improves the path.
bool ImproveOnce(const Moves& m, int first, int last, std::vector<int>* order, double* cost) {
  for (int i = first; i < last; ++i) {
    for (int j = i + 1; j <= last; ++j) {
      std::vector<int> reversed = *order;
      std::reverse(reversed.begin() + i, reversed.begin() + j + 1);
      if (const double c = PathCost(m, reversed); c < *cost - 1e-12) {
        *order = std::move(reversed);
        *cost = c;
        return true;
      }
    }
  }
  for (int from = first; from <= last; ++from) {
    for (int to = first; to <= last; ++to) {
      if (to == from) continue;
      std::vector<int> moved = *order;
      const int pose = moved[from];
      moved.erase(moved.begin() + from);
      moved.insert(moved.begin() + to, pose);
      if (const double c = PathCost(m, moved); c < *cost - 1e-12) {
        *order = std::move(moved);
        *cost = c;
        return true;
      }
    }
  }
  return false;
}

}  // namespace

VisitOrder OrderForTracking(const PlanningProblem& problem, const std::vector<Eigen::VectorXd>& poses) {
  const int n = static_cast<int>(poses.size());
  const int m_id = std::clamp(problem.num_identification_poses, 1, std::max(n, 1));
  VisitOrder result;
  if (n == 0) return result;
  const Moves m = MovesOf(problem, poses);
  std::vector<int> order = NearestNeighbourTour(m, m_id, n);
  double cost = PathCost(m, order);
  // Each pass strictly lowers the cost of a finite set of orders: it ends.
  bool improved = true;
  while (improved) {
    improved = (m_id > 2 && ImproveOnce(m, 1, m_id - 1, &order, &cost)) ||
               (n - m_id > 1 && ImproveOnce(m, m_id, n - 1, &order, &cost));
  }
  for (int k = 1; k < n; ++k) {
    result.moves_over_bounds += m.over(order[k - 1], order[k]);
    result.max_image_motion_px = std::max(result.max_image_motion_px, m.motion_px(order[k - 1], order[k]));
  }
  result.order = std::move(order);
  return result;
}

}  // namespace selfcal::planning
