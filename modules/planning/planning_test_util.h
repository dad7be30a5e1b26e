// Test-only helpers shared by the planning tests (also test/cross_module): the PUMA 560 on the shipped
// initial arc as a planning problem.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "identification/identifiability.h"
#include "planning/plan_check.h"
#include "planning/plan_problem.h"
#include "sim/sim_world.h"
#include "support/sim_worlds.h"

namespace selfcal::planning::testing {

struct World {
  sim::SimResult sim;
  PlanningProblem problem;
  std::vector<Eigen::VectorXd> start;
};

// The PUMA 560 on the shipped initial arc, the simulated scene's dots as the rough dot positions.
inline World MakeWorld() {
  World w;
  w.sim = selfcal::testing::PumaArcWorld(0.0);
  w.problem.robot = w.sim.truth.nominal;
  w.problem.camera = w.sim.observations.camera;
  w.problem.scene = Scene::FromDots(w.sim.truth.dots_in_base);
  w.problem.constraints.image_margin_px = 2.0;  // the simulator keeps the true projections 10 px inside
  for (const PoseObservation& p : w.sim.observations.poses) w.start.push_back(p.joints_rad);
  return w;
}

inline std::vector<Eigen::VectorXd> Head(const std::vector<Eigen::VectorXd>& poses, int count) {
  return std::vector<Eigen::VectorXd>(poses.begin(), poses.begin() + count);
}

inline bool HasIssue(const PlanCheck& check, PlanIssue issue) {
  for (const PlanProblemItem& p : check.problems) {
    if (p.issue == issue) return true;
  }
  return false;
}

inline std::vector<int> FreeColumns(const World& w) {
  const identification::IdentifiabilityReport id = identification::AnalyzeIdentifiability(
      w.problem.robot, KinematicParameters::Nominal(w.problem.robot), Head(w.start, 15), 0,
      identification::IdentifiabilityOptions());
  return id.free_indices;
}

}  // namespace selfcal::planning::testing
