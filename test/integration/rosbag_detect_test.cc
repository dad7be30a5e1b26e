// `selfcal detect --bag` on ROS 2 recordings written by an independent MCAP writer (npm's @mcap/core and
// @foxglove/cdr: test/tools/mcap_writer/write_bag.js, installed by scripts/install-deps): a simulated
// session rendered into a folder (selfcal_render_sequence --detect-folder) and the same session as a bag
// with /joint_states at 100 Hz, the arm moving between the poses and still at each, images at the still
// poses and half-way through every motion. The bag gives the same observations as the folder (every joint
// angle and every dot bit for bit) and `calibrate` the same model; raw and compressed images, zstd and
// uncompressed chunks, a URDF robot's joints picked by name from a message holding them in another order
// with a gripper's; then the refusals. Skipped, saying why, where node, the npm packages or zstd are absent.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/observations_file.h"
#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::FreshDir;
using testing::RunBinary;
using testing::RunSelfcalInSource;

const std::string kWriter = std::string(SELFCAL_SOURCE_DIR) + "/test/tools/mcap_writer";
const std::string kDetect = " --camera-fx-px 1000 --grid 8x8 --yardstick 0,63,148.49242404917499 --pixel-noise-px 0.015";

// Why the independent writer cannot run here, or empty.
std::string WriterMissing() {
  if (std::system("node --version > /dev/null 2>&1") != 0) return "node is not installed";
  if (!fs::exists(kWriter + "/node_modules/@mcap/core/package.json") ||
      !fs::exists(kWriter + "/node_modules/@foxglove/cdr/package.json")) {
    return "the npm packages @mcap/core and @foxglove/cdr are not installed in " + kWriter +
           " (scripts/install-deps or scripts/install-npm-tools)";
  }
  if (std::system("zstd --version > /dev/null 2>&1") != 0) return "the zstd program is not installed";
  return "";
}

class RosbagDetect : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    missing_ = WriterMissing();
    if (!missing_.empty()) return;
    dir_ = FreshDir("rosbag", "detect");
    std::string output;
    ASSERT_EQ(RunBinary(SELFCAL_RENDER_SEQUENCE, (dir_ / "folder").string() +
                            " --flat-sheet-grid 8x8 --spacing-mm 15 --noise 2 --blur 0.5 --supersampling 4 --detect-folder",
                        &output), 0) << output;
    // The folder's verification roles, which a bag cannot carry, taken out: both paths identify on every pose.
    std::ifstream in(dir_ / "folder" / "poses.yaml");
    std::ofstream out(dir_ / "poses_all_identification.yaml");
    std::string line;
    while (std::getline(in, line)) out << std::regex_replace(line, std::regex(", role: verification"), "") << "\n";
  }
  void SetUp() override {
    if (!missing_.empty()) GTEST_SKIP() << "skipped: " << missing_;
  }

  static std::string WriteBag(const std::string& name, const std::string& options) {
    const std::string bag = (dir_ / name).string();
    std::string output;
    EXPECT_EQ(RunBinary("node " + kWriter + "/write_bag.js", (dir_ / "folder").string() + " " + bag + options, &output), 0)
        << output;
    return bag;
  }

  static std::string missing_;
  static fs::path dir_;
};
std::string RosbagDetect::missing_;
fs::path RosbagDetect::dir_;

void ExpectSameObservations(const std::string& from_bag, const std::string& from_folder) {
  Result<ObservationSet> bag = io::LoadObservations(from_bag), folder = io::LoadObservations(from_folder);
  ASSERT_TRUE(bag.ok()) << bag.status().ToString();
  ASSERT_TRUE(folder.ok()) << folder.status().ToString();
  ASSERT_EQ(bag->poses.size(), folder->poses.size());
  for (size_t i = 0; i < bag->poses.size(); ++i) {
    EXPECT_EQ(bag->poses[i].joints_rad, folder->poses[i].joints_rad) << bag->poses[i].id;
    EXPECT_EQ(bag->poses[i].dots_px, folder->poses[i].dots_px) << bag->poses[i].id;
  }
}

// Every number of `a` within 1e-9 (relative) of `b`'s, every other value equal.
void ExpectSameJson(const nlohmann::json& a, const nlohmann::json& b, const std::string& where) {
  if (a.is_number() && b.is_number()) {
    EXPECT_NEAR(a.get<double>(), b.get<double>(), 1e-9 * (1 + std::abs(b.get<double>()))) << where;
  } else if (a.is_array() && b.is_array() && a.size() == b.size()) {
    for (size_t k = 0; k < a.size(); ++k) ExpectSameJson(a[k], b[k], where + "[" + std::to_string(k) + "]");
  } else if (a.is_object() && b.is_object()) {
    for (auto it = b.begin(); it != b.end(); ++it) {
      ASSERT_TRUE(a.contains(it.key())) << where << "." << it.key();
      ExpectSameJson(a.at(it.key()), it.value(), where + "." + it.key());
    }
  } else {
    EXPECT_EQ(a, b) << where;
  }
}

