#include "sim/sim_world.h"

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include "sim/trajectory_generator.h"
#include "support/test_robots.h"

namespace selfcal::sim {
namespace {

std::vector<Eigen::VectorXd> ArcTrajectory(const RobotModel& robot) {
  const GeneratedTrajectory t = MakeArcTrajectory(robot, ArcTrajectoryOptions());
  EXPECT_TRUE(t.ok) << t.message;
  return t.joints;
}

TEST(Sim, ArcTrajectoryIsSmoothAndWithinLimits) {
  const RobotModel puma = testing::Puma560();
  const std::vector<Eigen::VectorXd> joints = ArcTrajectory(puma);
  ASSERT_EQ(joints.size(), 25u);
  for (size_t i = 0; i < joints.size(); ++i) {
    EXPECT_TRUE(WithinLimits(puma, joints[i], DegToRad(5))) << "pose " << i;
    if (i > 0) {
      EXPECT_LT((joints[i] - joints[i - 1]).cwiseAbs().maxCoeff(), DegToRad(30)) << "pose " << i;
    }
  }
}

TEST(Sim, EveryDotInEveryViewAndProjectionsMatchTruth) {
  const RobotModel puma = testing::Puma560();
  SimOptions options;
  options.pixel_noise_px = 0.0;
  const SimResult world = Simulate(puma, ArcTrajectory(puma), options);
  ASSERT_TRUE(world.ok) << world.message;
  const ObservationSet& obs = world.observations;
  EXPECT_EQ(obs.Validate(), "");
  ASSERT_EQ(obs.poses.size(), 25u);
  EXPECT_EQ(obs.PosesWithRole(PoseRole::kIdentification).size(), 15u);
  EXPECT_EQ(world.truth.dots_in_base.size(), 80u);
  EXPECT_NEAR((world.truth.dots_in_base[0] - world.truth.dots_in_base[1]).norm(), 0.2, 1e-12);
  // The solver sees the nominal f_x, not the hidden one.
  EXPECT_EQ(obs.camera.fx_px, 1000.0);
  EXPECT_NE(world.truth.camera_true.fx_px, 1000.0);
  for (size_t i = 0; i < obs.poses.size(); ++i) {
    ASSERT_EQ(obs.poses[i].dots_px.size(), 80u) << "pose " << i;
    const Rigid3 cam_from_base = BaseFromCam(puma, world.truth.rho_true, obs.poses[i].joints_rad).Inverse();
    for (const auto& [id, px] : obs.poses[i].dots_px) {
      EXPECT_TRUE(InImage(obs.camera, px, options.image_margin_px));
      const auto expected = Project(world.truth.camera_true, cam_from_base * world.truth.dots_in_base[id]);
      ASSERT_TRUE(expected.has_value());
      EXPECT_LT((*expected - px).norm(), 1e-9);
    }
  }
}

TEST(Sim, HiddenErrorsMakeTheNominalModelWrongAndAreSeeded) {
  const RobotModel puma = testing::Puma560();
  const std::vector<Eigen::VectorXd> joints = ArcTrajectory(puma);
  SimOptions options;
  const SimResult a = Simulate(puma, joints, options);
  const SimResult b = Simulate(puma, joints, options);
  options.world_seed = 2;
  const SimResult c = Simulate(puma, joints, options);
  ASSERT_TRUE(a.ok && b.ok && c.ok);
  EXPECT_EQ(a.truth.rho_true, b.truth.rho_true);
  EXPECT_EQ(a.observations.poses[3].dots_px.at(7), b.observations.poses[3].dots_px.at(7));
  EXPECT_NE(a.truth.rho_true, c.truth.rho_true);
  // Errors only on identifiable parameters by default, of the stated size (1 mm, 0.2 deg).
  const Eigen::VectorXd delta = a.truth.rho_true - KinematicParameters::Nominal(puma);
  const KinematicParameters params(6);
  int perturbed = 0;
  for (int i = 0; i < params.size(); ++i) {
    const bool listed = std::count(a.truth.perturbed_indices.begin(), a.truth.perturbed_indices.end(), i) > 0;
    if (!listed) {
      EXPECT_EQ(delta[i], 0.0) << params.name(i);
    }
    if (delta[i] != 0.0) ++perturbed;
    const double bound = params.kind(i) == ParameterKind::kLength ? 5 * 2e-3 : 5 * DegToRad(0.5);
    EXPECT_LT(std::abs(delta[i]), bound) << params.name(i);
  }
  EXPECT_GT(perturbed, 20);
  // The nominal model mispredicts the true relative camera poses by millimetres.
  const Eigen::VectorXd rho0 = KinematicParameters::Nominal(puma);
  const Rigid3 true_rel = BaseFromCam(puma, a.truth.rho_true, joints[0]).Inverse() * BaseFromCam(puma, a.truth.rho_true, joints[20]);
  const Rigid3 nominal_rel = BaseFromCam(puma, rho0, joints[0]).Inverse() * BaseFromCam(puma, rho0, joints[20]);
  EXPECT_GT(ComparePoses(true_rel, nominal_rel).position_m, 5e-4);
}

TEST(Sim, ReobserveChangesOnlyTheNoise) {
  const RobotModel puma = testing::Puma560();
  SimOptions options;
  options.pixel_noise_px = 0.0;
  const SimResult world = Simulate(puma, ArcTrajectory(puma), options);
  ASSERT_TRUE(world.ok);
  const ObservationSet noisy = Reobserve(world, 0.5, 9);
  double sum2 = 0;
  int n = 0;
  for (size_t i = 0; i < noisy.poses.size(); ++i) {
    for (const auto& [id, px] : noisy.poses[i].dots_px) {
      sum2 += (px - world.observations.poses[i].dots_px.at(id)).squaredNorm();
      n += 2;
    }
  }
  // 4000 coordinates: the sample std is within ~5 % of 0.5 px with overwhelming probability.
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.5, 0.025);
}

// A flat dot sheet: one plane through the scene, the yardstick on it, every dot in every view.
TEST(Sim, FlatSheetPutsEveryDotOnOnePlaneInViewOfEveryPose) {
  const RobotModel puma = testing::Puma560();
  SimOptions options;
  options.pixel_noise_px = 0.0;
  options.flat_sheet = true;
  const SimResult world = Simulate(puma, ArcTrajectory(puma), options);
  ASSERT_TRUE(world.ok) << world.message;
  const std::vector<Eigen::Vector3d>& dots = world.truth.dots_in_base;
  ASSERT_EQ(dots.size(), 80u);
  EXPECT_NEAR((dots[0] - dots[1]).norm(), options.yardstick_length_m, 1e-12);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : dots) mean += p;
  mean /= static_cast<double>(dots.size());
  Eigen::MatrixXd centred(3, dots.size());
  for (size_t d = 0; d < dots.size(); ++d) centred.col(d) = dots[d] - mean;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeFullU);
  const Eigen::Vector3d normal = svd.matrixU().col(2);
  EXPECT_GT(svd.singularValues()[1], 0.3);  // a sheet, not a line: spread over tenths of a metre
  for (size_t d = 0; d < dots.size(); ++d) EXPECT_LT(std::abs(normal.dot(dots[d] - mean)), 1e-12) << "dot " << d;
  const ObservationSet& obs = world.observations;
  EXPECT_EQ(obs.Validate(), "");
  for (size_t i = 0; i < obs.poses.size(); ++i) {
    ASSERT_EQ(obs.poses[i].dots_px.size(), 80u) << "pose " << i;
    const Rigid3 cam_from_base = world.truth.base_from_cam[i].Inverse();
    for (const auto& [id, px] : obs.poses[i].dots_px) {
      EXPECT_GE((cam_from_base * dots[id]).z(), options.min_depth_m) << "pose " << i << " dot " << id;
      EXPECT_TRUE(InImage(obs.camera, px, options.image_margin_px)) << "pose " << i << " dot " << id;
    }
  }
  // The sheet faces the cameras: the mean optical axis is its normal.
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  for (const Rigid3& c : world.truth.base_from_cam) axis += c.rotation.col(2);
  EXPECT_GT(std::abs(normal.dot(axis.normalized())), 1 - 1e-9);
}

