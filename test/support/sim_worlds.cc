#include "support/sim_worlds.h"

#include <gtest/gtest.h>

#include "sim/trajectory_generator.h"
#include "support/test_robots.h"

namespace selfcal::testing {

sim::SimResult PumaArcWorld(double noise_px, uint64_t world_seed, uint64_t noise_seed, bool flat_sheet) {
  sim::SimOptions options;
  options.pixel_noise_px = noise_px;
  options.world_seed = world_seed;
  options.noise_seed = noise_seed;
  options.flat_sheet = flat_sheet;
  return PumaArcWorld(options);
}

sim::SimResult PumaArcWorld(const sim::SimOptions& options) {
  const RobotModel puma = Puma560();
  const sim::GeneratedTrajectory trajectory = sim::MakeArcTrajectory(puma, sim::ArcTrajectoryOptions());
  EXPECT_TRUE(trajectory.ok) << trajectory.message;
  sim::SimResult world = sim::Simulate(puma, trajectory.joints, options);
  EXPECT_TRUE(world.ok) << world.message;
  return world;
}

}  // namespace selfcal::testing
