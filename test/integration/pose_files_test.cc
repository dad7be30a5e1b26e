// Pose files as robots and recorders write them (docs/detect.md): the kvasios Franka recordings read as they
// are stored (one folder per pose, libfranka's TCP pose as 16 numbers in JSON, the Franka Hand's TCP made the
// flange through --flange-from-tool-mm-deg), rotations written to 9 decimals or orthonormal only to 2e-5
// taken as the nearest rotation with the correction said per pose, and bad input (a folder without its pose
// file, a pose of 15 numbers, a rotation 1e-2 off) refused with exit 2 naming the file, nothing written.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/observations_file.h"
#include "io/pose_files.h"
#include "io/robot_config.h"
#include "kinematics/robot_model.h"
#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::FreshDir;
using testing::RunSelfcalInSource;

const fs::path kKvasios = fs::path(SELFCAL_SOURCE_DIR) / "test/data/kvasios-franka-handeye";
const std::string kKvasiosCamera = (kKvasios / "realsense_factory.yaml").string();
// The Franka Hand's TCP in the flange frame: 103.4 mm along z, turned -45 deg about z.
const std::string kFrankaHand = " --flange-from-tool-mm-deg 0,0,103.4,0,0,-45";

std::string DetectKvasios(const std::string& folder, const std::string& out) {
  return "detect --images " + folder + " --pose-matrix-key O_T_EE" + kFrankaHand +
         " --detector chessboard --grid 4x6 --camera-file " + kKvasiosCamera + " --out " + out;
}

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Every session read as stored: 12 of 12 images each, and the flange poses made from O_T_EE and the hand's
// TCP equal the Panda's nominal forward kinematics of the recorded joint angles to 0.1 mm (and 0.01 deg):
// O_T_EE is row-major in these files, and the tool transform is the right way round.
TEST(PoseFilesCli, KvasiosIsReadAsStoredAndItsFlangePosesAreThePandasForwardKinematics) {
  const fs::path dir = FreshDir("pose_files", "kvasios");
  Result<RobotModel> panda = io::LoadRobotModel(std::string(SELFCAL_SOURCE_DIR) + "/config/robots/panda.yaml");
  ASSERT_TRUE(panda.ok()) << panda.status().ToString();
  const Eigen::VectorXd nominal = KinematicParameters::Nominal(*panda);
  int poses = 0;
  double worst_m = 0, worst_rad = 0;
  for (const std::string session : {"s1", "s2", "s3"}) {
    const std::string obs = (dir / (session + ".yaml")).string();
    std::string output;
    ASSERT_EQ(RunSelfcalInSource(DetectKvasios((kKvasios / session).string(), obs), &output), 0) << output;
    EXPECT_NE(output.find("12 of 12 images with points (24 to 24 points each), flange poses"), std::string::npos)
        << output;
    // libfranka's float output: every pose's rotation corrected, and said so.
    EXPECT_NE(output.find("data.json: pose pose_07: its rotation matrix was not orthonormal"), std::string::npos)
        << output;
    Result<ObservationSet> set = io::LoadObservations(obs);
    ASSERT_TRUE(set.ok()) << set.status().ToString();
    ASSERT_EQ(set->poses.size(), 12u);
    for (const PoseObservation& pose : set->poses) {
      ASSERT_TRUE(pose.base_from_flange.has_value()) << pose.id;
      const nlohmann::json data = ReadJson(kKvasios / session / pose.id / "data.json");
      const std::vector<double> q = data.at("joint_pose").get<std::vector<double>>();
      const Rigid3 fk = BaseFromFlange(*panda, nominal, Eigen::Map<const Eigen::VectorXd>(q.data(), 7));
      const double dt = (fk.translation - pose.base_from_flange->translation).norm();
      const double dr = LogSO3(Eigen::Matrix3d(fk.rotation.transpose() * pose.base_from_flange->rotation)).norm();
      EXPECT_LT(dt, 1e-4) << session << " " << pose.id;
      EXPECT_LT(dr, DegToRad(0.01)) << session << " " << pose.id;
      worst_m = std::max(worst_m, dt);
      worst_rad = std::max(worst_rad, dr);
      ++poses;
    }
  }
  EXPECT_EQ(poses, 36);
  std::printf("kvasios: %d flange poses, largest difference from the nominal forward kinematics %.3g mm, %.3g deg\n",
              poses, worst_m * 1e3, RadToDeg(worst_rad));
}

// The same folders with the joint angles as the pose: a joint-angle set on the Panda; calibrate --fix fx with
// the camera file keeps the file's f_x in calibrated_model.yaml to the bit.
TEST(PoseFilesCli, KvasiosJointsAreReadAsStoredAndAHeldFocalLengthIsTheFiles) {
  const fs::path dir = FreshDir("pose_files", "kvasios_joints");
  const std::string obs = (dir / "s1.yaml").string();
  std::string output;
  ASSERT_EQ(RunSelfcalInSource("detect --images " + (kKvasios / "s1").string() +
                                   " --pose-joints-key joint_pose --robot config/robots/panda.yaml --detector chessboard "
                                   "--grid 4x6 --camera-file " + kKvasiosCamera + " --yardstick 5,18,198.252 --out " + obs,
                               &output),
            0)
      << output;
  EXPECT_NE(output.find("12 of 12 images with points (24 to 24 points each), joint poses"), std::string::npos) << output;
  const fs::path out = dir / "cal";
  ASSERT_EQ(RunSelfcalInSource("calibrate " + obs + " --camera-file " + kKvasiosCamera + " --fix fx --no-html --out " +
                                   out.string(),
                               &output),
            0)
      << output;
  EXPECT_EQ(output.find("nan"), std::string::npos) << output;
  Result<io::CalibratedModel> model = io::LoadCalibratedModel((out / "calibrated_model.yaml").string());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  ASSERT_TRUE(model->camera.has_value());
  EXPECT_EQ(model->camera->fx_px, 633.8876342773438);  // realsense_factory.yaml's camera_matrix[0]
}

