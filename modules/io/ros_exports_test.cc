// The ROS-facing exports re-read the way ROS reads them: camera_info.yaml by yaml-cpp against the keys of
// camera_calibration_parsers' format, and the UR kinematics file as ur_description's xacro builds its chain
// (per joint <origin xyz rpy> then a turn about z), against the calibrated model's forward kinematics.
#include <random>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "io/camera_info_file.h"
#include "io/io_test_util.h"
#include "io/robot_config.h"
#include "io/robot_origin.h"
#include "io/ur_kinematics_file.h"
#include "support/perturbed_model.h"
#include "support/ur_description_chain.h"

namespace selfcal::io {
namespace {

using namespace testing;  // io::testing: TempDir, ReadFile, SourcePath

std::vector<double> Data(const YAML::Node& matrix, int rows, int cols) {
  EXPECT_EQ(matrix["rows"].as<int>(), rows);
  EXPECT_EQ(matrix["cols"].as<int>(), cols);
  return matrix["data"].as<std::vector<double>>();
}

TEST(CameraInfoFile, HoldsTheCameraInCameraCalibrationParsersKeys) {
  CameraIntrinsics camera;
  camera.width_px = 1280;
  camera.height_px = 960;
  camera.fx_px = 1001.25;
  camera.mu = 1.001;
  camera.cx_px = 641.5;
  camera.cy_px = 478.25;
  camera.k1 = -0.12;
  camera.k2 = 0.03;
  camera.p1 = 1e-4;
  camera.p2 = -2e-4;
  camera.k3 = 0.005;
  TempDir dir;
  ASSERT_TRUE(SaveCameraInfo(camera, "wrist camera", dir.File("camera_info.yaml")).ok());
  const YAML::Node doc = YAML::LoadFile(dir.File("camera_info.yaml"));
  EXPECT_EQ(doc["image_width"].as<int>(), 1280);
  EXPECT_EQ(doc["image_height"].as<int>(), 960);
  EXPECT_EQ(doc["camera_name"].as<std::string>(), "wrist camera");
  EXPECT_EQ(doc["distortion_model"].as<std::string>(), "plumb_bob");
  const double fy = camera.fy_px();
  EXPECT_EQ(Data(doc["camera_matrix"], 3, 3), (std::vector<double>{1001.25, 0, 641.5, 0, fy, 478.25, 0, 0, 1}));
  EXPECT_EQ(Data(doc["distortion_coefficients"], 1, 5), (std::vector<double>{-0.12, 0.03, 1e-4, -2e-4, 0.005}));
  EXPECT_EQ(Data(doc["rectification_matrix"], 3, 3), (std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
  EXPECT_EQ(Data(doc["projection_matrix"], 3, 4),
            (std::vector<double>{1001.25, 0, 641.5, 0, 0, fy, 478.25, 0, 0, 0, 1, 0}));
}

TEST(UrKinematicsFile, ReproducesTheCalibratedModelThroughUrDescriptionsChain) {
  Result<RobotModel> nominal = LoadRobotModel(SourcePath("config/robots/ur5e.yaml"));
  ASSERT_TRUE(nominal.ok()) << nominal.status().message();
  EXPECT_TRUE(IsUniversalRobotsArm(*nominal));
  // Every parameter moved, the tilts of the parallel joints 2-3-4 included, and the base.
  const RobotModel calibrated = selfcal::testing::PerturbedModel(*nominal, 2e-3, DegToRad(0.3), true, 7);
  TempDir dir;
  ASSERT_TRUE(SaveUrKinematics(calibrated, dir.File("ur.yaml")).ok());
  const YAML::Node doc = YAML::LoadFile(dir.File("ur.yaml"));
  ASSERT_TRUE(doc["kinematics"].IsMap());
  EXPECT_EQ(doc["kinematics"].size(), 7u);
  EXPECT_EQ(doc["kinematics"]["hash"].as<std::string>().rfind("calib_", 0), 0u);
  const Eigen::VectorXd rho = KinematicParameters::Nominal(calibrated);
  std::mt19937_64 rng(11);
  double worst_m = 0, worst_rad = 0;
  for (int s = 0; s < 1000; ++s) {
    Eigen::VectorXd q(6);
    for (int j = 0; j < 6; ++j) {
      q[j] = std::uniform_real_distribution<double>(calibrated.limits[j].min_rad, calibrated.limits[j].max_rad)(rng);
    }
    const PoseDifference d = ComparePoses(selfcal::testing::UrDescriptionChain(doc["kinematics"], q), BaseFromFlange(calibrated, rho, q));
    worst_m = std::max(worst_m, d.position_m);
    worst_rad = std::max(worst_rad, d.rotation_rad);
  }
  EXPECT_LE(worst_m, 1e-9);
  EXPECT_LE(worst_rad, 1e-9);
}

TEST(UrKinematicsFile, TheNominalUr5eGivesUrDescriptionsDefaultValues) {
  Result<RobotModel> nominal = LoadRobotModel(SourcePath("config/robots/ur5e.yaml"));
  ASSERT_TRUE(nominal.ok()) << nominal.status().message();
  Result<std::string> text = UrKinematicsYaml(*nominal);
  ASSERT_TRUE(text.ok()) << text.status().message();
  const YAML::Node k = YAML::Load(*text)["kinematics"];
  // ur_description's config/ur5e/default_kinematics.yaml: shoulder z = d1, forearm x = a2, wrist_1 (x, z) =
  // (a3, d4), wrist_2 y = -d5, wrist_3 y = d6, upper_arm and wrist_2 roll pi/2.
  EXPECT_NEAR(k["shoulder"]["z"].as<double>(), 0.1625, 1e-15);
  EXPECT_NEAR(k["forearm"]["x"].as<double>(), -0.425, 1e-15);
  EXPECT_NEAR(k["wrist_1"]["x"].as<double>(), -0.3922, 1e-15);
  EXPECT_NEAR(k["wrist_1"]["z"].as<double>(), 0.1333, 1e-15);
  EXPECT_NEAR(k["wrist_2"]["y"].as<double>(), -0.0997, 1e-15);
  EXPECT_NEAR(k["wrist_3"]["y"].as<double>(), 0.0996, 1e-15);
  EXPECT_NEAR(k["upper_arm"]["roll"].as<double>(), kPi / 2, 1e-15);
  EXPECT_NEAR(k["wrist_2"]["roll"].as<double>(), kPi / 2, 1e-15);
}

TEST(UrKinematicsFile, AFlangeOffTheLastAxisIsRefused) {
  RobotModel model = selfcal::testing::PerturbedModel(*LoadRobotModel(SourcePath("config/robots/ur5e.yaml")), 1e-3,
                                                      1e-3, false, 3);
  model.link_n_from_flange = Rigid3::FromTranslation(Eigen::Vector3d(0.01, 0, 0));
  Result<std::string> text = UrKinematicsYaml(model);
  ASSERT_FALSE(text.ok());
  EXPECT_NE(text.status().message().find("not on the last joint's axis"), std::string::npos);
  RobotModel panda = model;
  panda.name = "panda";
  EXPECT_FALSE(IsUniversalRobotsArm(panda));
}

TEST(RobotOriginOfConfig, ADhConfigsJointNamesLinksAndSpeedsAreReadForTheExports) {
  Result<RobotOrigin> ur = RobotOriginOfConfig(SourcePath("config/robots/ur5e.yaml"));
  ASSERT_TRUE(ur.ok()) << ur.status().message();
  EXPECT_FALSE(ur->FromUrdf());
  EXPECT_EQ(ur->config_joint_names.front(), "shoulder_pan_joint");
  EXPECT_EQ(ur->config_link_names.back(), "wrist_3_link");
  EXPECT_EQ(ur->max_velocity_rad_s, std::vector<double>(6, kPi));
  Result<RobotOrigin> puma = RobotOriginOfConfig(SourcePath("config/robots/puma560.yaml"));
  ASSERT_TRUE(puma.ok()) << puma.status().message();
  EXPECT_TRUE(puma->config_joint_names.empty() && puma->max_velocity_rad_s.empty());
}

TEST(RobotConfig, AJointOrLinkNameGivenTwiceIsRefusedAtItsRow) {
  std::string text = ReadFile(SourcePath("config/robots/ur5e.yaml"));
  const std::string second = "name: shoulder_lift_joint, link: upper_arm_link";
  ASSERT_NE(text.find(second), std::string::npos);
  text.replace(text.find(second), second.size(), "name: shoulder_lift_joint, link: tool0");
  TempDir dir;
  WriteFile(dir.File("robot.yaml"), text);
  Result<RobotModel> loaded = LoadRobotModel(dir.File("robot.yaml"));
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("link name `tool0` of joint 2 at " + dir.File("robot.yaml") + ":19"), std::string::npos)
      << loaded.status().message();
  EXPECT_NE(loaded.status().message().find("is already a link of the calibrated URDF"), std::string::npos);
}

}  // namespace
}  // namespace selfcal::io
