// The user's URDF with the calibrated joint origins (urdf_calibrated.h): the forward kinematics of the
// written text by ROS's kdl_parser (not selfcal's kdl_chain.h) equal the calibrated model's, every byte
// outside the changed origins is the input's.
#include "urdf/urdf_calibrated.h"

#include <random>
#include <regex>

#include <gtest/gtest.h>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>

#include "support/perturbed_model.h"
#include "support/temp_files.h"
#include "support/test_robots.h"

namespace selfcal::urdf {
namespace {

const std::string kData = std::string(SELFCAL_SOURCE_DIR) + "/test/data/urdf/";

struct Case {
  std::string file;
  UrdfChainSpec spec;
};

// Every parameter of rho moved (betas, base and camera corrections included), as a calibration would leave it.
RobotModel CalibratedLike(const RobotModel& nominal, std::uint64_t seed) {
  return testing::PerturbedModel(nominal, 5e-3, 5e-3, /*with_beta=*/true, seed);
}

// base_from_tip by kdl_parser's tree of `text` (ROS's own URDF-to-KDL reader, not kdl_chain.h's) at each
// joint vector.
std::vector<Rigid3> KdlParserPoses(const std::string& text, const std::string& base, const std::string& tip,
                                   const std::vector<Eigen::VectorXd>& joints) {
  KDL::Tree tree;
  EXPECT_TRUE(kdl_parser::treeFromString(text, tree));
  KDL::Chain chain;
  EXPECT_TRUE(tree.getChain(base, tip, chain)) << base << " -> " << tip;
  KDL::ChainFkSolverPos_recursive solver(chain);
  std::vector<Rigid3> poses;
  for (const Eigen::VectorXd& q : joints) {
    EXPECT_EQ(chain.getNrOfJoints(), static_cast<unsigned>(q.size()));
    KDL::JntArray values(chain.getNrOfJoints());
    for (unsigned j = 0; j < values.rows() && j < q.size(); ++j) values(j) = q[j];
    KDL::Frame f;
    solver.JntToCart(values, f);
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r(i, j) = f.M(i, j);
    }
    poses.emplace_back(r, Eigen::Vector3d(f.p.x(), f.p.y(), f.p.z()));
  }
  return poses;
}

// The worst position (m) or rotation (rad) difference of the text's flange and camera against the model's.
double WorstDifference(const std::string& text, const UrdfChainSpec& spec, const RobotModel& model) {
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  const std::vector<Eigen::VectorXd> joints = RandomJointsWithinLimits(model, 1000, 5);
  const std::vector<Rigid3> tips = KdlParserPoses(text, spec.base_link, spec.tip_link, joints);
  const std::vector<Rigid3> cams = KdlParserPoses(text, spec.base_link, spec.camera_link, joints);
  double worst = 0;
  for (size_t i = 0; i < joints.size(); ++i) {
    const PoseDifference t = ComparePoses(BaseFromFlange(model, rho, joints[i]), tips[i]);
    const PoseDifference c = ComparePoses(BaseFromCam(model, rho, joints[i]), cams[i]);
    worst = std::max({worst, t.position_m, t.rotation_rad, c.position_m, c.rotation_rad});
  }
  return worst;
}

// The text with every <origin ...> tag (and </origin>) removed and the lines left empty by that dropped.
std::string WithoutOrigins(const std::string& text) {
  const std::string stripped = std::regex_replace(text, std::regex("<origin[^>]*>(</origin>)?"), "");
  std::string out, line;
  std::istringstream in(stripped);
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t") != std::string::npos) out += line + "\n";
  }
  return out;
}

