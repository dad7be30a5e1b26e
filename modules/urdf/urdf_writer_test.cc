#include "urdf/urdf_writer.h"

#include <random>

#include <gtest/gtest.h>

#include "support/temp_files.h"
#include "support/test_robots.h"

namespace selfcal::urdf {
namespace {

// The PUMA with every parameter of rho moved (betas, base and camera corrections included), as a
// calibration would leave it.
RobotModel CalibratedLike(const RobotModel& nominal, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> small(0, 0.01);
  Eigen::VectorXd rho = KinematicParameters::Nominal(nominal);
  for (int i = 0; i < rho.size(); ++i) rho[i] += small(rng);
  return ApplyParameters(nominal, rho);
}

// KDL's forward kinematics of `text` (re-read by urdfdom, the chain built by kdl_chain.h) against the model's.
void ExpectKdlEqualsModel(const std::string& text, const RobotModel& model) {
  const std::vector<Eigen::VectorXd> joints = RandomJointsWithinLimits(model, 1000, 21);
  Result<std::vector<Rigid3>> tips = KdlChainPoses(text, "written", "base_link", "tool0", joints);
  Result<std::vector<Rigid3>> cams = KdlChainPoses(text, "written", "base_link", "camera_optical_frame", joints);
  ASSERT_TRUE(tips.ok()) << tips.status().message();
  ASSERT_TRUE(cams.ok()) << cams.status().message();
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  for (size_t i = 0; i < joints.size(); ++i) {
    ASSERT_TRUE(testing::RigidNear(BaseFromFlange(model, rho, joints[i]), (*tips)[i], 1e-9, 1e-9)) << i;
    ASSERT_TRUE(testing::RigidNear(BaseFromCam(model, rho, joints[i]), (*cams)[i], 1e-9, 1e-9)) << i;
  }
}

TEST(UrdfWriter, CalibratedModelsKdlForwardKinematicsEqualsTheModel) {
  for (const RobotModel& nominal : {testing::Puma560(), testing::Ur5e()}) {
    const RobotModel calibrated = CalibratedLike(nominal, 3);
    testing::TempDir dir;
    ASSERT_TRUE(WriteUrdf(calibrated, {}, dir.File("calibrated.urdf")).ok());
    const std::string text = testing::ReadFile(dir.File("calibrated.urdf"));
    ExpectKdlEqualsModel(text, calibrated);
    // Read back as a robot (urdfdom, the conversion and its own KDL check): the same arm, limits and names.
    Result<UrdfRobot> back =
        ParseUrdfRobot(text, "calibrated.urdf", {"base_link", "tool0", "camera_optical_frame"}, std::nullopt);
    ASSERT_TRUE(back.ok()) << back.status().message();
    EXPECT_EQ(back->joint_names.front(), "joint1");
    for (int j = 0; j < calibrated.num_joints(); ++j) {
      EXPECT_EQ(back->model.limits[j].min_rad, calibrated.limits[j].min_rad);
      EXPECT_EQ(back->model.limits[j].max_rad, calibrated.limits[j].max_rad);
    }
    for (const Eigen::VectorXd& q : RandomJointsWithinLimits(calibrated, 200, 8)) {
      EXPECT_TRUE(testing::RigidNear(BaseFromCam(calibrated, KinematicParameters::Nominal(calibrated), q),
                                     BaseFromCam(back->model, KinematicParameters::Nominal(back->model), q), 1e-9,
                                     1e-9));
    }
  }
}

// Eye-to-hand: the camera hangs from base_link (a chain without joints), the arm as before; KDL agrees
// with the model's fixed camera and flange.
TEST(UrdfWriter, AFixedCameraHangsFromTheBase) {
  RobotModel nominal = testing::Puma560();
  nominal.mount = CameraMount::kEyeToHand;
  nominal.base_from_cam = Rigid3(RotZ(0.4) * RotX(2.6), Eigen::Vector3d(0.8, -0.1, 0.5));
  const RobotModel calibrated = CalibratedLike(nominal, 4);
  Result<std::string> text = UrdfOfModel(calibrated, {});
  ASSERT_TRUE(text.ok()) << text.status().message();
  const std::vector<Eigen::VectorXd> joints = RandomJointsWithinLimits(calibrated, 100, 5);
  Result<std::vector<Rigid3>> tips = KdlChainPoses(*text, "written", "base_link", "tool0", joints);
  Result<std::vector<Rigid3>> cams = KdlChainPoses(*text, "written", "base_link", "camera_optical_frame",
                                                   std::vector<Eigen::VectorXd>(1, Eigen::VectorXd()));
  ASSERT_TRUE(tips.ok()) << tips.status().message();
  ASSERT_TRUE(cams.ok()) << cams.status().message();
  const Eigen::VectorXd rho = KinematicParameters::Nominal(calibrated);
  EXPECT_TRUE(testing::RigidNear(calibrated.base_from_cam, cams->front(), 1e-9, 1e-9));
  EXPECT_TRUE(testing::RigidNear(BaseFromCam(calibrated, rho, joints.front()), cams->front(), 1e-9, 1e-9));
  for (size_t i = 0; i < joints.size(); ++i) {
    ASSERT_TRUE(testing::RigidNear(BaseFromFlange(calibrated, rho, joints[i]), (*tips)[i], 1e-9, 1e-9)) << i;
  }
}

TEST(UrdfWriter, OriginsNearGimbalLockStayExact) {
  RobotModel model = testing::Puma560();
  model.links[2].alpha = kPi / 2;
  model.links[2].theta = kPi / 2;  // RotX(90) RotZ(90): pitch -90 deg in roll-pitch-yaw
  model.flange_from_cam = Rigid3(RotY(kPi / 2 - 1e-7), Eigen::Vector3d(0.01, 0, 0.05));
  model.base_from_link0 = Rigid3(RotY(-kPi / 2), Eigen::Vector3d(0, 0, 0.5));
  Result<std::string> text = UrdfOfModel(model, {});
  ASSERT_TRUE(text.ok()) << text.status().message();
  EXPECT_NE(text->find("joint3_origin"), std::string::npos);
  ExpectKdlEqualsModel(*text, model);
}

TEST(UrdfWriter, NamesAreTakenAndEscaped) {
  UrdfNames names;
  names.robot = "arm <\"1\">";
  names.joints = {"a", "b", "c", "d", "e", "f"};
  Result<std::string> text = UrdfOfModel(testing::Ur5e(), names);
  ASSERT_TRUE(text.ok()) << text.status().message();
  EXPECT_NE(text->find("<robot name=\"arm &lt;&quot;1&quot;&gt;\">"), std::string::npos) << *text;
  EXPECT_NE(text->find("<joint name=\"f\" type=\"revolute\">"), std::string::npos) << *text;
  names.joints.pop_back();
  EXPECT_FALSE(UrdfOfModel(testing::Ur5e(), names).ok());
}

TEST(UrdfWriter, RefusesATextKdlDisagreesWith) {
  FkCheckOptions impossible;
  impossible.tolerance_m = impossible.tolerance_rad = 1e-300;
  Result<std::string> text = UrdfOfModel(testing::Puma560(), {}, impossible);
  ASSERT_FALSE(text.ok());
  EXPECT_EQ(text.status().code(), ErrorCode::kInternal);
  EXPECT_NE(text.status().message().find("differs from KDL's"), std::string::npos) << text.status().message();
}

}  // namespace
}  // namespace selfcal::urdf
