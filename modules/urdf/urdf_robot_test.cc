#include "urdf/urdf_robot.h"

#include <regex>

#include <gtest/gtest.h>

#include "support/temp_files.h"
#include "support/test_robots.h"

namespace selfcal::urdf {
namespace {

std::string DataFile(const std::string& name) { return std::string(SELFCAL_SOURCE_DIR) + "/test/data/urdf/" + name; }
const UrdfChainSpec kWithCamera{"base_link", "tool0", "camera_optical_frame"};

// Worst position (m) and rotation (rad) difference of base_from_cam between two models at random joints.
std::pair<double, double> WorstCamDifference(const RobotModel& a, const RobotModel& b, int samples,
                                             std::uint64_t seed) {
  double worst_m = 0, worst_rad = 0;
  for (const Eigen::VectorXd& q : RandomJointsWithinLimits(a, samples, seed)) {
    const PoseDifference d = ComparePoses(BaseFromCam(a, KinematicParameters::Nominal(a), q),
                                          BaseFromCam(b, KinematicParameters::Nominal(b), q));
    worst_m = std::max(worst_m, d.position_m);
    worst_rad = std::max(worst_rad, d.rotation_rad);
  }
  return {worst_m, worst_rad};
}

void ExpectSameRobot(const RobotModel& dh, const std::string& file) {
  Result<UrdfRobot> robot = LoadUrdfRobot(DataFile(file), kWithCamera, std::nullopt);
  ASSERT_TRUE(robot.ok()) << robot.status().message();
  ASSERT_EQ(robot->model.num_joints(), dh.num_joints());
  EXPECT_EQ(robot->check.samples, 200);
  EXPECT_LE(robot->check.worst_position_m, 1e-9);
  EXPECT_LE(robot->check.worst_rotation_rad, 1e-9);
  for (int j = 0; j < dh.num_joints(); ++j) {
    EXPECT_EQ(robot->joint_names[j], "joint" + std::to_string(j + 1));
    EXPECT_NEAR(robot->model.limits[j].min_rad, dh.limits[j].min_rad, 1e-15);
    EXPECT_NEAR(robot->model.limits[j].max_rad, dh.limits[j].max_rad, 1e-15);
  }
  EXPECT_TRUE(testing::RigidNear(dh.flange_from_cam, robot->model.flange_from_cam, 1e-15, 1e-15));
  // Same forward kinematics as the DH table the URDF was written from, at joints other than the check's.
  const auto [m, rad] = WorstCamDifference(robot->model, dh, 1000, 7);
  EXPECT_LE(m, 1e-9);
  EXPECT_LE(rad, 1e-9);
  // And as KDL's, at those joints too, flange and camera.
  const std::string text = testing::ReadFile(DataFile(file));
  const std::vector<Eigen::VectorXd> joints = RandomJointsWithinLimits(dh, 300, 11);
  Result<std::vector<Rigid3>> flanges = KdlChainPoses(text, file, "base_link", "flange", joints);
  ASSERT_TRUE(flanges.ok()) << flanges.status().message();
  for (size_t i = 0; i < joints.size(); ++i) {
    EXPECT_TRUE(testing::RigidNear((*flanges)[i],
                                   BaseFromFlange(robot->model, KinematicParameters::Nominal(robot->model), joints[i]),
                                   1e-9, 1e-9));
  }
}

TEST(UrdfRobot, Ur5eEqualsItsDhTableAndKdl) { ExpectSameRobot(testing::Ur5e(), "ur5e.urdf"); }

TEST(UrdfRobot, PumaWithAxesOffZAndFixedMountsEqualsItsDhTableAndKdl) {
  ExpectSameRobot(testing::Puma560(), "puma560.urdf");
}

TEST(UrdfRobot, ParallelAxesTakeHayatiBetaNotHugeOffsets) {
  Result<UrdfRobot> robot = LoadUrdfRobot(DataFile("ur5e.urdf"), kWithCamera, std::nullopt);
  ASSERT_TRUE(robot.ok()) << robot.status().message();
  EXPECT_EQ(ParallelAxisPairs(robot->model), (std::vector<int>{2, 3}));  // pairs (2,3) and (3,4)
  for (const LinkParameters& link : robot->model.links) EXPECT_LT(std::abs(link.d), 0.2);
  // The elbow axis tilted by 1e-4 and 0.05 rad towards the common normal (about y, where plain DH would
  // need an offset d of about a / tilt): a beta of that size, offsets still small.
  for (const double tilt : {1e-4, 0.05}) {
    std::string text = testing::ReadFile(DataFile("ur5e.urdf"));
    const size_t at = text.find("<axis xyz=\"0 0 1\"/>", text.find("<joint name=\"joint3\""));
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 19, "<axis xyz=\"" + std::to_string(std::tan(tilt)) + " 0 1\"/>");
    Result<UrdfRobot> tilted = ParseUrdfRobot(text, "tilted.urdf", kWithCamera, std::nullopt);
    ASSERT_TRUE(tilted.ok()) << tilted.status().message();
    double max_beta = 0;
    for (const LinkParameters& link : tilted->model.links) {
      max_beta = std::max(max_beta, std::abs(link.beta));
      EXPECT_LT(std::abs(link.d), 0.2) << tilt;
    }
    EXPECT_NEAR(max_beta, tilt, 2e-6) << tilt;
  }
}

TEST(UrdfRobot, ReversedAndObliqueUnnormalisedAxesMatchKdl) {
  // Joint 1 turning about -z and joint 4 about an oblique axis of length 2: no longer the DH robot, but
  // the conversion must still reproduce KDL's forward kinematics (the loader's check, 1e-9).
  std::string text = testing::ReadFile(DataFile("ur5e.urdf"));
  for (const auto& [joint, axis] :
       {std::pair<std::string, std::string>{"joint1", "0 0 -1"}, {"joint4", "0.6 -0.8 1.7320508"}}) {
    const size_t at = text.find("<axis xyz=\"0 0 1\"/>", text.find("<joint name=\"" + joint + "\""));
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 19, "<axis xyz=\"" + axis + "\"/>");
  }
  Result<UrdfRobot> robot = ParseUrdfRobot(text, "oblique.urdf", kWithCamera, std::nullopt);
  ASSERT_TRUE(robot.ok()) << robot.status().message();
  EXPECT_LE(robot->check.worst_position_m, 1e-9);
  EXPECT_GT(WorstCamDifference(robot->model, testing::Ur5e(), 50, 2).first, 1e-3);  // a different arm indeed
}

