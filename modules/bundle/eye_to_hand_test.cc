// The bundle adjustment of an eye-to-hand cell (a fixed camera, the points on the flange): the twists of
// points_from_cam against numeric derivatives, exact recovery from noise-free images and the
// free set (eye_to_hand_statistics_test.cc: the sigmas against seeded noise).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>

#include <gtest/gtest.h>

#include "bundle/bundle_adjustment.h"
#include "bundle/bundle_problem.h"
#include "support/eye_to_hand_world.h"
#include "support/test_robots.h"

namespace selfcal::bundle {
namespace {

using selfcal::testing::EyeToHandOptions;
using selfcal::testing::EyeToHandWorld;
using selfcal::testing::MakeEyeToHandWorld;

// The twist (omega, v) of points_from_cam for every rho entry, by central differences of PointsFromCamOfPose.
void ExpectTwistsMatchNumeric(const ObservationSet& obs, const Eigen::VectorXd& rho, const char* label) {
  const internal::BundleData data = internal::MakeBundleData(obs, 1e-6);
  std::vector<int> columns(rho.size());
  for (int k = 0; k < rho.size(); ++k) columns[k] = k;
  const double h = 1e-6;
  for (size_t pose = 0; pose < data.joints.size(); pose += 5) {
    internal::PoseCache cache;
    internal::ComputePoseCache(data, static_cast<int>(pose), rho.data(), columns, true, &cache);
    const Rigid3 g = internal::PointsFromCamOfPose(data, static_cast<int>(pose), rho);
    EXPECT_LT((cache.rotation - g.rotation.transpose()).norm(), 1e-15) << label;
    for (int k = 0; k < rho.size(); ++k) {
      Eigen::VectorXd plus = rho, minus = rho;
      plus[k] += h;
      minus[k] -= h;
      const Rigid3 gp = internal::PointsFromCamOfPose(data, static_cast<int>(pose), plus);
      const Rigid3 gm = internal::PointsFromCamOfPose(data, static_cast<int>(pose), minus);
      const Eigen::Matrix3d w = (gp.rotation - gm.rotation) / (2 * h) * g.rotation.transpose();
      const Eigen::Vector3d omega(w(2, 1), w(0, 2), w(1, 0));
      const Eigen::Vector3d v = (gp.translation - gm.translation) / (2 * h) - omega.cross(g.translation);
      // Central differences of O(1) functions at h = 1e-6: truncation ~1e-12, rounding ~1e-10.
      EXPECT_LT((omega - cache.omega[k]).norm(), 1e-8) << label << " pose " << pose << " " << k;
      EXPECT_LT((v - cache.v[k]).norm(), 1e-8) << label << " pose " << pose << " " << k;
    }
  }
}

TEST(EyeToHandBundle, TwistsOfPointsFromCamMatchNumericDerivatives) {
  for (const RobotModel& robot : {selfcal::testing::Puma560(), selfcal::testing::Panda()}) {
    EyeToHandOptions options;
    options.num_poses = 10;
    const EyeToHandWorld world = MakeEyeToHandWorld(robot, options);
    ExpectTwistsMatchNumeric(world.observations, world.rho_true, "joints");
    ObservationSet in_hand = world.observations;  // the same joints eye-in-hand: the other branch
    in_hand.robot.mount = CameraMount::kEyeInHand;
    ExpectTwistsMatchNumeric(in_hand, world.rho_true, "eye-in-hand");
    options.flange_poses = true;
    const EyeToHandWorld flange = MakeEyeToHandWorld(robot, options);
    Eigen::VectorXd rho = flange.rho_true;
    rho.head<6>() << 0.01, -0.02, 0.03, 0.02, -0.01, 0.015;  // a base correction, so that its twists count
    ExpectTwistsMatchNumeric(flange.observations, rho, "flange poses");
  }
}

// Noise-free images: every identifiable parameter, base_from_cam and the points in the flange frame exact.
void ExpectExactRecovery(const RobotModel& robot, bool flange_poses) {
  EyeToHandOptions options;
  options.flange_poses = flange_poses;
  const EyeToHandWorld world = MakeEyeToHandWorld(robot, options);
  const ObservationSet& obs = world.observations;
  const BundleReport r = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, {});
  ASSERT_EQ(r.outcome, Outcome::kConverged) << robot.name << ": " << r.message;
  EXPECT_EQ(r.free_indices, world.perturbed_indices) << robot.name;
  EXPECT_TRUE(r.weak.empty()) << robot.name << ": " << r.weak.front().name;
  const KinematicParameters params(obs.robot.num_joints());
  for (int i = 0; i < r.rho.size(); ++i) {
    EXPECT_NEAR(r.rho[i], world.rho_true[i], 1e-9) << robot.name << " " << params.name(i);
  }
  EXPECT_NEAR(r.fx_px, world.camera_true.fx_px, 1e-6) << robot.name;
  const Rigid3 base_from_cam = BaseFromCam(obs.robot, r.rho, Eigen::VectorXd());
  EXPECT_TRUE(selfcal::testing::RigidNear(world.base_from_cam_true, base_from_cam, 1e-9, 1e-9)) << robot.name;
  ASSERT_EQ(r.dots_in_base.size(), world.dots_in_flange.size());
  for (const auto& [id, p] : r.dots_in_base) {
    EXPECT_LT((p - world.dots_in_flange[id]).norm(), 1e-9) << robot.name << " dot " << id;
  }
  if (!flange_poses) {
    std::cout << "[ figure ] " << robot.name << " eye-to-hand: " << r.free_indices.size() << " free of "
              << r.rho.size() << " (generic rank " << r.generic_rank << ")\n";
  }
}

TEST(EyeToHandBundle, RecoversTheHiddenArmCameraAndPointsExactlyWithoutNoise) {
  for (const RobotModel& robot : {selfcal::testing::Puma560(), selfcal::testing::Ur5e(), selfcal::testing::Panda()}) {
    ExpectExactRecovery(robot, false);
  }
}

TEST(EyeToHandBundle, RecoversTheFixedCameraAndPointsOfAFlangePoseSetExactly) {
  ExpectExactRecovery(selfcal::testing::Puma560(), true);
}

// A set in which no dot can be placed (here: every dot seen by one pose only) ends degenerate and says so,
// rather than blaming f_x (or, before, crashing in the rank selection of a problem without rows).
TEST(EyeToHandBundle, NoDotPlacedIsDegenerateAndSaysWhy) {
  EyeToHandOptions options;
  options.flange_poses = true;
  ObservationSet obs = MakeEyeToHandWorld(selfcal::testing::Puma560(), options).observations;
  int pose_number = 0;
  for (PoseObservation& pose : obs.poses) {
    std::map<int, Eigen::Vector2d> renamed;
    for (const auto& [id, pixel] : pose.dots_px) renamed[1000 * pose_number + id] = pixel;
    pose.dots_px = renamed;
    ++pose_number;
  }
  const BundleReport r = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, {});
  EXPECT_EQ(r.outcome, Outcome::kDegenerate) << r.message;
  EXPECT_NE(r.message.find("no dot could be placed"), std::string::npos) << r.message;
}