// The ViSP Franka set's flange poses as a selfcal poses list of rotation matrices: written to 9 decimals, and
// disturbed by 2e-5 (as libfranka's float output), each is accepted and its correction said per pose; 1e-2
// off is refused naming the file, the line and the pose, and nothing is written.
TEST(PoseFilesCli, RoundedRotationsAreMadeRotationsAndAWrongOneIsRefusedByLine) {
  const fs::path dir = FreshDir("pose_files", "rounded");
  const fs::path visp = fs::path(SELFCAL_SOURCE_DIR) / "test/data/visp-franka-eye-in-hand";
  auto write_list = [&](const std::string& name, double disturb) {
    std::string text = "format: selfcal-poses\nversion: 1\nposes:\n";
    for (int n = 1; n <= 8; ++n) {
      Result<Rigid3> pose = io::LoadPerImagePoseFile((visp / ("franka_pose_rPe_" + std::to_string(n) + ".yaml")).string());
      EXPECT_TRUE(pose.ok()) << pose.status().ToString();
      Eigen::Matrix3d r = pose->rotation;
      if (n == 3) r(0, 1) += disturb;
      char line[512];
      std::snprintf(line, sizeof(line),
                    "  - image: franka_image-%d.png\n    base_from_flange: {xyz_m: [%.9f, %.9f, %.9f], rotation: "
                    "[[%.9f, %.9f, %.9f], [%.9f, %.9f, %.9f], [%.9f, %.9f, %.9f]]}\n",
                    n, pose->translation.x(), pose->translation.y(), pose->translation.z(), r(0, 0), r(0, 1), r(0, 2),
                    r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
      text += line;
    }
    const fs::path path = dir / name;
    std::ofstream(path) << text;
    return path.string();
  };
  const std::string images = " --images '" + (visp / "franka_image-*.png").string() + "'";
  const std::string detect = "detect --detector chessboard --grid 9x6 --camera-fx-px 607.6" + images + " --poses ";
  std::string output;
  for (const auto& [name, disturb] : {std::pair<std::string, double>{"decimals9.yaml", 0.0}, {"float.yaml", 2e-5}}) {
    const std::string out = (dir / (name + ".obs.yaml")).string();
    ASSERT_EQ(RunSelfcalInSource(detect + write_list(name, disturb) + " --out " + out, &output), 0) << output;
    EXPECT_NE(output.find(name + ":8: pose franka_image-3: its rotation matrix was not orthonormal; taken as the "
                                 "nearest rotation (corrected by "),
              std::string::npos)
        << output;
    EXPECT_TRUE(fs::exists(out));
  }
  const std::string out = (dir / "refused.obs.yaml").string();
  EXPECT_EQ(RunSelfcalInSource(detect + write_list("wrong.yaml", 1e-2) + " --out " + out, &output), 2) << output;
  EXPECT_NE(output.find("`poses[2].base_from_flange.rotation` at " + (dir / "wrong.yaml").string() +
                        ":9 is not a rotation matrix (max |R^T R - I| = 0.0"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("a rotation is orthonormal to 1e-04"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out));
}

// One pose folder of a copied session without its data.json, and a pose of 15 numbers: exit 2, the message
// names the folder or the file and line, and neither the observations file nor the contact sheet is written.
TEST(PoseFilesCli, AFolderWithoutItsPoseFileAndAPoseOf15NumbersAreRefusedNamingThem) {
  const fs::path dir = FreshDir("pose_files", "bad");
  const fs::path session = dir / "s1";
  fs::copy(kKvasios / "s1", session, fs::copy_options::recursive);
  const std::string out = (dir / "obs.yaml").string(), sheet = (dir / "sheet.png").string();
  const std::string detect = DetectKvasios(session.string(), out) + " --contact-sheet " + sheet;
  fs::remove(session / "pose_04" / "data.json");
  std::string output;
  EXPECT_EQ(RunSelfcalInSource(detect, &output), 2) << output;
  EXPECT_NE(output.find((session / "pose_04").string() + ": holds image.png as its image and none as its pose file"),
            std::string::npos)
      << output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(sheet));

  fs::copy_file(kKvasios / "s1" / "pose_04" / "data.json", session / "pose_04" / "data.json");
  nlohmann::json data = ReadJson(session / "pose_06" / "data.json");
  data["O_T_EE"].erase(15);
  std::ofstream(session / "pose_06" / "data.json") << data.dump(4);
  EXPECT_EQ(RunSelfcalInSource(detect, &output), 2) << output;
  const std::string file = (session / "pose_06" / "data.json").string();
  EXPECT_NE(output.find(file + ":"), std::string::npos) << output;
  EXPECT_NE(output.find("`O_T_EE` has 15 numbers; a 4x4 pose is 16 numbers (or 4 rows of 4)"), std::string::npos)
      << output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(sheet));
  // A key that is not there is named with the nearest one.
  EXPECT_EQ(RunSelfcalInSource("detect --images " + session.string() + " --pose-matrix-key O_T_E --detector chessboard "
                               "--grid 4x6 --camera-fx-px 600 --out " + out,
                               &output),
            2)
      << output;
  EXPECT_NE(output.find("no key `O_T_E` (--pose-matrix-key); did you mean `O_T_EE`?"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace selfcal
