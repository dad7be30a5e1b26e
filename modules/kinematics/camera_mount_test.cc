// Eye-to-hand kinematics: the fixed camera, the camera in the points' (flange) frame, the parameters and the
// scale applied to a fixed camera.
#include <random>

#include <gtest/gtest.h>

#include "kinematics/robot_model.h"
#include "support/test_robots.h"

namespace selfcal {
namespace {

using testing::RigidNear;

RobotModel EyeToHandPuma() {
  RobotModel model = testing::Puma560();
  model.mount = CameraMount::kEyeToHand;
  model.base_from_cam = Rigid3(RotZ(0.3) * RotX(2.8), Eigen::Vector3d(0.9, -0.1, 0.6));
  return model;
}

Eigen::VectorXd SomePose() { return (Eigen::VectorXd(6) << 0.1, -0.4, 0.5, 0.7, -0.3, 0.2).finished(); }

Eigen::VectorXd PerturbedRho(const RobotModel& model, unsigned seed) {
  Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 0.01);
  for (int i = 0; i < rho.size(); ++i) rho[i] += g(rng);
  return rho;
}

TEST(CameraMount, NamesRoundTripAndOthersAreRefused) {
  for (CameraMount m : {CameraMount::kEyeInHand, CameraMount::kEyeToHand}) {
    CameraMount parsed = m == CameraMount::kEyeInHand ? CameraMount::kEyeToHand : CameraMount::kEyeInHand;
    ASSERT_TRUE(ParseCameraMount(CameraMountName(m), &parsed));
    EXPECT_EQ(parsed, m);
  }
  CameraMount untouched = CameraMount::kEyeToHand;
  EXPECT_FALSE(ParseCameraMount("eye-to-hand", &untouched));
  EXPECT_FALSE(ParseCameraMount("", &untouched));
  EXPECT_EQ(untouched, CameraMount::kEyeToHand);
}

TEST(CameraMount, EyeInHandPointsFrameIsTheBase) {
  const RobotModel puma = testing::Puma560();
  const Eigen::VectorXd rho = PerturbedRho(puma, 3);
  EXPECT_TRUE(RigidNear(PointsFromCam(puma, rho, SomePose()), BaseFromCam(puma, rho, SomePose()), 0, 0));
}

TEST(CameraMount, EyeToHandCameraIsFixedAndPointsFrameIsTheFlange) {
  const RobotModel model = EyeToHandPuma();
  const Eigen::VectorXd rho = PerturbedRho(model, 4);
  const Eigen::VectorXd q1 = SomePose();
  const Eigen::VectorXd q2 = q1 + Eigen::VectorXd::Constant(6, 0.3);
  const Rigid3 base_from_cam = BaseFromCam(model, rho, q1);
  EXPECT_TRUE(RigidNear(base_from_cam, BaseFromCam(model, rho, q2), 0, 0));
  const Rigid3 cam_correction = RigidFromTranslationRotvec(rho.data() + KinematicParameters(6).CamOffset());
  EXPECT_TRUE(RigidNear(base_from_cam, model.base_from_cam * cam_correction, 1e-15, 1e-15));
  // A point carried by the flange seen from the fixed camera, either way round.
  const Eigen::Vector3d in_flange(0.02, -0.03, 0.05);
  for (const Eigen::VectorXd& q : {q1, q2}) {
    const Eigen::Vector3d through_base = base_from_cam.Inverse() * (BaseFromFlange(model, rho, q) * in_flange);
    const Eigen::Vector3d through_points = PointsFromCam(model, rho, q).Inverse() * in_flange;
    EXPECT_LT((through_base - through_points).norm(), 1e-14);
  }
  // flange_from_cam takes no part in eye-to-hand.
  RobotModel other = model;
  other.flange_from_cam = Rigid3(RotY(1.0), Eigen::Vector3d(0.3, 0.2, 0.1));
  EXPECT_TRUE(RigidNear(PointsFromCam(model, rho, q1), PointsFromCam(other, rho, q1), 0, 0));
}

TEST(CameraMount, EyeToHandGivenFlangeMatchesTheJointChain) {
  const RobotModel model = EyeToHandPuma();
  const Eigen::VectorXd rho = PerturbedRho(model, 5);
  const Rigid3 base_from_flange = BaseFromFlange(model, rho, SomePose());
  // The recorded flange pose replaces the whole chain, base correction included: with the base correction
  // zeroed and the nominal base identity, both give the same camera.
  RobotModel flat = model;
  flat.base_from_link0 = Rigid3();
  Eigen::VectorXd rho_flat = rho;
  rho_flat.head<6>().setZero();
  EXPECT_TRUE(RigidNear(PointsFromCamGivenFlange<double>(flat, rho_flat.data(), base_from_flange),
                        PointsFromCam(model, rho, SomePose()), 1e-14, 1e-14));
}

TEST(CameraMount, EyeToHandApplyParametersMovesTheFixedCamera) {
  const RobotModel model = EyeToHandPuma();
  const Eigen::VectorXd rho = PerturbedRho(model, 6);
  const RobotModel applied = ApplyParameters(model, rho);
  EXPECT_TRUE(RigidNear(applied.flange_from_cam, model.flange_from_cam, 0, 0));
  EXPECT_TRUE(RigidNear(PointsFromCam(model, rho, SomePose()),
                        PointsFromCam(applied, KinematicParameters::Nominal(applied), SomePose()), 1e-14, 1e-14));
}

TEST(CameraMount, EyeToHandScaleLengthsScalesTheFixedCamera) {
  RobotModel model = EyeToHandPuma();
  Eigen::VectorXd rho = PerturbedRho(model, 7);
  const Rigid3 before = PointsFromCam(model, rho, SomePose());
  ScaleLengths(1.25, &model, &rho);
  const Rigid3 after = PointsFromCam(model, rho, SomePose());
  EXPECT_TRUE(RigidNear(Rigid3(before.rotation, 1.25 * before.translation), after, 1e-14, 1e-14));
}

}  // namespace
}  // namespace selfcal