// The free set eye-to-hand has the size of the eye-in-hand one of the same poses (mirror gauges): the
// camera correction kept, the base and joint 1 fixed against it, the tail (j_n.theta, j_n.d) fixed by the points.
TEST(EyeToHandBundle, FreeSetMirrorsEyeInHand) {
  for (const RobotModel& robot : {selfcal::testing::Puma560(), selfcal::testing::Ur5e(), selfcal::testing::Panda()}) {
    const EyeToHandWorld world = MakeEyeToHandWorld(robot, EyeToHandOptions());
    const BundleReport r = RunBundleAdjustment(world.observations, KinematicParameters::Nominal(world.observations.robot),
                                               world.observations.camera.fx_px, {});
    ASSERT_EQ(r.outcome, Outcome::kConverged) << r.message;
    const KinematicParameters params(robot.num_joints());
    std::string fixed;
    for (const std::string& name : r.fixed_names) fixed += name + " ";
    std::cout << "[ figure ] " << robot.name << " eye-to-hand fixed: " << fixed << "\n";
    for (int i = 0; i < 6; ++i) EXPECT_NE(std::find(r.free_indices.begin(), r.free_indices.end(), params.CamOffset() + i), r.free_indices.end());
    for (const char* name : {"base.tx", "base.rz", "j1.alpha", "j1.a", "j1.theta", "j1.d"}) {
      EXPECT_NE(std::find(r.fixed_names.begin(), r.fixed_names.end(), name), r.fixed_names.end()) << name;
    }
    const std::string last = "j" + std::to_string(robot.num_joints());
    for (const std::string& name : {last + ".theta", last + ".d"}) {
      EXPECT_NE(std::find(r.fixed_names.begin(), r.fixed_names.end(), name), r.fixed_names.end()) << name;
    }
    EXPECT_EQ(static_cast<int>(r.free_indices.size()), r.generic_rank) << robot.name;
  }
}

}  // namespace
}  // namespace selfcal::bundle
