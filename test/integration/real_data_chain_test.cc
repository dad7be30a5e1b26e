// The whole chain on the public data shipped in test/data, as a user runs it: `selfcal detect`, then
// `selfcal calibrate` on the flange poses. The figure checked is the one that needs no reference
// estimator: the rotation angle of every relative camera motion from the images alone against the
// recorded flange motion (the angle does not depend on the hand-eye transform). On the ViSP Franka
// chessboard, PnP with the known board gives 0.165 deg median (the shared data's README: 0.18 deg with
// OpenCV's PnP, 0.58 deg max); selfcal, without the board's geometry and with one radial term, must not be worse.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli.h"

namespace selfcal {
namespace {

using testing::FreshDir;
using testing::RunSelfcalInSource;

constexpr double kDeg = 3.14159265358979323846 / 180.0;

TEST(RealDataChain, FrankaChessboardImageMotionsAgreeWithTheFlangeAtLeastAsWellAsPnp) {
  const auto dir = FreshDir("chain", "franka");
  const std::string obs = (dir / "franka.yaml").string();
  std::string output;
  ASSERT_EQ(RunSelfcalInSource("detect --images 'test/data/visp-franka-eye-in-hand/franka_image-*.png' --poses "
                               "'test/data/visp-franka-eye-in-hand/franka_pose_rPe_*.yaml' --detector chessboard "
                               "--grid 9x6 --camera-fx-px 607.59 --camera-cx-px 323.46 --camera-cy-px 243.26 --out " +
                                   obs,
                               &output),
            0)
      << output;
  const auto out = dir / "calibration";
  ASSERT_EQ(RunSelfcalInSource("calibrate " + obs + " --free camera,fx,k1 --out " + out.string(), &output), 0) << output;
  std::ifstream in(out / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  const nlohmann::json& motions = report.at("hand_eye").at("image_motions");
  ASSERT_TRUE(motions.at("ok").get<bool>()) << motions.dump();
  EXPECT_EQ(motions.at("pairs").size(), 28u);
  EXPECT_LE(motions.at("median_error_rad").get<double>(), 0.165 * kDeg) << motions.at("message");
  EXPECT_LE(motions.at("max_error_rad").get<double>(), 0.58 * kDeg) << motions.at("message");
  EXPECT_EQ(motions.at("pairs_over_2deg").get<int>(), 0);
  EXPECT_TRUE(std::filesystem::exists(out / "hand_eye.yaml"));
}

}  // namespace
}  // namespace selfcal
