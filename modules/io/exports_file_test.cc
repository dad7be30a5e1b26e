// The exports' files re-read by what consumes them: the DH table in the user's convention by the
// robot-config loader, the ROS static transform by yaml-cpp, and `entered_as` through a calibrated model.
#include <random>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "io/dh_config_file.h"
#include "io/io_test_util.h"
#include "io/robot_config.h"
#include "io/robot_origin.h"
#include "io/static_transform_file.h"
#include "io/targets_file.h"
#include "io/urdf_robot_config.h"
#include "support/perturbed_model.h"
#include "support/test_robots.h"

namespace selfcal::io {
namespace {

using namespace testing;  // io::testing: TempDir, ReadFile, WriteFile, SourcePath

// The shipped config with every parameter but the betas moved (a calibration the convention can hold).
RobotModel CalibratedLike(const RobotModel& nominal, std::uint64_t seed) {
  return selfcal::testing::PerturbedModel(nominal, 2e-3, DegToRad(0.2), /*with_beta=*/false, seed);
}

void ExpectSameForwardKinematics(const RobotModel& a, const RobotModel& b, double tol) {
  const Eigen::VectorXd rho_a = KinematicParameters::Nominal(a), rho_b = KinematicParameters::Nominal(b);
  std::mt19937_64 rng(9);
  double worst_m = 0, worst_rad = 0;
  for (int s = 0; s < 500; ++s) {
    Eigen::VectorXd q(a.num_joints());
    for (int j = 0; j < q.size(); ++j) {
      q[j] = std::uniform_real_distribution<double>(a.limits[j].min_rad, a.limits[j].max_rad)(rng);
    }
    for (const auto& [x, y] : {std::pair{BaseFromFlange(a, rho_a, q), BaseFromFlange(b, rho_b, q)},
                               std::pair{BaseFromCam(a, rho_a, q), BaseFromCam(b, rho_b, q)}}) {
      const PoseDifference d = ComparePoses(x, y);
      worst_m = std::max(worst_m, d.position_m);
      worst_rad = std::max(worst_rad, d.rotation_rad);
    }
  }
  EXPECT_LE(worst_m, tol);
  EXPECT_LE(worst_rad, tol);
}

TEST(DhConfigFile, CalibratedPumaInStandardDhReadsBackToTheModel) {
  Result<RobotModel> nominal = LoadRobotModel(SourcePath("config/robots/puma560.yaml"));
  ASSERT_TRUE(nominal.ok()) << nominal.status().message();
  Result<RobotOrigin> origin = RobotOriginOfConfig(SourcePath("config/robots/puma560.yaml"));
  ASSERT_TRUE(origin.ok()) << origin.status().message();
  EXPECT_EQ(origin->dh_convention, "standard");
  const RobotModel calibrated = CalibratedLike(*nominal, 1);
  const DhExpression dh = ExpressAsDh(calibrated, "standard");
  ASSERT_TRUE(dh.exact);
  TempDir dir;
  ASSERT_TRUE(SaveDhRobotConfig(dh.table, "puma560", "test", dir.File("robot.yaml")).ok());
  const std::string text = ReadFile(dir.File("robot.yaml"));
  EXPECT_NE(text.find("dh_convention: standard"), std::string::npos) << text;
  EXPECT_EQ(text.find("link_n_from_flange"), std::string::npos) << text;
  Result<RobotModel> reread = LoadRobotModel(dir.File("robot.yaml"));
  ASSERT_TRUE(reread.ok()) << reread.status().message() << "\n" << text;
  EXPECT_EQ(RobotOriginOfConfig(dir.File("robot.yaml"))->dh_convention, "standard");
  ExpectSameForwardKinematics(calibrated, *reread, 1e-9);
}

TEST(DhConfigFile, ModifiedAndHayatiTablesReadBackToTheModel) {
  RobotModel calibrated = CalibratedLike(selfcal::testing::Ur5e(), 2);
  calibrated.link_n_from_flange = Rigid3(RotY(0.2), Eigen::Vector3d(0.001, 0.002, 0.1));
  TempDir dir;
  for (const char* convention : {"modified", "modified_hayati"}) {
    if (std::string(convention) == "modified_hayati") calibrated.links[2].beta = DegToRad(0.03);
    const DhExpression dh = ExpressAsDh(calibrated, convention);
    ASSERT_TRUE(dh.exact) << convention;
    ASSERT_TRUE(SaveDhRobotConfig(dh.table, "ur5e", "", dir.File("robot.yaml")).ok());
    Result<RobotModel> reread = LoadRobotModel(dir.File("robot.yaml"));
    ASSERT_TRUE(reread.ok()) << reread.status().message();
    EXPECT_EQ(RobotOriginOfConfig(dir.File("robot.yaml"))->dh_convention, convention);
    ExpectSameForwardKinematics(calibrated, *reread, 1e-9);
  }
}

TEST(StaticTransformFile, YamlCppReadsTheTransformBack) {
  const Rigid3 flange_from_cam(RotZ(2.9) * RotY(-0.4) * RotX(1.3), Eigen::Vector3d(0.0412345678901, -0.003, 0.0612));
  TempDir dir;
  ASSERT_TRUE(SaveStaticTransform({"tool0", "camera_color_optical_frame", flange_from_cam}, dir.File("tf.yaml")).ok());
  const YAML::Node doc = YAML::LoadFile(dir.File("tf.yaml"));
  EXPECT_EQ(doc["header"]["frame_id"].as<std::string>(), "tool0");
  EXPECT_EQ(doc["child_frame_id"].as<std::string>(), "camera_color_optical_frame");
  const YAML::Node t = doc["transform"]["translation"], r = doc["transform"]["rotation"];
  const Eigen::Vector3d translation(t["x"].as<double>(), t["y"].as<double>(), t["z"].as<double>());
  const Eigen::Quaterniond q(r["w"].as<double>(), r["x"].as<double>(), r["y"].as<double>(), r["z"].as<double>());
  EXPECT_GE(q.w(), 0.0);
  EXPECT_NEAR(q.norm(), 1.0, 1e-15);
  const PoseDifference d = ComparePoses(flange_from_cam, Rigid3(q.toRotationMatrix(), translation));
  EXPECT_LE(d.position_m, 1e-12);
  EXPECT_LE(d.rotation_rad, 1e-12);
}

TEST(StaticTransformFile, LaunchFileCarriesTheYamlsNumbersAndQuotesFrameNames) {
  const Rigid3 flange_from_cam(RotZ(-2.9) * RotX(0.3), Eigen::Vector3d(0.0412345678901, -1e-5, 0.0612));
  const StaticTransform transform{"tool0", "cam's\\frame\n", flange_from_cam};
  const std::string launch = StaticTransformLaunchPy(transform);
  const YAML::Node doc = YAML::Load(StaticTransformYaml(transform));
  const YAML::Node t = doc["transform"]["translation"], r = doc["transform"]["rotation"];
  const std::string expected_numbers = "'--x', '" + t["x"].as<std::string>() + "', '--y', '" + t["y"].as<std::string>() +
                                       "', '--z', '" + t["z"].as<std::string>() + "',\n                '--qx', '" +
                                       r["x"].as<std::string>() + "', '--qy', '" + r["y"].as<std::string>() +
                                       "', '--qz', '" + r["z"].as<std::string>() + "', '--qw', '" +
                                       r["w"].as<std::string>() + "',";
  EXPECT_NE(launch.find(expected_numbers), std::string::npos) << launch;
  EXPECT_NE(launch.find("'--frame-id', 'tool0',"), std::string::npos) << launch;
  EXPECT_NE(launch.find("'--child-frame-id', 'cam\\'s\\\\frame\\x0a',"), std::string::npos) << launch;
  EXPECT_NE(launch.find("executable='static_transform_publisher'"), std::string::npos);
}

TEST(RobotOrigin, UrdfNamesSurviveTheSessionsRecordedRobot) {
  const std::vector<std::string> expected = {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                             "wrist_1_joint",      "wrist_2_joint",       "wrist_3_joint"};
  Result<RobotOrigin> origin = RobotOriginOfConfig(SourcePath("test/data/urdf/ur5e_named_robot.yaml"));
  ASSERT_TRUE(origin.ok()) << origin.status().message();
  EXPECT_EQ(origin->joint_names, expected);
  EXPECT_EQ(origin->base_link, "base_link_inertia");
  EXPECT_EQ(origin->tip_link, "tool_flange");
  EXPECT_EQ(origin->camera_link, "camera_color_optical_frame");
  EXPECT_TRUE(origin->dh_convention.empty());
  // A session records the converted URDF robot; the names come with it, and the robot still loads.
  Result<std::string> recorded = RobotConfigTextForSession(SourcePath("test/data/urdf/ur5e_named_robot.yaml"));
  ASSERT_TRUE(recorded.ok()) << recorded.status().message();
  Result<RobotModel> from_session = ParseRobotModelText(*recorded, "robot.yaml");
  ASSERT_TRUE(from_session.ok()) << from_session.status().message();
  Result<RobotOrigin> recorded_origin = RobotOriginOfConfigText(*recorded, "robot.yaml");
  ASSERT_TRUE(recorded_origin.ok()) << recorded_origin.status().message();
  EXPECT_EQ(recorded_origin->joint_names, expected);
  EXPECT_EQ(recorded_origin->tip_link, "tool_flange");
}

TEST(EnteredAs, ItsJointCountMustMatchTheTable) {
  Result<RobotModel> refused = ParseRobotModelText(
      "name: r\ndh_convention: modified_hayati\njoints:\n  - {a_mm: 0, alpha_deg: 0, d_mm: 0, min_deg: -90, "
      "max_deg: 90}\nflange_from_cam: {xyz_mm: [0, 0, 0], rpy_deg: [0, 0, 0]}\nentered_as: {joint_names: [a, b]}\n",
      "r.yaml");
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("names 2 joints, the table has 1"), std::string::npos)
      << refused.status().message();
}

TEST(TargetsFile, RoundTripIsExactAndProblemsNameTheLine) {
  TempDir dir;
  TargetsFile file;
  file.robot = "puma560";
  file.camera_frame = false;
  Eigen::VectorXd seed(6);
  seed << 0.1, -0.2, 0.3, -0.4, 0.5, -0.6;
  file.targets.push_back({Rigid3(RotZ(0.3) * RotX(-1.1), Eigen::Vector3d(0.6, -0.15, 0.3)), seed});
  file.targets.push_back({Rigid3(RotY(2.0), Eigen::Vector3d(0.5, 0.1, 0.2)), std::nullopt});
  ASSERT_TRUE(SaveTargetsFile(file, dir.File("t.yaml")).ok());
  Result<TargetsFile> reread = LoadTargetsFile(dir.File("t.yaml"), 6);
  ASSERT_TRUE(reread.ok()) << reread.status().message();
  EXPECT_EQ(reread->robot, "puma560");
  EXPECT_FALSE(reread->camera_frame);
  ASSERT_EQ(reread->targets.size(), 2u);
  EXPECT_EQ(reread->targets[0].base_from_target.rotation, file.targets[0].base_from_target.rotation);
  EXPECT_EQ(reread->targets[0].base_from_target.translation, file.targets[0].base_from_target.translation);
  EXPECT_EQ(*reread->targets[0].seed, seed);
  EXPECT_FALSE(reread->targets[1].seed.has_value());
  WriteFile(dir.File("bad.yaml"),
            "format: selfcal-targets\nversion: 1\nframe: tool\ntargets:\n  - {pose: {xyz_mm: [1, 2, 3], rpy_deg: [0, 0, 0]}, "
            "seed_deg: [1, 2]}\n");
  const Status bad = LoadTargetsFile(dir.File("bad.yaml"), 6).status();
  EXPECT_NE(bad.message().find("`frame` = `tool` at " + dir.File("bad.yaml") + ":3 must be camera or flange"),
            std::string::npos)
      << bad.message();
  EXPECT_NE(bad.message().find("seed_deg"), std::string::npos) << bad.message();
}

// The mutation campaign's `robot: ""` (test/data/mutation-findings/targets-03614-unexplained) was accepted.
TEST(TargetsFile, AnEmptyRobotNameIsRefusedByLine) {
  TempDir dir;
  WriteFile(dir.File("t.yaml"), "format: selfcal-targets\nversion: 1\nrobot: \"\"\nframe: flange\ntargets:\n"
                                "  - {pose: {xyz_mm: [700, 0, 40], rpy_deg: [0, 90, 0]}}\n");
  const Status bad = LoadTargetsFile(dir.File("t.yaml"), 6).status();
  EXPECT_EQ(bad.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(bad.message().find("`robot` at " + dir.File("t.yaml") + ":3 is empty"), std::string::npos) << bad.message();
}

}  // namespace
}  // namespace selfcal::io
