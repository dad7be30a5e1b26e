// The simulated eye-to-hand cell: a camera fixed in the base frame, dots on a plate the flange carries.
#include <gtest/gtest.h>

#include "sim/image_renderer.h"
#include "sim/sim_world.h"
#include "sim/trajectory_generator.h"
#include "support/test_robots.h"

namespace selfcal::sim {
namespace {

// The PUMA 560 in its eye-to-hand cell: the fixed camera 0.8 m in front of the flange at the config's home.
RobotModel PumaEyeToHand() {
  RobotModel puma = testing::Puma560();
  Eigen::VectorXd home(6);
  home << 0, 20, -200, 0, 45, 0;
  puma.mount = CameraMount::kEyeToHand;
  puma.base_from_cam = DefaultFixedCamera(puma, home * kPi / 180);
  return puma;
}

std::vector<Eigen::VectorXd> Start(const RobotModel& robot) {
  EyeToHandTrajectoryOptions options;
  options.home_joints_deg = {0, 20, -200, 0, 45, 0};
  const GeneratedTrajectory t = MakeEyeToHandTrajectory(robot, options);
  EXPECT_TRUE(t.ok) << t.message;
  return t.joints;
}

TEST(EyeToHandSim, DefaultCameraFacesTheFlangeAtHome) {
  const RobotModel robot = PumaEyeToHand();
  Eigen::VectorXd home(6);
  home << 0, 20, -200, 0, 45, 0;
  const Rigid3 flange = BaseFromFlange(robot, KinematicParameters::Nominal(robot), home * kPi / 180);
  const Rigid3& cam = robot.base_from_cam;
  EXPECT_NEAR((cam.translation - flange.translation).norm(), 0.8, 1e-12);
  // The optical axis points at the flange, against the flange's z axis.
  EXPECT_NEAR(cam.rotation.col(2).dot(-flange.rotation.col(2)), 1.0, 1e-12);
  EXPECT_NEAR((cam.rotation.transpose() * cam.rotation - Eigen::Matrix3d::Identity()).norm(), 0, 1e-12);
}

TEST(EyeToHandSim, TrajectoryKeepsThePlateFacingTheCameraAndMovesEveryJoint) {
  const RobotModel robot = PumaEyeToHand();
  const std::vector<Eigen::VectorXd> joints = Start(robot);
  ASSERT_EQ(joints.size(), 25u);
  Eigen::VectorXd lo = joints[0], hi = joints[0];
  for (size_t i = 0; i < joints.size(); ++i) {
    EXPECT_TRUE(WithinLimits(robot, joints[i], DegToRad(5))) << "pose " << i;
    const Rigid3 x = PointsFromCam(robot, KinematicParameters::Nominal(robot), joints[i]);
    // The camera seen from the flange: in front of the plate (flange +z), within 35 deg of its normal.
    const Eigen::Vector3d to_camera = (x.translation - Eigen::Vector3d(0, 0, 0.03)).normalized();
    EXPECT_GT(to_camera.z(), std::cos(DegToRad(35))) << "pose " << i;
    lo = lo.cwiseMin(joints[i]);
    hi = hi.cwiseMax(joints[i]);
  }
  for (int j = 0; j < 6; ++j) EXPECT_GT(hi[j] - lo[j], DegToRad(5)) << "joint " << j + 1;
}

TEST(EyeToHandSim, DotsOnThePlateProjectThroughPointsFromCam) {
  const RobotModel robot = PumaEyeToHand();
  const std::vector<Eigen::VectorXd> joints = Start(robot);
  SimOptions options;
  options.pixel_noise_px = 0.0;
  const SimResult world = Simulate(robot, joints, options);
  ASSERT_TRUE(world.ok) << world.message;
  const SimOptions::Plate& plate = options.plate;
  ASSERT_EQ(world.truth.dots_in_base.size(), static_cast<size_t>(plate.num_dots));
  EXPECT_NEAR((world.truth.dots_in_base[0] - world.truth.dots_in_base[1]).norm(), plate.yardstick_length_m, 1e-12);
  ASSERT_EQ(world.observations.yardsticks.size(), 1u);
  EXPECT_EQ(world.observations.yardsticks[0].length_m, plate.yardstick_length_m);
  int raised = 0;
  for (const Eigen::Vector3d& p : world.truth.dots_in_base) {  // on the plate, in the flange frame
    EXPECT_LE(p.head<2>().cwiseAbs().maxCoeff(), plate.half_size_m);
    const bool on_face = std::abs(p.z() - plate.standoff_m) < 1e-12;
    const bool up = std::abs(p.z() - plate.standoff_m - plate.raised_m) < 1e-12;
    EXPECT_TRUE(on_face || up);
    raised += up ? 1 : 0;
  }
  EXPECT_GE(raised, 2);  // not coplanar
  EXPECT_EQ(world.observations.robot.mount, CameraMount::kEyeToHand);
  // The hidden fixed camera: the nominal one corrected by the hidden camera correction, off by millimetres.
  const Rigid3 truth_cam = FixedCameraTruth(world.truth);
  const PoseDifference off = ComparePoses(truth_cam, robot.base_from_cam);
  EXPECT_GT(off.position_m, 1e-5);
  EXPECT_LT(off.position_m, 0.02);
  for (size_t i = 0; i < joints.size(); ++i) {
    const Rigid3 flange = BaseFromFlange(robot, world.truth.rho_true, joints[i]);
    ASSERT_EQ(world.observations.poses[i].dots_px.size(), world.truth.dots_in_base.size()) << "pose " << i;
    for (const auto& [id, px] : world.observations.poses[i].dots_px) {
      // Through the base: the dot carried by the true flange, seen by the true fixed camera.
      const Eigen::Vector3d in_base = flange * world.truth.dots_in_base[id];
      const auto expected = Project(world.truth.camera_true, truth_cam.Inverse() * in_base);
      ASSERT_TRUE(expected.has_value());
      EXPECT_LT((*expected - px).norm(), 1e-8) << "pose " << i << " dot " << id;
    }
  }
}

TEST(EyeToHandSim, SeededAndRenderedDiscsMatchTheProjections) {
  const RobotModel robot = PumaEyeToHand();
  const std::vector<Eigen::VectorXd> joints = Start(robot);
  SimOptions options;
  options.separation_dot_radius_m = kDefaultDotRadiusM;
  const SimResult a = Simulate(robot, joints, options), b = Simulate(robot, joints, options);
  ASSERT_TRUE(a.ok) << a.message;
  EXPECT_EQ(a.truth.dots_in_base, b.truth.dots_in_base);
  EXPECT_EQ(a.truth.rho_true, b.truth.rho_true);
  options.world_seed = 2;
  const SimResult c = Simulate(robot, joints, options);
  ASSERT_TRUE(c.ok) << c.message;
  EXPECT_NE(a.truth.dots_in_base, c.truth.dots_in_base);
  // The renderer, given PointsFromCam, draws every plate dot whole where it projects.
  const DotScene scene = MakeDotScene(a.truth);
  RenderOptions render;
  render.supersampling = 4;
  const RenderedImage image = RenderDots(a.truth.camera_true, a.truth.base_from_cam[3], scene, render, 1);
  for (const RenderedDot& d : image.dots) {
    EXPECT_TRUE(d.in_front && d.fully_inside) << "dot " << d.id;
    const auto uv = Project(a.truth.camera_true, a.truth.base_from_cam[3].Inverse() * a.truth.dots_in_base[d.id]);
    EXPECT_LT((d.projected_centre_px - *uv).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace selfcal::sim
