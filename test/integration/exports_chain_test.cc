// The calibrated model's exports end to end through the selfcal binary (docs/urdf.md,
// docs/calibrated-model-format.md, docs/ros-static-transform.md), each re-read by what consumes it:
// calibrated.urdf keeps a URDF robot's names (urdfdom) and equals the model (KDL); the flange-to-camera
// static transform (yaml-cpp); the DH table in the entered convention, or why not; a URDF robot's
// calibrated.urdf is the user's URDF with only joint origins changed; a UR5e's ur_description kinematics
// file is the calibrated model (docs/calibrated-model-format.md).
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <urdf_parser/urdf_parser.h>
#include <yaml-cpp/yaml.h>

#include "io/observations_file.h"
#include "io/robot_config.h"
#include "support/cli.h"
#include "support/temp_files.h"
#include "support/ur_description_chain.h"
#include "urdf/urdf_robot.h"
#include "urdf/urdf_writer.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;

const std::string kSource = SELFCAL_SOURCE_DIR;

// The worst FK difference (m or rad) of KDL's chain base -> tip of `urdf` against the model's flange or camera.
double WorstKdlDifference(const std::string& urdf, const std::string& base, const std::string& tip,
                          const RobotModel& model, bool camera,
                          std::vector<Eigen::VectorXd> joints = std::vector<Eigen::VectorXd>()) {
  if (joints.empty()) joints = urdf::RandomJointsWithinLimits(model, 300, 21);
  Result<std::vector<Rigid3>> kdl = urdf::KdlChainPoses(urdf, "calibrated.urdf", base, tip, joints);
  EXPECT_TRUE(kdl.ok()) << kdl.status().message();
  if (!kdl.ok()) return 1e9;
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  double worst = 0;
  for (size_t i = 0; i < joints.size(); ++i) {
    const Rigid3 ours = camera ? BaseFromCam(model, rho, joints[i]) : BaseFromFlange(model, rho, joints[i]);
    const PoseDifference d = ComparePoses(ours, (*kdl)[i]);
    worst = std::max({worst, d.position_m, d.rotation_rad});
  }
  return worst;
}

