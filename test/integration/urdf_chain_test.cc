// A URDF robot end to end: simulate (points mode) with the test UR5e URDF as the nominal robot, then the
// calibrated.urdf that calibrate wrote re-read by urdfdom + KDL: its KDL forward kinematics equals
// the calibrated model of calibrated_model.yaml to 1e-9 m / 1e-9 rad at random joints within the limits.
#include <algorithm>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/robot_config.h"
#include "support/cli.h"
#include "support/temp_files.h"
#include "support/test_robots.h"
#include "urdf/urdf_robot.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;

TEST(UrdfChain, SimulatedUrdfRobotCalibratesAndItsCalibratedUrdfEqualsTheModel) {
  const fs::path dir = testing::FreshDir("UrdfChain", "ur5e");
  const std::string source = SELFCAL_SOURCE_DIR;
  std::string output;
  const int code = testing::RunSelfcal("simulate --points --no-html --quiet --json --robot " + source +
                                           "/test/data/urdf/ur5e_robot.yaml --trajectory " + source +
                                           "/config/trajectories/initial_ur5e.yaml --out " + dir.string(),
                                       &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_EQ(nlohmann::json::parse(output).at("files").at("calibrated_urdf"), (dir / "calibrated.urdf").string());
  Result<io::CalibratedModel> calibrated = io::LoadCalibratedModel((dir / "calibrated_model.yaml").string());
  ASSERT_TRUE(calibrated.ok()) << calibrated.status().message();
  const RobotModel& model = calibrated->model;
  const std::string text = testing::ReadFile((dir / "calibrated.urdf").string());
  const std::vector<Eigen::VectorXd> joints = urdf::RandomJointsWithinLimits(model, 500, 17);
  Result<std::vector<Rigid3>> tips = urdf::KdlChainPoses(text, "calibrated.urdf", "base_link", "tool0", joints);
  Result<std::vector<Rigid3>> cams =
      urdf::KdlChainPoses(text, "calibrated.urdf", "base_link", "camera_optical_frame", joints);
  ASSERT_TRUE(tips.ok()) << tips.status().message();
  ASSERT_TRUE(cams.ok()) << cams.status().message();
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  double worst_m = 0, worst_rad = 0;
  for (size_t i = 0; i < joints.size(); ++i) {
    for (const auto& [ours, kdl] : {std::pair{BaseFromFlange(model, rho, joints[i]), (*tips)[i]},
                                    std::pair{BaseFromCam(model, rho, joints[i]), (*cams)[i]}}) {
      const PoseDifference d = ComparePoses(ours, kdl);
      worst_m = std::max(worst_m, d.position_m);
      worst_rad = std::max(worst_rad, d.rotation_rad);
    }
  }
  EXPECT_LE(worst_m, 1e-9);
  EXPECT_LE(worst_rad, 1e-9);
  // The calibration moved the arm: the calibrated URDF is not the nominal one.
  Result<RobotModel> nominal = io::LoadRobotModel(source + "/test/data/urdf/ur5e_robot.yaml");
  ASSERT_TRUE(nominal.ok()) << nominal.status().message();
  const PoseDifference moved = ComparePoses(BaseFromCam(*nominal, KinematicParameters::Nominal(*nominal), joints[0]),
                                            BaseFromCam(model, rho, joints[0]));
  EXPECT_GT(moved.position_m, 1e-5);
  if (!HasFailure()) fs::remove_all(dir);
}

// A robot config naming a URDF followed by 100,000 nested elements: `plan --check` ended by SIGSEGV (exit
// 139) after 15-21 s in tinyxml's recursion; every command that reads a robot config was exposed. Now a
// refusal (exit 2) naming the URDF, the line and the limit, well under a second, nothing written.
TEST(UrdfChain, DeeplyNestedUrdfIsRefusedByLineByEveryCommandThatReadsARobot) {
  const fs::path dir = testing::FreshDir("UrdfChain", "deep");
  const std::string source = SELFCAL_SOURCE_DIR;
  std::string urdf = testing::ReadFile(source + "/test/data/urdf/ur5e.urdf");
  const size_t end = urdf.rfind("</robot>");
  ASSERT_NE(end, std::string::npos);
  const int line = 1 + static_cast<int>(std::count(urdf.begin(), urdf.begin() + static_cast<long>(end), '\n'));
  std::string deep;
  for (int i = 0; i < 100000; ++i) deep += "<link>";
  for (int i = 0; i < 100000; ++i) deep += "</link>";
  urdf.insert(end, deep);
  std::ofstream(dir / "ur5e.urdf") << urdf;
  fs::copy_file(source + "/test/data/urdf/ur5e_robot.yaml", dir / "robot.yaml");
  const std::string robot = (dir / "robot.yaml").string();
  const std::string expected = (dir / "ur5e.urdf").string() + ":" + std::to_string(line) +
                               ": elements nested deeper than 64 levels, the limit for a URDF";
  for (const std::string& command :
       {"plan --check " + source + "/config/trajectories/initial_ur5e.yaml --robot " + robot,
        "simulate --points --robot " + robot + " --out " + (dir / "sim").string()}) {
    std::string output;
    EXPECT_EQ(testing::RunSelfcal(command, &output), 2) << command << "\n" << output;
    EXPECT_NE(output.find(expected), std::string::npos) << command << "\n" << output;
  }
  EXPECT_FALSE(fs::exists(dir / "sim"));
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
}  // namespace selfcal
