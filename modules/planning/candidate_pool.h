// Seeded candidate configurations for exchange designs (planning/planner.h, D- and A-optimal criteria):
// camera poses around the scene, each reached by inverse kinematics of the nominal model from a template
// pose and kept only when it satisfies every single-pose constraint (joint limits less the margin, every
// scene point in the image with the margin and in the depth range).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "planning/plan_problem.h"

namespace selfcal::planning {

struct PoolOptions {
  int count = 200;
  uint64_t seed = 1;
  // Viewpoints: a template pose's viewing direction (scene centre -> camera) turned about the base z axis by
  // up to +-azimuth and about the horizontal by up to +-elevation, its distance scaled within
  // [distance_min, distance_max]; the camera aims at a point within aim_fraction of the scene's half
  // extent around its centre, rolled about its axis by up to +-roll from the template's.
  double azimuth_rad = DegToRad(45.0);
  double elevation_rad = DegToRad(20.0);
  double distance_min = 0.85, distance_max = 1.2;
  double aim_fraction = 0.5;
  double roll_rad = DegToRad(40.0);
  int max_attempts_per_candidate = 30;
};

// Single-pose constraints; *reason (if given) names the first violation.
bool PoseFeasible(const PlanningProblem& problem, const Eigen::VectorXd& q, std::string* reason = nullptr);

// Up to options.count feasible candidates, each within max_joint_travel_rad of templates[0] (the same arm and
// wrist configuration) (fewer when attempts run out), deterministic for the seed.
std::vector<Eigen::VectorXd> MakeCandidatePool(const PlanningProblem& problem,
                                               const std::vector<Eigen::VectorXd>& templates,
                                               const PoolOptions& options);

}  // namespace selfcal::planning