Rigid3 RigidOf(const ::urdf::Pose& p) {
  const Eigen::Quaterniond q(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  return Rigid3(q.toRotationMatrix(), Eigen::Vector3d(p.position.x, p.position.y, p.position.z));
}

// The lines of `text` with every <origin ...> tag removed, the lines left empty by that dropped.
std::vector<std::string> LinesWithoutOrigins(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(std::regex_replace(text, std::regex("<origin[^>]*>(</origin>)?"), ""));
  for (std::string line; std::getline(in, line);) {
    if (line.find_first_not_of(" \t") != std::string::npos) out.push_back(line);
  }
  return out;
}

std::vector<Eigen::VectorXd> Random1000(const RobotModel& model) { return urdf::RandomJointsWithinLimits(model, 1000, 31); }

// The movable joints, base to tip, by urdfdom: walked from the tip link up to the base.
std::vector<std::string> RevoluteJointsTo(const ::urdf::ModelInterface& parsed, const std::string& tip) {
  std::vector<std::string> revolute;
  for (::urdf::LinkConstSharedPtr link = parsed.getLink(tip); link && link->parent_joint;
       link = parsed.getLink(link->parent_joint->parent_link_name)) {
    if (link->parent_joint->type == ::urdf::Joint::REVOLUTE) revolute.insert(revolute.begin(), link->parent_joint->name);
  }
  return revolute;
}

TEST(ExportsChain, CalibratedUrdfKeepsTheInputsNamesAndEqualsTheModel) {
  const fs::path dir = testing::FreshDir("ExportsChain", "names");
  std::string output;
  ASSERT_EQ(testing::RunSelfcal("simulate --points --no-html --quiet --json --robot " + kSource +
                                    "/test/data/urdf/ur5e_named_robot.yaml --trajectory " + kSource +
                                    "/config/trajectories/initial_ur5e.yaml --out " + dir.string(),
                                &output),
            0)
      << output;
  const std::string text = testing::ReadFile((dir / "calibrated.urdf").string());
  const ::urdf::ModelInterfaceSharedPtr parsed = ::urdf::parseURDF(text);
  ASSERT_TRUE(parsed) << text;
  const std::vector<std::string> revolute = RevoluteJointsTo(*parsed, "tool_flange");
  const std::vector<std::string> expected = {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                             "wrist_1_joint",      "wrist_2_joint",       "wrist_3_joint"};
  EXPECT_EQ(revolute, expected);
  EXPECT_TRUE(parsed->getLink("base_link_inertia"));
  EXPECT_TRUE(parsed->getLink("camera_color_optical_frame"));
  Result<io::CalibratedModel> calibrated = io::LoadCalibratedModel((dir / "calibrated_model.yaml").string());
  ASSERT_TRUE(calibrated.ok()) << calibrated.status().message();
  const RobotModel& model = calibrated->model;
  EXPECT_LE(WorstKdlDifference(text, "base_link_inertia", "tool_flange", model, false), 1e-9);
  EXPECT_LE(WorstKdlDifference(text, "base_link_inertia", "camera_color_optical_frame", model, true), 1e-9);

  // The static transform, named from the URDF, read with yaml-cpp.
  const YAML::Node tf = YAML::LoadFile((dir / "camera_static_transform.yaml").string());
  EXPECT_EQ(tf["header"]["frame_id"].as<std::string>(), "tool_flange");
  EXPECT_EQ(tf["child_frame_id"].as<std::string>(), "camera_color_optical_frame");
  const YAML::Node t = tf["transform"]["translation"], r = tf["transform"]["rotation"];
  const Eigen::Quaterniond q(r["w"].as<double>(), r["x"].as<double>(), r["y"].as<double>(), r["z"].as<double>());
  const PoseDifference d = ComparePoses(
      model.flange_from_cam,
      Rigid3(q.toRotationMatrix(), Eigen::Vector3d(t["x"].as<double>(), t["y"].as<double>(), t["z"].as<double>())));
  EXPECT_LE(d.position_m, 1e-12);
  EXPECT_LE(d.rotation_rad, 1e-12);
  // A URDF robot's export is the URDF: no DH table is attempted.
  EXPECT_FALSE(fs::exists(dir / "calibrated_robot.yaml"));
  const nlohmann::json doc = nlohmann::json::parse(output);
  EXPECT_EQ(doc.at("files").at("camera_static_transform"), (dir / "camera_static_transform.yaml").string());
  if (!HasFailure()) fs::remove_all(dir);
}

// The 7-joint Panda entered as a URDF with franka_description's names (test/data/urdf/panda.urdf, written
// from Franka's published table): simulated with hidden errors, calibrated, exported. The export keeps
// the names and its KDL forward kinematics is the calibrated model's, over random joints and at the
// held-out verification poses themselves, so its held-out error is the internal model's.
TEST(ExportsChain, APandaUrdfIsCalibratedAndExportedWithItsNamesAndItsModel) {
  const fs::path dir = testing::FreshDir("ExportsChain", "panda");
  std::string output;
  ASSERT_EQ(testing::RunSelfcal("simulate --points --no-html --quiet --robot " + kSource +
                                    "/test/data/urdf/panda_robot.yaml --trajectory " + kSource +
                                    "/config/trajectories/initial_panda.yaml --out " + dir.string(),
                                &output),
            0)
      << output;
  const std::string text = testing::ReadFile((dir / "calibrated.urdf").string());
  const ::urdf::ModelInterfaceSharedPtr parsed = ::urdf::parseURDF(text);
  ASSERT_TRUE(parsed) << text;
  EXPECT_EQ(RevoluteJointsTo(*parsed, "panda_link8"), (std::vector<std::string>{"panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4",
                                                "panda_joint5", "panda_joint6", "panda_joint7"}));
  Result<io::CalibratedModel> calibrated = io::LoadCalibratedModel((dir / "calibrated_model.yaml").string());
  ASSERT_TRUE(calibrated.ok()) << calibrated.status().message();
  const RobotModel& model = calibrated->model;
  ASSERT_EQ(model.num_joints(), 7);
  EXPECT_LE(WorstKdlDifference(text, "panda_link0", "panda_link8", model, false), 1e-9);
  EXPECT_LE(WorstKdlDifference(text, "panda_link0", "camera_optical_frame", model, true), 1e-9);
  Result<ObservationSet> observations = io::LoadObservations((dir / "observations.yaml").string());
  ASSERT_TRUE(observations.ok()) << observations.status().message();
  std::vector<Eigen::VectorXd> heldout;
  for (int k : observations->PosesWithRole(PoseRole::kVerification)) heldout.push_back(observations->poses[k].joints_rad);
  ASSERT_GE(heldout.size(), 5u);
  EXPECT_LE(WorstKdlDifference(text, "panda_link0", "camera_optical_frame", model, true, heldout), 1e-9);
  if (!HasFailure()) fs::remove_all(dir);
}

// The shipped PUMA config is standard DH; its parallel joints 2 and 3 get a calibrated beta, which standard
// DH cannot hold: nothing is written for it, and the output says why and what it would cost.
TEST(ExportsChain, AStandardDhRobotWithACalibratedBetaGetsTheReasonInsteadOfATable) {
  const fs::path dir = testing::FreshDir("ExportsChain", "puma");
  std::string output;
  ASSERT_EQ(testing::RunSelfcalInSource("simulate --points --no-html --robot config/robots/puma560.yaml --out " +
                                            dir.string(),
                                        &output),
            0)
      << output;
  EXPECT_FALSE(fs::exists(dir / "calibrated_robot.yaml"));
  EXPECT_NE(output.find("calibrated robot (standard DH): not written, the calibrated model is not expressible in it"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("j3.beta = "), std::string::npos) << output;
  EXPECT_NE(output.find("(Hayati's parallel-axis parameter), which standard DH cannot hold"), std::string::npos);
  EXPECT_NE(output.find("dropping them would move the flange by up to"), std::string::npos) << output;
  // No names or speeds in the config: joint1 .. joint6 and the documented placeholder velocity.
  const ::urdf::ModelInterfaceSharedPtr parsed = ::urdf::parseURDF(testing::ReadFile((dir / "calibrated.urdf").string()));
  ASSERT_TRUE(parsed);
  ASSERT_TRUE(parsed->getJoint("joint3") && parsed->getJoint("joint3")->limits);
  EXPECT_EQ(parsed->getJoint("joint3")->limits->velocity, urdf::kDefaultJointVelocityRadPerS);
  // The default names, tool0 -> camera_optical_frame.
  const YAML::Node tf = YAML::LoadFile((dir / "camera_static_transform.yaml").string());
  EXPECT_EQ(tf["header"]["frame_id"].as<std::string>(), "tool0");
  EXPECT_EQ(tf["child_frame_id"].as<std::string>(), "camera_optical_frame");
  if (!HasFailure()) fs::remove_all(dir);
}

// The exports ROS 2 and MoveIt load: a URDF robot's calibrated.urdf is the user's URDF with only joint origins
// changed (read back by urdfdom, KDL's forward kinematics the calibrated model's, 1000 random joints).
TEST(ExportsChain, AUrdfRobotsCalibratedUrdfIsTheUsersUrdfWithOnlyJointOriginsChanged) {
  const fs::path dir = testing::FreshDir("ExportsChain", "meshes");
  std::string output;
  ASSERT_EQ(testing::RunSelfcal("simulate --points --no-html --quiet --robot " + kSource +
                                    "/test/data/urdf/ur5e_meshes_robot.yaml --trajectory " + kSource +
                                    "/config/trajectories/initial_ur5e.yaml --out " + dir.string(),
                                &output),
            0)
      << output;
  const std::string input = testing::ReadFile(kSource + "/test/data/urdf/ur5e_meshes.urdf");
  const std::string written = testing::ReadFile((dir / "calibrated.urdf").string());
  // The diff: nothing but <origin> tags.
  EXPECT_EQ(LinesWithoutOrigins(written), LinesWithoutOrigins(input));
  // Which origins: the movable joints' and the camera's, no link's (visual, collision, inertial) and no
  // other joint's; every limit, velocity and effort as the user wrote it.
  const ::urdf::ModelInterfaceSharedPtr a = ::urdf::parseURDF(input), b = ::urdf::parseURDF(written);
  ASSERT_TRUE(a && b) << written;
  const std::set<std::string> changed = {"shoulder_lift_joint", "elbow_joint",  "wrist_1_joint",
                                         "wrist_2_joint",       "wrist_3_joint", "camera_optical_joint"};
  for (const auto& [name, joint] : a->joints_) {
    const ::urdf::JointSharedPtr other = b->joints_.at(name);
    const PoseDifference d =
        ComparePoses(RigidOf(joint->parent_to_joint_origin_transform), RigidOf(other->parent_to_joint_origin_transform));
    if (changed.count(name)) {
      EXPECT_GT(d.position_m + d.rotation_rad, 1e-6) << name;
    } else if (name != "shoulder_pan_joint") {  // its origin (none given) holds the base correction, if any
      EXPECT_EQ(d.position_m + d.rotation_rad, 0) << name;
    }
    if (joint->limits) {
      ASSERT_TRUE(other->limits) << name;
      EXPECT_EQ(other->limits->velocity, joint->limits->velocity) << name;
      EXPECT_EQ(other->limits->effort, joint->limits->effort) << name;
      EXPECT_EQ(other->limits->lower, joint->limits->lower) << name;
    }
  }
  for (const auto& [name, link] : a->links_) {
    const ::urdf::LinkSharedPtr other = b->links_.at(name);
    ASSERT_EQ(link->visual_array.size(), other->visual_array.size()) << name;
    for (size_t k = 0; k < link->visual_array.size(); ++k) {
      EXPECT_EQ(ComparePoses(RigidOf(link->visual_array[k]->origin), RigidOf(other->visual_array[k]->origin)).position_m, 0);
    }
    ASSERT_EQ(link->collision_array.size(), other->collision_array.size()) << name;
  }
  Result<io::CalibratedModel> calibrated = io::LoadCalibratedModel((dir / "calibrated_model.yaml").string());
  ASSERT_TRUE(calibrated.ok()) << calibrated.status().message();
  EXPECT_LE(WorstKdlDifference(written, "base_link_inertia", "tool_flange", calibrated->model, false, Random1000(calibrated->model)), 1e-9);
  EXPECT_LE(WorstKdlDifference(written, "base_link_inertia", "camera_color_optical_frame", calibrated->model, true,
                               Random1000(calibrated->model)), 1e-9);
  if (!HasFailure()) fs::remove_all(dir);
}

// The same through a session: `run` records the converted model with the URDF's names and file
// (entered_as), so `calibrate SESSION` writes the user's URDF too, not selfcal's.
TEST(ExportsChain, ASessionOfAUrdfRobotIsCalibratedIntoTheUsersUrdf) {
  const fs::path dir = testing::FreshDir("ExportsChain", "meshes-session");
  std::string output;
  ASSERT_EQ(testing::RunSelfcal("simulate --no-html --quiet --robot " + kSource +
                                    "/test/data/urdf/ur5e_meshes_robot.yaml --trajectory " + kSource +
                                    "/config/trajectories/initial_ur5e.yaml --out " + (dir / "sim").string(),
                                &output),
            0)
      << output;
  ASSERT_EQ(testing::RunSelfcal("calibrate --no-html " + (dir / "sim" / "session").string() + " --out " +
                                    (dir / "cal").string(),
                                &output),
            0)
      << output;
  EXPECT_NE(output.find("ur5e_meshes.urdf with the calibrated joint origins"), std::string::npos) << output;
  const std::string input = testing::ReadFile(kSource + "/test/data/urdf/ur5e_meshes.urdf");
  const std::string written = testing::ReadFile((dir / "cal" / "calibrated.urdf").string());
  EXPECT_EQ(LinesWithoutOrigins(written), LinesWithoutOrigins(input));
  Result<io::CalibratedModel> calibrated = io::LoadCalibratedModel((dir / "cal" / "calibrated_model.yaml").string());
  ASSERT_TRUE(calibrated.ok()) << calibrated.status().message();
  EXPECT_LE(WorstKdlDifference(written, "base_link_inertia", "camera_color_optical_frame", calibrated->model, true,
                               Random1000(calibrated->model)),
            1e-9);
  if (!HasFailure()) fs::remove_all(dir);
}

// A UR5e's ur_description kinematics file, built into the chain the way ur_description's xacro builds it, is
// the calibrated model; a DH robot's calibrated.urdf has the non-zero velocity limits MoveIt needs.
TEST(ExportsChain, AUr5esKinematicsFileIsTheCalibratedModelAndItsUrdfHasVelocities) {
  const fs::path dir = testing::FreshDir("ExportsChain", "ur5e");
  std::string output;
  ASSERT_EQ(testing::RunSelfcalInSource("simulate --points --no-html --robot config/robots/ur5e.yaml --trajectory "
                                        "config/trajectories/initial_ur5e.yaml --out " + dir.string(),
                                        &output),
            0)
      << output;
  EXPECT_NE(output.find("ur_description kinematics (kinematics_params_file): "), std::string::npos) << output;
  Result<io::CalibratedModel> calibrated = io::LoadCalibratedModel((dir / "calibrated_model.yaml").string());
  ASSERT_TRUE(calibrated.ok()) << calibrated.status().message();
  const RobotModel& model = calibrated->model;
  const YAML::Node doc = YAML::LoadFile((dir / "ur_calibrated_kinematics.yaml").string());
  EXPECT_EQ(doc["kinematics"]["hash"].as<std::string>().rfind("calib_", 0), 0u);
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  std::mt19937_64 rng(12);
  double worst_m = 0, worst_rad = 0;
  for (int s = 0; s < 1000; ++s) {
    Eigen::VectorXd q(6);
    for (int j = 0; j < 6; ++j) {
      q[j] = std::uniform_real_distribution<double>(model.limits[j].min_rad, model.limits[j].max_rad)(rng);
    }
    const PoseDifference d = ComparePoses(testing::UrDescriptionChain(doc["kinematics"], q), BaseFromFlange(model, rho, q));
    worst_m = std::max(worst_m, d.position_m);
    worst_rad = std::max(worst_rad, d.rotation_rad);
  }
  EXPECT_LE(worst_m, 1e-9);
  EXPECT_LE(worst_rad, 1e-9);
  std::cout << "UR5e kinematics file against the calibrated model, 1000 random joints: worst " << worst_m << " m, "
            << worst_rad << " rad\n";
  // A DH robot's calibrated.urdf: the config's joint and link names (ur_description's) and its velocity
  // limits (180 deg/s), which MoveIt's time parameterization takes (not 0).
  const ::urdf::ModelInterfaceSharedPtr parsed = ::urdf::parseURDF(testing::ReadFile((dir / "calibrated.urdf").string()));
  ASSERT_TRUE(parsed);
  EXPECT_EQ(RevoluteJointsTo(*parsed, "tool0"),
            (std::vector<std::string>{"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
                                      "wrist_2_joint", "wrist_3_joint"}));
  for (const auto& [name, joint] : parsed->joints_) {
    if (joint->type != ::urdf::Joint::REVOLUTE) continue;
    ASSERT_TRUE(joint->limits) << name;
    EXPECT_DOUBLE_EQ(joint->limits->velocity, kPi) << name;
  }
  EXPECT_EQ(parsed->getJoint("elbow_joint")->child_link_name, "forearm_link");
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
}  // namespace selfcal
