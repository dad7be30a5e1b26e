// The shipped robots end to end (docs/robots.md): every command that takes a robot takes the trajectory
// made for it by default, refuses one made for another robot as a usage error (exit 2) naming both
// robots, and make-trajectory starts from the config's home; the 7-joint Panda and the ABB IRB 140
// calibrate in the simulator.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/trajectory_file.h"
#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::RunSelfcal;

const std::vector<std::string> kRobots = {"puma560", "ur5e", "panda", "irb140"};

std::string Config(const std::string& robot) { return "config/robots/" + robot + ".yaml"; }
std::string Initial(const std::string& robot) { return "config/trajectories/initial_" + robot + ".yaml"; }
int Joints(const std::string& robot) { return robot == "panda" ? 7 : 6; }

nlohmann::json ReadJsonFile(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The refusal of a trajectory made for `own` given with the config of `other`: exit 2, both robots named.
void ExpectOtherRobotRefused(const std::string& command, const std::string& own, const std::string& other) {
  std::string output;
  EXPECT_EQ(RunSelfcal(command, &output), 2) << command << "\n" << output;
  EXPECT_NE(output.find("is for robot `" + own + "`"), std::string::npos) << command << "\n" << output;
  EXPECT_NE(output.find("is robot `" + other + "`"), std::string::npos) << command << "\n" << output;
}

// Every command that takes a robot and a trajectory refuses the PUMA's arc for the UR5e, and the UR5e's
// planned file for the 7-joint Panda (another joint count: still the robot named first).
TEST(Robots, ATrajectoryForAnotherRobotIsAUsageErrorNamingBoth) {
  const fs::path dir = testing::FreshDir("robots", "mismatch");
  const std::string ur5e = " --robot " + Config("ur5e");
  const std::string puma_arc = Initial("puma560");
  ExpectOtherRobotRefused("simulate --points" + ur5e + " --trajectory " + puma_arc + " --out " + (dir / "a").string(),
                          "puma560", "ur5e");
  ExpectOtherRobotRefused("simulate" + ur5e + " --trajectory " + puma_arc + " --out " + (dir / "b").string(), "puma560",
                          "ur5e");
  ExpectOtherRobotRefused("identifiability" + ur5e + " --trajectory " + puma_arc, "puma560", "ur5e");
  ExpectOtherRobotRefused("study --runs 1" + ur5e + " --trajectory initial=" + puma_arc + " --out " +
                              (dir / "s.json").string(),
                          "puma560", "ur5e");
  ExpectOtherRobotRefused("plan" + ur5e + " --start " + puma_arc + " --out " + (dir / "p.yaml").string(), "puma560",
                          "ur5e");
  ExpectOtherRobotRefused("plan" + ur5e + " --check config/trajectories/planned_d-optimal_puma560.yaml", "puma560",
                          "ur5e");
  ExpectOtherRobotRefused("run --dry-run --robot-config " + Config("ur5e") + " --plan " + puma_arc + " --session " +
                              (dir / "r").string(),
                          "puma560", "ur5e");
  ExpectOtherRobotRefused("plan --robot " + Config("panda") + " --check config/trajectories/planned_d-optimal_ur5e.yaml",
                          "ur5e", "panda");
  EXPECT_FALSE(fs::exists(dir / "b")) << "a refused simulate leaves no output folder";
  fs::remove_all(dir);
}

// Without a trajectory, each command takes the robot's own shipped one.
TEST(Robots, CommandsTakeTheRobotsOwnTrajectoryByDefault) {
  const fs::path dir = testing::FreshDir("robots", "defaults");
  std::string output;
  ASSERT_EQ(RunSelfcal("simulate --points --noise-px 0 --no-html --robot " + Config("ur5e") + " --out " +
                           (dir / "ur5e").string(),
                       &output),
            0)
      << output;
  EXPECT_NE(output.find("trajectory " + Initial("ur5e")), std::string::npos) << output;
  EXPECT_EQ(RunSelfcal("identifiability --robot " + Config("panda"), &output), 0) << output;
  EXPECT_NE(output.find("robot panda, 15 poses"), std::string::npos) << output;
  EXPECT_EQ(RunSelfcal("run --dry-run --robot-config " + Config("irb140") + " --session " + (dir / "r").string(), &output),
            0)
      << output;
  EXPECT_NE(output.find("dry run: nothing moved"), std::string::npos) << output;
  fs::remove_all(dir);
}

// make-trajectory without --home-deg starts from the config's home_deg: for every shipped robot it writes
// the shipped initial arc again (to 1e-9 rad), which passes the plan check for that robot; a config
// without a home and no --home-deg is a usage error, not a failed inverse kinematics.
TEST(Robots, MakeTrajectoryStartsFromTheConfigsHome) {
  const fs::path dir = testing::FreshDir("robots", "make");
  std::string output;
  for (const std::string& robot : kRobots) {
    const std::string out = (dir / (robot + ".yaml")).string();
    ASSERT_EQ(RunSelfcal("make-trajectory --robot " + Config(robot) + " --out " + out, &output), 0) << robot << output;
    Result<io::TrajectoryFile> made = io::LoadTrajectoryFile(out, Joints(robot));
    Result<io::TrajectoryFile> shipped = io::LoadTrajectoryFile(std::string(SELFCAL_SOURCE_DIR) + "/" + Initial(robot), Joints(robot));
    ASSERT_TRUE(made.ok() && shipped.ok()) << robot;
    ASSERT_EQ(made->poses.size(), shipped->poses.size()) << robot;
    for (size_t i = 0; i < made->poses.size(); ++i) {
      EXPECT_LT((made->poses[i] - shipped->poses[i]).cwiseAbs().maxCoeff(), 1e-9) << robot << " pose " << i;
    }
    EXPECT_EQ(RunSelfcal("plan --robot " + Config(robot) + " --check " + out, &output), 0) << robot << output;
  }
  std::string text;
  {
    std::ifstream in(std::string(SELFCAL_SOURCE_DIR) + "/" + Config("ur5e"));
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("home_deg:", 0) != 0) text += line + "\n";
    }
  }
  std::ofstream(dir / "no_home.yaml") << text;
  EXPECT_EQ(RunSelfcal("make-trajectory --robot " + (dir / "no_home.yaml").string() + " --out " +
                           (dir / "x.yaml").string(),
                       &output),
            2)
      << output;
  EXPECT_NE(output.find("has no home_deg and no --home-deg was given"), std::string::npos) << output;
  fs::remove_all(dir);
}