TEST(UrdfRobot, FlangeFromCamGivenWhenNoCameraLink) {
  const Rigid3 cam(RotZ(0.5), Eigen::Vector3d(0.01, 0.02, 0.03));
  Result<UrdfRobot> robot = LoadUrdfRobot(DataFile("ur5e.urdf"), {"base_link", "tool0", ""}, cam);
  ASSERT_TRUE(robot.ok()) << robot.status().message();
  EXPECT_TRUE(testing::RigidNear(cam, robot->model.flange_from_cam, 0, 0));
  Result<UrdfRobot> none = LoadUrdfRobot(DataFile("ur5e.urdf"), {"base_link", "tool0", ""}, std::nullopt);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find("camera_link"), std::string::npos) << none.status().message();
}

void ExpectRefused(const std::string& text, const UrdfChainSpec& spec, const std::string& words) {
  Result<UrdfRobot> robot = ParseUrdfRobot(text, "arm.urdf", spec, Rigid3());
  ASSERT_FALSE(robot.ok()) << words;
  EXPECT_EQ(robot.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(robot.status().message().find(words), std::string::npos) << robot.status().message();
  EXPECT_NE(robot.status().message().find("arm.urdf"), std::string::npos) << robot.status().message();
}

TEST(UrdfRobot, RefusesWhatTheModelCannotHold) {
  const std::string ur = testing::ReadFile(DataFile("ur5e.urdf"));
  const std::string prismatic =
      std::regex_replace(ur, std::regex("name=\"joint4\" type=\"revolute\""), "name=\"joint4\" type=\"prismatic\"");
  ExpectRefused(prismatic, kWithCamera, "joint `joint4` is prismatic");
  const std::string continuous =
      std::regex_replace(ur, std::regex("name=\"joint6\" type=\"revolute\""), "name=\"joint6\" type=\"continuous\"");
  ExpectRefused(continuous, kWithCamera, "joint `joint6` is continuous");
  ExpectRefused(ur, {"base_link", "tool9", ""}, "tip_link `tool9` is not a link of robot `ur5e`");
  ExpectRefused(ur, {"tool0", "base_link", ""}, "link `base_link` is not below link `tool0`");
  ExpectRefused(ur, {"base_link", "link3", "camera_optical_frame"}, "joint `joint4` between tip_link `link3`");
  ExpectRefused("<robot name=\"x\"><link name=", kWithCamera, "arm.urdf:1: unterminated tag `<link`");
}

TEST(UrdfRobot, KdlDisagreementIsRefusedNamingTheWorstPose) {
  FkCheckOptions impossible;
  impossible.tolerance_m = 1e-300;
  impossible.tolerance_rad = 1e-300;
  Result<UrdfRobot> robot = LoadUrdfRobot(DataFile("puma560.urdf"), kWithCamera, std::nullopt, impossible);
  ASSERT_FALSE(robot.ok());
  EXPECT_NE(robot.status().message().find("differs from KDL's by"), std::string::npos) << robot.status().message();
  EXPECT_NE(robot.status().message().find("at joints ["), std::string::npos) << robot.status().message();
}

TEST(UrdfRobot, RandomJointsAreSeededAndWithinLimits) {
  const RobotModel puma = testing::Puma560();
  const auto a = RandomJointsWithinLimits(puma, 50, 3), b = RandomJointsWithinLimits(puma, 50, 3);
  const auto c = RandomJointsWithinLimits(puma, 50, 4);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i], b[i]);
    EXPECT_TRUE(WithinLimits(puma, a[i]));
  }
  EXPECT_NE(a[0], c[0]);
}

}  // namespace
}  // namespace selfcal::urdf
