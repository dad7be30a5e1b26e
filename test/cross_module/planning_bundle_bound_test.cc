// Planning's Fisher design against the bundle adjustment's Cramer-Rao bound (two modules of one layer).
#include <vector>

#include <gtest/gtest.h>

#include "bundle/bundle_adjustment.h"
#include "planning/fisher_design.h"
#include "planning/planning_test_util.h"

namespace selfcal::planning {
namespace {

using testing::FreeColumns;
using testing::MakeWorld;
using testing::World;

TEST(Planning, FisherDesignMatchesTheBundleCramerRaoBound) {
  const World w = MakeWorld();
  const std::vector<int> free = FreeColumns(w);
  FisherDesignOptions options;
  options.pixel_noise_px = 0.2;
  options.yardstick_sigma_m = 1e-6;
  // The bound at the nominal model (the planner's view): the truth of the bound is the nominal robot.
  sim::SimResult nominal_world = w.sim;
  bundle::BundleTruth truth;
  truth.rho = KinematicParameters::Nominal(w.problem.robot);
  for (size_t j = 0; j < w.sim.truth.dots_in_base.size(); ++j) truth.dots_in_base[j] = w.sim.truth.dots_in_base[j];
  ObservationSet geometry = w.sim.observations;
  geometry.camera.fx_px = w.problem.camera.fx_px;
  truth.camera = geometry.camera;
  // Every dot seen in every identification pose, as the design assumes (the simulator keeps them in view).
  bundle::BundleOptions bundle_options;
  bundle_options.yardstick_sigma_m = 1e-6;
  const bundle::CramerRaoReport bound = bundle::BundleCramerRao(geometry, truth, 0.2, bundle_options);
  ASSERT_TRUE(bound.ok) << bound.message;
  ASSERT_EQ(bound.free_indices, free);
  // The simulated yardstick is dots 0 and 1, as the design's.
  FisherDesign design(w.problem, free, options);
  std::vector<int> all;
  for (int i = 0; i < 15; ++i) all.push_back(design.AddCandidate(w.start[i]));
  const FisherValue v = design.Evaluate(all);
  ASSERT_TRUE(v.ok);
  for (size_t c = 0; c < free.size(); ++c) {
    EXPECT_NEAR(v.stddev[c], bound.stddev[free[c]], 0.02 * bound.stddev[free[c]]) << free[c];
  }
  EXPECT_NEAR(v.stddev[free.size()], bound.fx_stddev, 0.02 * bound.fx_stddev);
}

}  // namespace
}  // namespace selfcal::planning