// The 7-joint Panda (Craig table) and the ABB IRB 140 calibrate in the simulator at 0.2 px on their
// shipped D-optimal plans: accepted, the bundle frees the parameters the rank analysis leaves (28 for 7
// joints: 4 per joint 2..7 less j7's theta and d, and the camera's 6; 24 for 6 joints), and the held-out
// 3-D error is below half the nominal model's (measured: panda 0.45 of 1.55 mm, irb140 0.45 of 1.59 mm;
// docs/robots.md).
TEST(Robots, NewRobotsCalibrateInTheSimulator) {
  const fs::path dir = testing::FreshDir("robots", "simulate");
  for (const std::string& robot : {std::string("panda"), std::string("irb140")}) {
    std::string output;
    ASSERT_EQ(RunSelfcal("simulate --points --no-html --robot " + Config(robot) +
                             " --trajectory config/trajectories/planned_d-optimal_" + robot + ".yaml --out " +
                             (dir / robot).string(),
                         &output),
              0)
        << robot << output;
    const nlohmann::json comparison = ReadJsonFile(dir / robot / "comparison_with_truth.json");
    const double nominal = comparison["bundle"]["error3d_rms_mm"]["nominal"].get<double>();
    const double bundle = comparison["bundle"]["error3d_rms_mm"]["bundle"].get<double>();
    EXPECT_LT(bundle, 0.5 * nominal) << robot << output;
    const nlohmann::json report = ReadJsonFile(dir / robot / "report.json");
    EXPECT_TRUE(report["accepted"].get<bool>()) << robot;
    EXPECT_EQ(report["methods"]["bundle"]["free"].size(), robot == "panda" ? 28u : 24u) << robot;
  }
  fs::remove_all(dir);
}


// `plan --robot R` from each robot's own arc and the simulator's scene of the default world seed plans at
// every seed tried (the IRB 140 was refused at all of these: a dot outside the arc's reference image, and,
// with its old home, an arc whose wrist rolled 184 deg, so that no candidate near pose 0 could replace the
// arc's last pose; world seeds 2 and 3 for the repair of pose 0 on the PUMA and the IRB 140).
TEST(Robots, EveryShippedRobotPlansFromItsArc) {
  const fs::path dir = testing::FreshDir("robots", "plan");
  struct Case {
    std::string robot;
    int seed;
    int world_seed;
  };
  std::vector<Case> cases;
  for (const std::string& robot : kRobots) {
    for (int seed : {1, 2, 3, 201, 202, 203, 204}) cases.push_back({robot, seed, 1});
    for (int world_seed : {2, 3}) cases.push_back({robot, 1, world_seed});
  }
  for (const Case& c : cases) {
    const std::string name = c.robot + "_" + std::to_string(c.seed) + "_" + std::to_string(c.world_seed) + ".yaml";
    const std::string out = (dir / name).string();
    std::string output;
    EXPECT_EQ(RunSelfcal("plan --robot " + Config(c.robot) + " --criterion d-optimal --seed " + std::to_string(c.seed) +
                             " --sim-world-seed " + std::to_string(c.world_seed) + " --out " + out,
                         &output),
              0)
        << c.robot << " seed " << c.seed << " world seed " << c.world_seed << "\n" << output;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace selfcal
