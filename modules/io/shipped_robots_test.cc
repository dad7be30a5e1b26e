// Every robot config shipped in config/robots/ against the table it cites (its `source:`): the published
// DH values, in the source's own convention and units, give the same flange pose as the loaded config at
// random joint angles inside the limits, and the limits are the published ones. The forward kinematics
// here is written out from the source's convention, not taken from RobotModel::FromDh, so a conversion
// slip in the reader fails here too. docs/robots.md lists the robots and their sources.
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/io_test_util.h"
#include "io/robot_config.h"
#include "support/test_robots.h"

namespace selfcal::io {
namespace {

using namespace testing;  // io::testing: SourcePath
using selfcal::testing::RigidNear;

// One row as the source prints it (SI: m, rad), and the joint limits the source gives (rad).
struct PublishedRow {
  double a, d, alpha, theta_offset, min_rad, max_rad;
};
enum class Published { kStandard, kCraig };  // Rz Tz Tx Rx per row, or Rx Tx Rz Tz (alpha_{i-1}, a_{i-1})
struct PublishedTable {
  Published convention;
  std::vector<PublishedRow> rows;
  double flange_d = 0;  // Craig tables: the fixed flange row's d (m)
};

constexpr double kDeg = kPi / 180;

// Corke, Robotics Toolbox for MATLAB, mdl_puma560.m: standard DH; qlim in degrees.
PublishedTable Puma560Table() {
  return {Published::kStandard,
          {{0, 0, kPi / 2, 0, -160 * kDeg, 160 * kDeg},
           {0.4318, 0, 0, 0, -45 * kDeg, 225 * kDeg},
           {0.0203, 0.15005, -kPi / 2, 0, -225 * kDeg, 45 * kDeg},
           {0, 0.4318, kPi / 2, 0, -110 * kDeg, 170 * kDeg},
           {0, 0, -kPi / 2, 0, -100 * kDeg, 100 * kDeg},
           {0, 0, 0, 0, -266 * kDeg, 266 * kDeg}}};
}

// Universal Robots, "DH parameters for calculations of kinematics and dynamics", UR5e; limits of
// Universal_Robots_ROS2_Description config/ur5e/joint_limits.yaml (+-360 deg, the elbow +-180 deg).
PublishedTable Ur5eTable() {
  return {Published::kStandard,
          {{0, 0.1625, kPi / 2, 0, -2 * kPi, 2 * kPi},
           {-0.425, 0, 0, 0, -2 * kPi, 2 * kPi},
           {-0.3922, 0, 0, 0, -kPi, kPi},
           {0, 0.1333, kPi / 2, 0, -2 * kPi, 2 * kPi},
           {0, 0.0997, -kPi / 2, 0, -2 * kPi, 2 * kPi},
           {0, 0.0996, 0, 0, -2 * kPi, 2 * kPi}}};
}

// Franka Robotics, FCI documentation, "Robot and interface specifications": Denavit-Hartenberg parameters
// (Craig's convention; a and alpha are a_{i-1}, alpha_{i-1}), the flange row d = 0.107 m, and "Limits for
// Panda" (rad, as printed).
PublishedTable PandaTable() {
  return {Published::kCraig,
          {{0, 0.333, 0, 0, -2.8973, 2.8973},
           {0, 0, -kPi / 2, 0, -1.7628, 1.7628},
           {0, 0.316, kPi / 2, 0, -2.8973, 2.8973},
           {0.0825, 0, kPi / 2, 0, -3.0718, -0.0698},
           {-0.0825, 0.384, -kPi / 2, 0, -2.8973, 2.8973},
           {0, 0, kPi / 2, 0, -0.0175, 3.7525},
           {0.088, 0, kPi / 2, 0, -2.8973, 2.8973}},
          0.107};
}

// Corke, Robotics Toolbox for Python, models/DH/IRB140.py: standard DH; qlim in degrees.
PublishedTable Irb140Table() {
  return {Published::kStandard,
          {{0.070, 0.352, -kPi / 2, 0, -180 * kDeg, 180 * kDeg},
           {0.360, 0, 0, 0, -100 * kDeg, 100 * kDeg},
           {0, 0, -kPi / 2, 0, -220 * kDeg, 60 * kDeg},
           {0, 0.380, kPi / 2, 0, -200 * kDeg, 200 * kDeg},
           {0, 0, -kPi / 2, 0, -120 * kDeg, 120 * kDeg},
           {0, 0.065, 0, 0, -400 * kDeg, 400 * kDeg}}};
}

// The published tables by config name: every shipped config must have one here.
const std::map<std::string, PublishedTable>& Tables() {
  static const std::map<std::string, PublishedTable> tables = {
      {"puma560", Puma560Table()}, {"ur5e", Ur5eTable()}, {"panda", PandaTable()}, {"irb140", Irb140Table()}};
  return tables;
}

Rigid3 Rz(double t) { return Rigid3::FromRotation(RotZ(t)); }
Rigid3 Rx(double t) { return Rigid3::FromRotation(RotX(t)); }
Rigid3 Tz(double d) { return Rigid3::FromTranslation(Eigen::Vector3d(0, 0, d)); }
Rigid3 Tx(double a) { return Rigid3::FromTranslation(Eigen::Vector3d(a, 0, 0)); }

// link0_from_flange of the published table, in its own convention.
Rigid3 PublishedFlange(const PublishedTable& table, const Eigen::VectorXd& q) {
  Rigid3 t = Rigid3::Identity();
  for (size_t i = 0; i < table.rows.size(); ++i) {
    const PublishedRow& r = table.rows[i];
    const double theta = q[static_cast<int>(i)] + r.theta_offset;
    t = table.convention == Published::kStandard ? t * Rz(theta) * Tz(r.d) * Tx(r.a) * Rx(r.alpha)
                                                 : t * Rx(r.alpha) * Tx(r.a) * Rz(theta) * Tz(r.d);
  }
  return t * Tz(table.flange_d);
}

void ExpectMatchesTable(const std::string& name, const PublishedTable& table) {
  const std::string path = SourcePath("config/robots/" + name + ".yaml");
  Result<CalibratedModel> config = LoadRobotConfig(path);
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  const RobotModel& model = config->model;
  EXPECT_EQ(model.name, name) << path;
  EXPECT_FALSE(config->source.empty()) << path << " cites no source";
  ASSERT_EQ(model.num_joints(), static_cast<int>(table.rows.size())) << path;
  for (int j = 0; j < model.num_joints(); ++j) {
    EXPECT_NEAR(model.limits[j].min_rad, table.rows[j].min_rad, 1e-12) << name << " joint " << j + 1;
    EXPECT_NEAR(model.limits[j].max_rad, table.rows[j].max_rad, 1e-12) << name << " joint " << j + 1;
  }
  EXPECT_TRUE(RigidNear(model.base_from_link0, Rigid3::Identity(), 1e-15, 1e-15)) << name << ": the tables start at link 0";
  std::mt19937_64 rng(7);
  const Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::VectorXd q(model.num_joints());
    for (int j = 0; j < q.size(); ++j) {
      q[j] = std::uniform_real_distribution<double>(table.rows[j].min_rad, table.rows[j].max_rad)(rng);
    }
    EXPECT_TRUE(RigidNear(PublishedFlange(table, q), BaseFromFlange(model, rho, q), 1e-12, 1e-12))
        << name << " at q = " << q.transpose();
  }
  // The config's home (make-trajectory's start) lies inside the published limits.
  ASSERT_EQ(config->home_rad.size(), table.rows.size()) << name << ": no home_deg";
  for (size_t j = 0; j < table.rows.size(); ++j) {
    EXPECT_GE(config->home_rad[j], table.rows[j].min_rad) << name << " home joint " << j + 1;
    EXPECT_LE(config->home_rad[j], table.rows[j].max_rad) << name << " home joint " << j + 1;
  }
}

TEST(ShippedRobots, Puma560IsCorkesMdlPuma560) { ExpectMatchesTable("puma560", Puma560Table()); }
TEST(ShippedRobots, Ur5eIsUniversalRobotsTable) { ExpectMatchesTable("ur5e", Ur5eTable()); }
TEST(ShippedRobots, PandaIsFrankasCraigTable) { ExpectMatchesTable("panda", PandaTable()); }
TEST(ShippedRobots, Irb140IsCorkesIrb140) { ExpectMatchesTable("irb140", Irb140Table()); }

// A config added to config/robots/ without its published table here fails: each shipped robot is checked.
TEST(ShippedRobots, EveryShippedConfigHasItsSourceTable) {
  int configs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(SourcePath("config/robots"))) {
    if (entry.path().extension() != ".yaml") continue;
    ++configs;
    EXPECT_EQ(Tables().count(entry.path().stem().string()), 1u) << entry.path() << " has no source-comparison table";
  }
  EXPECT_EQ(configs, static_cast<int>(Tables().size()));
}