nlohmann::json Calibrate(const std::string& observations, const fs::path& out) {
  std::string output;
  EXPECT_EQ(RunSelfcalInSource("calibrate " + observations + " --out " + out.string(), &output), 0) << output;
  std::ifstream in(out / "report.json");
  return nlohmann::json::parse(in);
}

TEST_F(RosbagDetect, RawImagesInZstdChunksGiveTheFoldersObservationsAndCalibration) {
  const std::string bag = WriteBag("raw.mcap", "");
  const std::string from_folder = (dir_ / "folder.yaml").string(), from_bag = (dir_ / "bag.yaml").string();
  std::string output;
  ASSERT_EQ(RunSelfcalInSource("detect --images " + (dir_ / "folder").string() + " --poses " +
                                   (dir_ / "poses_all_identification.yaml").string() +
                                   " --robot config/robots/puma560.yaml" + kDetect + " --out " + from_folder, &output),
            0) << output;
  ASSERT_EQ(RunSelfcalInSource("detect --bag " + bag + " --image-topic /camera/image_raw --robot config/robots/puma560.yaml" +
                                   kDetect + " --out " + from_bag, &output),
            0) << output;
  EXPECT_NE(output.find("25 of 49 images on /camera/image_raw taken while the arm was still (24 while moving left out)"),
            std::string::npos) << output;
  EXPECT_NE(output.find("the robot config names no joints"), std::string::npos) << output;
  ExpectSameObservations(from_bag, from_folder);
  const nlohmann::json bag_report = Calibrate(from_bag, dir_ / "cal_bag");
  const nlohmann::json folder_report = Calibrate(from_folder, dir_ / "cal_folder");
  EXPECT_EQ(bag_report.at("verdict"), "accepted");
  ExpectSameJson(bag_report.at("methods").at("bundle").at("parameters"),
                 folder_report.at("methods").at("bundle").at("parameters"), "parameters");
}

TEST_F(RosbagDetect, CompressedImagesAndAUrdfRobotsJointsByName) {
  const std::string bag = WriteBag("named.mcap", " --compressed --compression none --joint-names "
                                                 "joint1,joint2,joint3,joint4,joint5,joint6 --extra-joint gripper_finger");
  const std::string from_folder = (dir_ / "folder_urdf.yaml").string(), from_bag = (dir_ / "named.yaml").string();
  std::string output;
  ASSERT_EQ(RunSelfcalInSource("detect --images " + (dir_ / "folder").string() + " --poses " +
                                   (dir_ / "poses_all_identification.yaml").string() +
                                   " --robot test/data/urdf/puma560_robot.yaml" + kDetect + " --out " + from_folder,
                               &output), 0) << output;
  ASSERT_EQ(RunSelfcalInSource("detect --bag " + bag + " --image-topic /camera/image_raw/compressed --robot "
                                   "test/data/urdf/puma560_robot.yaml" + kDetect + " --out " + from_bag, &output),
            0) << output;
  EXPECT_EQ(output.find("names no joints"), std::string::npos) << output;
  ExpectSameObservations(from_bag, from_folder);
}

TEST_F(RosbagDetect, RefusalsNameTheTopicTheJointOrTheByte) {
  const std::string bag = WriteBag("refusals.mcap", " --joint-names a,b,c,d,e,f");
  const std::string robot = " --robot test/data/urdf/puma560_robot.yaml" + kDetect;
  struct Case {
    std::string arguments, words;
  } cases[] = {
      {"--bag " + bag + " --image-topic /camera/depth" + robot, "no topic /camera/depth (--image-topic); the bag holds"},
      {"--bag " + bag + " --image-topic /joint_states" + robot, "holds sensor_msgs/msg/JointState, not sensor_msgs/msg/Image"},
      {"--bag " + bag + " --image-topic /camera/image_raw" + robot, "joint state without the robot's joint `joint1`"},
      {"--bag " + bag + " --image-topic /camera/image_raw" + kDetect, "--bag needs --robot and --image-topic"},
      {"--bag " + bag + " --images x --image-topic /camera/image_raw" + robot, "give --images"},
  };
  for (const Case& c : cases) {
    std::string output;
    EXPECT_EQ(RunSelfcalInSource("detect " + c.arguments + " --out " + (dir_ / "refused.yaml").string(), &output), 2)
        << c.arguments << "\n" << output;
    EXPECT_NE(output.find(c.words), std::string::npos) << c.arguments << "\n" << output;
    EXPECT_FALSE(fs::exists(dir_ / "refused.yaml"));
  }
  // A recording cut short: refused naming the file and the byte where it ends.
  const std::string cut = (dir_ / "cut.mcap").string();
  fs::copy_file(bag, cut);
  fs::resize_file(cut, fs::file_size(bag) / 2);
  std::string output;
  EXPECT_EQ(RunSelfcalInSource("detect --bag " + cut + " --image-topic /camera/image_raw --robot config/robots/puma560.yaml" +
                                   kDetect + " --out " + (dir_ / "refused.yaml").string(), &output), 2) << output;
  EXPECT_NE(output.find(cut + ": byte "), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir_ / "refused.yaml"));
}

}  // namespace
}  // namespace selfcal
