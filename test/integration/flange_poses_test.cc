// `selfcal calibrate` on an observations file of flange poses (no robot, no joints, no nominal hand-eye
// transform): the hand-eye result file against the simulator's hidden truth, the refusals, and
// --fix kinematics on a joint-angle file.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/hand_eye_file.h"
#include "io/observations_file.h"
#include "support/cli.h"
#include "support/sim_worlds.h"

namespace selfcal {
namespace {

using testing::FreshDir;
using testing::RunSelfcal;

struct FlangeFile {
  std::string path;
  Rigid3 flange_from_cam_true;
  double fx_true = 0;
};

// The standard world (0.2 px) recorded as flange poses of the true arm, written as a file.
FlangeFile WriteFlangeFile(const std::filesystem::path& dir) {
  const sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3);
  FlangeFile out;
  out.fx_true = world.truth.camera_true.fx_px;
  ObservationSet obs = world.observations;
  obs.robot = FlangePoseModel(Rigid3());
  obs.flange_from_cam_known = false;
  for (size_t i = 0; i < obs.poses.size(); ++i) {
    const Rigid3 flange = BaseFromFlange(world.truth.nominal, world.truth.rho_true, obs.poses[i].joints_rad);
    if (i == 0) out.flange_from_cam_true = flange.Inverse() * world.truth.base_from_cam[0];
    obs.poses[i].base_from_flange = flange;
    obs.poses[i].joints_rad.resize(0);
  }
  out.path = (dir / "flange_observations.yaml").string();
  EXPECT_TRUE(io::SaveObservations(obs, out.path).ok());
  return out;
}

TEST(FlangePosesCli, CalibrateWritesTheHandEyeResultWithinItsSigmas) {
  const auto dir = FreshDir("flange", "calibrate");
  const FlangeFile file = WriteFlangeFile(dir);
  std::string output;
  const int code = RunSelfcal("calibrate " + file.path + " --out " + (dir / "out").string(), &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "calibrated_model.yaml"));
  Result<io::HandEyeResult> result = io::LoadHandEye((dir / "out" / "hand_eye.yaml").string());
  ASSERT_TRUE(result.ok()) << result.status().ToString() << output;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(std::isfinite(result->stddev[k])) << k;
    EXPECT_NEAR(result->flange_from_cam.translation[k], file.flange_from_cam_true.translation[k], 4 * result->stddev[k]);
  }
  const Eigen::Vector3d w = LogSO3(result->flange_from_cam.rotation.transpose() * file.flange_from_cam_true.rotation);
  for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(w[k]), 4 * result->stddev[3 + k]) << k;
  EXPECT_NEAR(result->fx_px, file.fx_true, 4 * result->fx_stddev_px);
  std::ifstream in(dir / "out" / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report.at("verdict"), "accepted");
}

TEST(FlangePosesCli, TheKinematicsOnlyPaperMethodAndBadMasksAreRefused) {
  const auto dir = FreshDir("flange", "refusals");
  const FlangeFile file = WriteFlangeFile(dir);
  std::string output;
  EXPECT_EQ(RunSelfcal("calibrate " + file.path + " --method paper --out " + (dir / "paper").string(), &output), 2)
      << output;
  EXPECT_NE(output.find("flange poses"), std::string::npos) << output;
  EXPECT_EQ(RunSelfcal("calibrate " + file.path + " --fix j2 --out " + (dir / "mask").string(), &output), 2) << output;
  EXPECT_NE(output.find("unknown parameter `j2`"), std::string::npos) << output;
  // Checked before any work: no report, no output directory.
  EXPECT_FALSE(std::filesystem::exists(dir / "mask")) << output;
}

}  // namespace
}  // namespace selfcal
