// Tests of the scene move behind a refused held-out test (scene_shift.h), on the standard simulated world
// with the hidden truth as the model: a move given to the verification images' points is found again, and a
// wrong model without a move is not taken for one.

#include "calibration/scene_shift.h"

#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "base/numbers.h"
#include "geometry/rigid3.h"
#include "support/sim_worlds.h"

namespace selfcal::calibration {
namespace {

std::map<int, Eigen::Vector3d> TruePoints(const sim::SimResult& world) {
  std::map<int, Eigen::Vector3d> points;
  for (std::size_t i = 0; i < world.truth.dots_in_base.size(); ++i) {
    points[static_cast<int>(i)] = world.truth.dots_in_base[i];
  }
  return points;
}

// The verification poses' dots as the true arm and camera see the points after `move` (about their centroid).
ObservationSet VerificationSeesMovedPoints(const sim::SimResult& world, const Rigid3& move) {
  ObservationSet set = world.observations;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : world.truth.dots_in_base) centre += p;
  centre /= static_cast<double>(world.truth.dots_in_base.size());
  for (PoseObservation& pose : set.poses) {
    if (pose.role != PoseRole::kVerification) continue;
    const Rigid3 cam_from_points = PointsFromCamAt(world.truth.nominal, world.truth.rho_true, pose).Inverse();
    for (auto& [id, pixel] : pose.dots_px) {
      const Eigen::Vector3d moved = move.rotation * (world.truth.dots_in_base[id] - centre) + centre + move.translation;
      pixel = *Project(world.truth.camera_true, cam_from_points * moved);
    }
  }
  return set;
}

// The held-out statistic of the verification dots before the move at a pixel noise of noise_px, and its
// limit (about 1.1 dof for these few hundred dof).
double ChiSquareAt(const SceneShift& shift, double noise_px) {
  return 2.0 * shift.dots * std::pow(shift.rms_before_px / noise_px, 2);
}
double Limit(const SceneShift& shift) { return 2.0 * shift.dots * 1.1; }

TEST(SceneShift, AMoveOfTheVerificationImagesSceneIsFoundAgain) {
  const sim::SimResult world = testing::PumaArcWorld(0.0);
  ASSERT_TRUE(world.ok) << world.message;
  ASSERT_FALSE(world.observations.PosesWithRole(PoseRole::kVerification).empty());
  // 4 mm and 2 deg: about what kvasios' board did between its second and third recording.
  const Rigid3 move(ExpSO3<double>(Eigen::Vector3d(0.01, -0.03, 0.02)), Eigen::Vector3d(0.003, -0.002, 0.0015));
  const ObservationSet set = VerificationSeesMovedPoints(world, move);
  const SceneShift shift = SceneShiftOfVerification(set, world.truth.nominal, world.truth.rho_true,
                                                    world.truth.camera_true, TruePoints(world));
  ASSERT_TRUE(shift.computed);
  EXPECT_GT(shift.poses, 0);
  EXPECT_GT(shift.rms_before_px, 1.0);
  EXPECT_LT(shift.rms_after_px, 1e-6);
  EXPECT_NEAR(shift.translation_m, move.translation.norm(), 1e-8);
  EXPECT_NEAR(shift.rotation_rad, std::sqrt(0.01 * 0.01 + 0.03 * 0.03 + 0.02 * 0.02), 1e-8);
  EXPECT_TRUE(VerificationSceneMoved(shift, ChiSquareAt(shift, 0.1), Limit(shift)));
}

TEST(SceneShift, AWrongLinkLengthIsNotTakenForAMovedScene) {
  const sim::SimResult world = testing::PumaArcWorld(0.0);
  ASSERT_TRUE(world.ok) << world.message;
  const ObservationSet set = VerificationSeesMovedPoints(world, Rigid3());
  Eigen::VectorXd wrong = world.truth.rho_true;
  const int j3_a = KinematicParameters(world.truth.nominal.num_joints()).IndexOf("j3.a");
  ASSERT_GE(j3_a, 0);
  wrong[j3_a] += 0.005;
  const SceneShift shift =
      SceneShiftOfVerification(set, world.truth.nominal, wrong, world.truth.camera_true, TruePoints(world));
  ASSERT_TRUE(shift.computed);
  // The wrong length moves the dots by pixels, and a move of the scene takes most of it (these verification
  // poses are close to each other), but not down to the test's noise (0.1 px here).
  EXPECT_GT(shift.rms_before_px, 1.0);
  EXPECT_GT(shift.rms_after_px, 0.2) << shift.rms_after_px << " of " << shift.rms_before_px;
  EXPECT_FALSE(VerificationSceneMoved(shift, ChiSquareAt(shift, 0.1), Limit(shift)));
}

TEST(SceneShift, NoVerificationPoseIsNoFigure) {
  const sim::SimResult world = testing::PumaArcWorld(0.0);
  ASSERT_TRUE(world.ok) << world.message;
  ObservationSet set = world.observations;
  for (PoseObservation& pose : set.poses) pose.role = PoseRole::kIdentification;
  const SceneShift shift = SceneShiftOfVerification(set, world.truth.nominal, world.truth.rho_true,
                                                    world.truth.camera_true, TruePoints(world));
  EXPECT_FALSE(shift.computed);
  EXPECT_FALSE(VerificationSceneMoved(shift, 1.0, 2.0));
}

}  // namespace
}  // namespace selfcal::calibration
