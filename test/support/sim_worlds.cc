#include "support/sim_worlds.h"

#include <gtest/gtest.h>

#include "kinematics/robot_model.h"
#include "observations/observation_set.h"
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

EyeToHandCell PumaEyeToHandCell() {
  EyeToHandCell cell;
  cell.robot = Puma560();
  const std::vector<double> home_deg = {0, 20, -200, 0, 45, 0};
  Eigen::VectorXd home(6);
  for (int j = 0; j < 6; ++j) home[j] = DegToRad(home_deg[j]);
  cell.robot.mount = CameraMount::kEyeToHand;
  cell.robot.base_from_cam = sim::DefaultFixedCamera(cell.robot, home);
  sim::EyeToHandTrajectoryOptions options;
  options.home_joints_deg = home_deg;
  const sim::GeneratedTrajectory t = sim::MakeEyeToHandTrajectory(cell.robot, options);
  EXPECT_TRUE(t.ok) << t.message;
  cell.start = t.joints;
  return cell;
}

ObservationSet AsFlangePoseSet(const sim::SimResult& world) {
  ObservationSet obs = world.observations;
  obs.robot = FlangePoseModel(Rigid3());
  obs.flange_from_cam_known = false;
  for (PoseObservation& pose : obs.poses) {
    pose.base_from_flange = BaseFromFlange(world.truth.nominal, world.truth.rho_true, pose.joints_rad);
    pose.joints_rad.resize(0);
  }
  return obs;
}

}  // namespace selfcal::testing