// The 7-joint Panda is the one Craig-convention table: its flange row must reach the model (107 mm along
// the last z axis), or every camera pose would be off by it.
TEST(ShippedRobots, PandaFlangeRowIsTheLinkToFlangeTransform) {
  Result<CalibratedModel> config = LoadRobotConfig(SourcePath("config/robots/panda.yaml"));
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  EXPECT_TRUE(RigidNear(config->model.link_n_from_flange, Tz(0.107), 1e-15, 1e-15));
  EXPECT_EQ(config->model.num_parameters(), KinematicParameters(7).size());
}

// home_deg is checked like the joints: one value per joint, inside its limits, named by key and line.
TEST(ShippedRobots, HomeOutsideTheLimitsIsRefused) {
  TempDir dir;
  std::string text = ReadFile(SourcePath("config/robots/puma560.yaml"));
  const size_t at = text.find("home_deg: [0, 20, -200, 0, 45, 0]");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 34, "home_deg: [0, 20, -230, 0, 45, 0]");
  WriteFile(dir.File("puma.yaml"), text);
  Result<CalibratedModel> config = LoadRobotConfig(dir.File("puma.yaml"));
  ASSERT_FALSE(config.ok());
  EXPECT_NE(config.status().message().find("`home_deg[2]`"), std::string::npos) << config.status().ToString();
  EXPECT_NE(config.status().message().find("outside its limits"), std::string::npos) << config.status().ToString();
  text.replace(at, 34, "home_deg: [0, 20, -200, 0, 45]    ");
  WriteFile(dir.File("short.yaml"), text);
  EXPECT_FALSE(LoadRobotConfig(dir.File("short.yaml")).ok());
}

}  // namespace
}  // namespace selfcal::io