TEST(CalibratedUserUrdf, KeepsTheUsersUrdfAndEqualsTheCalibratedModel) {
  const std::vector<Case> cases = {
      {"ur5e_meshes.urdf", {"base_link_inertia", "tool_flange", "camera_color_optical_frame"}},
      {"puma560.urdf", {"base_link", "tool0", "camera_optical_frame"}},  // axes off z, fixed joints mid-chain
      {"panda.urdf", {"panda_link0", "panda_link8", "camera_optical_frame"}}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string input = testing::ReadFile(kData + c.file);
    Result<UrdfRobot> nominal = ParseUrdfRobot(input, c.file, c.spec, std::nullopt);
    ASSERT_TRUE(nominal.ok()) << nominal.status().message();
    const RobotModel calibrated = CalibratedLike(nominal->model, 4);
    Result<std::string> written = CalibratedUserUrdf(input, c.file, c.spec, calibrated);
    ASSERT_TRUE(written.ok()) << written.status().message();
    EXPECT_LE(WorstDifference(*written, c.spec, calibrated), 1e-9);
    EXPECT_GT(WorstDifference(input, c.spec, calibrated), 1e-4);  // the input is the nominal arm
    EXPECT_EQ(WithoutOrigins(*written), WithoutOrigins(input));
  }
}

TEST(CalibratedUserUrdf, ChangesOnlyTheNamedJointsOrigins) {
  const std::string input =
      "<robot name=\"r\">\n"
      "  <!-- <joint name=\"a\" type=\"revolute\"><origin xyz=\"9 9 9\"/></joint> -->\n"
      "  <transmission name=\"t\"><joint name=\"a\"><hardwareInterface>x</hardwareInterface></joint></transmission>\n"
      "  <joint name=\"a\" type=\"revolute\">\n"
      "    <parent link=\"p\"/><child link=\"c\"/>\n"
      "  </joint>\n"
      "  <joint name='b' type='fixed'><origin xyz='1 2 3'></origin><parent link='c'/><child link='d'/></joint>\n"
      "  <joint name=\"e\" type=\"fixed\"><origin xyz=\"4 5 6\"/><parent link=\"d\"/><child link=\"f\"/></joint>\n"
      "</robot>\n";
  const Rigid3 shift = Rigid3::FromTranslation(Eigen::Vector3d(0.5, 0, 0));
  Result<std::string> out = ReplaceJointOrigins(input, "test", {{"a", shift}, {"b", Rigid3::FromRotation(RotZ(kPi / 2))}});
  ASSERT_TRUE(out.ok()) << out.status().message();
  const std::string expected =
      "<robot name=\"r\">\n"
      "  <!-- <joint name=\"a\" type=\"revolute\"><origin xyz=\"9 9 9\"/></joint> -->\n"
      "  <transmission name=\"t\"><joint name=\"a\"><hardwareInterface>x</hardwareInterface></joint></transmission>\n"
      "  <joint name=\"a\" type=\"revolute\">\n"
      "    <origin xyz=\"0.5 0 0\" rpy=\"0 0 0\"/>\n"
      "    <parent link=\"p\"/><child link=\"c\"/>\n"
      "  </joint>\n"
      "  <joint name='b' type='fixed'><origin xyz=\"0 0 0\" rpy=\"0 0 1.5707963267948966\"></origin><parent "
      "link='c'/><child link='d'/></joint>\n"
      "  <joint name=\"e\" type=\"fixed\"><origin xyz=\"4 5 6\"/><parent link=\"d\"/><child link=\"f\"/></joint>\n"
      "</robot>\n";
  EXPECT_EQ(*out, expected);
  Result<std::string> missing = ReplaceJointOrigins(input, "test", {{"z", shift}});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("no <joint> named `z`"), std::string::npos);
}

TEST(CalibratedUserUrdf, AUrdfOfAnotherArmIsRefused) {
  const std::string input = testing::ReadFile(kData + "panda.urdf");
  const RobotModel ur = CalibratedLike(testing::Ur5e(), 1);
  Result<std::string> out = CalibratedUserUrdf(input, "panda.urdf", {"panda_link0", "panda_link8", ""}, ur);
  ASSERT_FALSE(out.ok());
  EXPECT_NE(out.status().message().find("7 joints, the calibrated model 6"), std::string::npos)
      << out.status().message();
}

}  // namespace
}  // namespace selfcal::urdf
