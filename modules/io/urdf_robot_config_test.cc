// Robot configs that name a URDF: the test URDFs written from the shipped DH configs load to the same
// robots (forward kinematics to 1e-9 over random joints), sessions record the converted model, and the
// keys that would contradict the URDF are refused.
#include "io/urdf_robot_config.h"

#include <random>

#include <gtest/gtest.h>

#include "io/io_test_util.h"
#include "io/robot_config.h"
#include "support/test_robots.h"

namespace selfcal::io {
namespace {

using namespace testing;  // io::testing: TempDir, ReadFile, WriteFile, SourcePath

void ExpectSameArm(const RobotModel& expected, const RobotModel& actual, double tol) {
  ASSERT_EQ(expected.num_joints(), actual.num_joints());
  std::mt19937_64 rng(5);
  for (int j = 0; j < expected.num_joints(); ++j) {
    EXPECT_NEAR(expected.limits[j].min_rad, actual.limits[j].min_rad, 1e-12);
    EXPECT_NEAR(expected.limits[j].max_rad, actual.limits[j].max_rad, 1e-12);
  }
  for (int trial = 0; trial < 500; ++trial) {
    Eigen::VectorXd q(expected.num_joints());
    for (int j = 0; j < q.size(); ++j) {
      q[j] = std::uniform_real_distribution<double>(expected.limits[j].min_rad, expected.limits[j].max_rad)(rng);
    }
    EXPECT_TRUE(selfcal::testing::RigidNear(BaseFromCam(expected, KinematicParameters::Nominal(expected), q),
                                            BaseFromCam(actual, KinematicParameters::Nominal(actual), q), tol, tol))
        << "q = " << q.transpose();
  }
}

TEST(UrdfRobotConfig, TestUrdfsEqualTheShippedDhConfigs) {
  for (const std::string robot : {"ur5e", "puma560"}) {
    Result<RobotModel> dh = LoadRobotModel(SourcePath("config/robots/" + robot + ".yaml"));
    Result<RobotModel> from_urdf = LoadRobotModel(SourcePath("test/data/urdf/" + robot + "_robot.yaml"));
    ASSERT_TRUE(dh.ok()) << dh.status().message();
    ASSERT_TRUE(from_urdf.ok()) << from_urdf.status().message();
    EXPECT_EQ(from_urdf->name, robot);
    ExpectSameArm(*dh, *from_urdf, 1e-9);
  }
}

TEST(UrdfRobotConfig, SessionRecordsTheConvertedModelExactly) {
  const std::string path = SourcePath("test/data/urdf/puma560_robot.yaml");
  Result<std::string> text = RobotConfigTextForSession(path);
  ASSERT_TRUE(text.ok()) << text.status().message();
  EXPECT_EQ(text->find("\nurdf_file:"), std::string::npos) << *text;
  EXPECT_NE(text->find("dh_convention: modified_hayati"), std::string::npos) << *text;
  Result<RobotModel> recorded = ParseRobotModelText(*text, "session/robot.yaml");
  Result<RobotModel> loaded = LoadRobotModel(path);
  ASSERT_TRUE(recorded.ok()) << recorded.status().message();
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  ExpectSameArm(*loaded, *recorded, 1e-15);
  // A DH config is recorded as written.
  const std::string dh = SourcePath("config/robots/ur5e.yaml");
  EXPECT_EQ(*RobotConfigTextForSession(dh), ReadFile(dh));
}

std::string Refusal(const std::string& yaml) {
  TempDir dir;
  WriteFile(dir.File("robot.yaml"), yaml);
  Result<RobotModel> model = LoadRobotModel(dir.File("robot.yaml"));
  return model.ok() ? "" : model.status().message();
}

TEST(UrdfRobotConfig, RefusesContradictionsAndNamesTheUrdfProblem) {
  const std::string urdf = SourcePath("test/data/urdf/ur5e.urdf");
  const std::string head = "urdf_file: " + urdf + "\nbase_link: base_link\ntip_link: tool0\n";
  EXPECT_EQ(Refusal(head + "camera_link: camera_optical_frame\n"), "");
  std::string both =
      Refusal(head + "camera_link: camera_optical_frame\nflange_from_cam: {xyz_mm: [0, 0, 0], rpy_deg: [0, 0, 0]}\n");
  EXPECT_NE(both.find("not both"), std::string::npos) << both;
  std::string joints = Refusal(head + "camera_link: camera_optical_frame\ndh_convention: standard\n");
  EXPECT_NE(joints.find("takes the kinematics from the URDF"), std::string::npos) << joints;
  std::string no_cam = Refusal(head);
  EXPECT_NE(no_cam.find("give camera_link"), std::string::npos) << no_cam;
  std::string bad_tip =
      Refusal("urdf_file: " + urdf + "\nbase_link: base_link\ntip_link: nowhere\ncamera_link: tool0\n");
  EXPECT_NE(bad_tip.find("tip_link `nowhere` is not a link"), std::string::npos) << bad_tip;
  // Issue 36's campaign: the robot config's line of the key the URDF refusal is about, not only its name.
  EXPECT_NE(bad_tip.find("robot.yaml:3: "), std::string::npos) << bad_tip;
  EXPECT_NE(no_cam.find("robot.yaml:1: "), std::string::npos) << no_cam;
  std::string missing = Refusal("urdf_file: absent.urdf\nbase_link: a\ntip_link: b\ncamera_link: c\n");
  EXPECT_NE(missing.find("absent.urdf"), std::string::npos) << missing;
}

}  // namespace
}  // namespace selfcal::io