// A flat sheet laid out as a modified circle grid: ids row * cols + col on the spacing, seen from the
// printed side (col x row towards every camera), the origin dot larger, the diagonal the yardstick; a
// grid too large for the views is refused by name.
TEST(Sim, FlatSheetGridIsTheModifiedCircleGridSeenFromItsPrintedSide) {
  const RobotModel puma = testing::Puma560();
  SimOptions options;
  options.pixel_noise_px = 0.0;
  options.flat_sheet = true;
  options.sheet_grid.rows = 6;
  options.sheet_grid.cols = 8;
  options.sheet_grid.spacing_m = 0.02;
  const SimResult world = Simulate(puma, ArcTrajectory(puma), options);
  ASSERT_TRUE(world.ok) << world.message;
  const std::vector<Eigen::Vector3d>& dots = world.truth.dots_in_base;
  ASSERT_EQ(dots.size(), 48u);
  const Eigen::Vector3d col = (dots[1] - dots[0]) / 0.02, row = (dots[8] - dots[0]) / 0.02;
  EXPECT_NEAR(col.norm(), 1, 1e-12);
  EXPECT_NEAR(row.norm(), 1, 1e-12);
  EXPECT_NEAR(col.dot(row), 0, 1e-12);
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 8; ++c) {
      EXPECT_LT((dots[r * 8 + c] - (dots[0] + 0.02 * (c * col + r * row))).norm(), 1e-12) << r << ", " << c;
    }
  }
  for (const Rigid3& cam : world.truth.base_from_cam) {
    EXPECT_GT(col.cross(row).dot((cam.translation - dots[0]).normalized()), 0.5);  // facing the camera
  }
  ASSERT_EQ(world.truth.dot_radius_scale.size(), 48u);
  EXPECT_EQ(world.truth.dot_radius_scale[0], options.sheet_grid.origin_radius_scale);
  EXPECT_EQ(world.truth.dot_radius_scale[47], 1.0);
  ASSERT_EQ(world.observations.yardsticks.size(), 1u);
  EXPECT_EQ(world.observations.yardsticks[0].dot_b, 47);
  EXPECT_NEAR(world.observations.yardsticks[0].length_m, 0.02 * std::hypot(7, 5), 1e-12);
  EXPECT_EQ(world.observations.Validate(), "");

  options.sheet_grid.spacing_m = 0.2;
  const SimResult too_large = Simulate(puma, ArcTrajectory(puma), options);
  EXPECT_FALSE(too_large.ok);
  EXPECT_NE(too_large.message.find("the 6 x 8 grid of 200 mm does not fit in every view"), std::string::npos)
      << too_large.message;
}

TEST(Sim, RefusesImpossibleSetups) {
  const RobotModel puma = testing::Puma560();
  std::vector<Eigen::VectorXd> joints = ArcTrajectory(puma);
  SimOptions options;
  options.num_dots = 5;
  EXPECT_FALSE(Simulate(puma, joints, options).ok);
  options = SimOptions();
  options.sheet_grid.rows = options.sheet_grid.cols = 4;  // a grid needs flat_sheet
  EXPECT_NE(Simulate(puma, joints, options).message.find("sheet_grid needs flat_sheet"), std::string::npos);
  options = SimOptions();
  joints[4][1] = DegToRad(-80);  // beyond joint 2's -45 deg limit
  const SimResult r = Simulate(puma, joints, options);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("pose 4"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace selfcal::sim
