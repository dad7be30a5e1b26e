// selfcal detect --detector charuco on the kvasios recordings (test/data/kvasios-franka-handeye: a 5 x 7
// DICT_6X6_250 ChArUco board, 34 mm squares, 28 mm markers, 3 sessions x 12 poses), read as stored (a
// folder per pose, the joint angles under `joint_pose`); and the refusal of an unknown dictionary.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "io/observations_file.h"
#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::FreshDir;
using testing::RunSelfcal;

const std::string kKvasios = std::string(SELFCAL_SOURCE_DIR) + "/test/data/kvasios-franka-handeye";

// The detect command on one session's folders, writing into dir.
std::string DetectArguments(const std::string& session, const fs::path& dir, const std::string& dictionary) {
  return "detect --images " + kKvasios + "/" + session + " --pose-joints-key joint_pose --robot " +
         std::string(SELFCAL_SOURCE_DIR) + "/config/robots/panda.yaml --detector charuco --dictionary " + dictionary +
         " --board 5x7 --camera-file " + kKvasios + "/realsense_factory.yaml --out " + (dir / "obs.yaml").string() +
         " --contact-sheet " + (dir / "sheet.png").string();
}

// The RMS residual (px) of the best pose of the board (OpenCV's 5 x 7 ChArUco layout: corner id =
// row * 4 + col, 34 mm apart) through the named corners, with the camera file's intrinsics and lens.
double BoardFitRmsPx(const PoseObservation& pose) {
  std::vector<cv::Point3f> board;
  std::vector<cv::Point2f> image;
  for (const auto& [id, px] : pose.dots_px) {
    board.emplace_back(0.034f * static_cast<float>(id % 4 + 1), 0.034f * static_cast<float>(id / 4 + 1), 0.f);
    image.emplace_back(static_cast<float>(px.x()), static_cast<float>(px.y()));
  }
  const cv::Matx33d k(633.8876342773438, 0, 641.9505615234375, 0, 633.3662109375, 358.99456787109375, 0, 0, 1);
  const cv::Vec<double, 5> dist(-0.06063492223620415, 0.07267043739557266, -0.000246976938797161, 0.0005311704007908702,
                                -0.02355414256453514);
  cv::Mat rvec, tvec;
  cv::solvePnP(board, image, k, dist, rvec, tvec);
  std::vector<cv::Point2f> projected;
  cv::projectPoints(board, rvec, tvec, k, dist, projected);
  double sum = 0;
  for (size_t i = 0; i < image.size(); ++i) sum += std::pow(cv::norm(projected[i] - image[i]), 2);
  return std::sqrt(sum / static_cast<double>(image.size()));
}

// 36 of 36 images, at least 20 of the 24 corners each (a marker the recorder's drawn axes cross is not
// found); the ids fit the board's geometry in every image (measured: at most 0.40 px RMS; a corner named
// one square off would be ~60 px from its place).
TEST(CharucoDetectCli, KvasiosEveryImageOfEverySession) {
  for (const std::string session : {"s1", "s2", "s3"}) {
    const fs::path dir = FreshDir("charuco_detect", session);
    std::string out;
    ASSERT_EQ(RunSelfcal(DetectArguments(session, dir, "DICT_6X6_250"), &out), 0) << out;
    EXPECT_NE(out.find("12 of 12 images with points"), std::string::npos) << out;
    Result<ObservationSet> set = io::LoadObservations((dir / "obs.yaml").string());
    ASSERT_TRUE(set.ok()) << set.status().ToString();
    ASSERT_EQ(set->poses.size(), 12u);
    double worst = 0;
    size_t corners = 0;
    for (const PoseObservation& pose : set->poses) {
      EXPECT_GE(pose.dots_px.size(), 20u) << session << " " << pose.id;
      for (const auto& [id, px] : pose.dots_px) EXPECT_TRUE(id >= 0 && id < 24) << id;
      const double rms = BoardFitRmsPx(pose);
      EXPECT_LT(rms, 1.0) << session << " " << pose.id;
      worst = std::max(worst, rms);
      corners += pose.dots_px.size();
    }
    std::printf("%s: 12 images, %zu corners, largest board fit RMS %.3f px\n", session.c_str(), corners, worst);
    EXPECT_TRUE(fs::exists(dir / "sheet.png"));
  }
}

TEST(CharucoDetectCli, AnUnknownDictionaryIsRefusedNamingTheValidOnesAndNothingIsWritten) {
  const fs::path dir = FreshDir("charuco_detect", "unknown_dictionary");
  std::string out;
  EXPECT_EQ(RunSelfcal(DetectArguments("s1", dir, "DICT_6X6_25"), &out), 2) << out;
  EXPECT_NE(out.find("unknown ChArUco dictionary `DICT_6X6_25`: one of DICT_4X4_50, "), std::string::npos) << out;
  EXPECT_NE(out.find("DICT_6X6_250"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "obs.yaml"));
  EXPECT_FALSE(fs::exists(dir / "sheet.png"));
}

TEST(CharucoDetectCli, TheBoardOptionsBelongToCharucoOnly) {
  const fs::path dir = FreshDir("charuco_detect", "options");
  std::string out;
  const std::string args = DetectArguments("s1", dir, "DICT_6X6_250");
  EXPECT_EQ(RunSelfcal(args + " --grid 4x6", &out), 2) << out;
  EXPECT_NE(out.find("--detector charuco takes --dictionary NAME and --board XxY"), std::string::npos) << out;
  std::string chessboard = args;
  chessboard.replace(chessboard.find("--detector charuco"), 18, "--detector chessboard --grid 4x6");
  EXPECT_EQ(RunSelfcal(chessboard, &out), 2) << out;
  EXPECT_NE(out.find("--dictionary and --board apply to charuco only"), std::string::npos) << out;
  std::string bad_board = args;
  bad_board.replace(bad_board.find("--board 5x7"), 11, "--board 5by7");
  EXPECT_EQ(RunSelfcal(bad_board, &out), 2) << out;
  EXPECT_NE(out.find("--board `5by7`: XxY expected"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "obs.yaml"));
}

}  // namespace
}  // namespace selfcal
