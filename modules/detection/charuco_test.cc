// ChArUco boards (detection/charuco.h): dictionaries by name, the kvasios recordings' board (a 5 x 7
// DICT_6X6_250 board, 34 mm squares, 28 mm markers, seen by a RealSense wrist camera; its recorder drew the
// board's axes into every image) named as the recorder's own OpenCV ChArUco pose names it, and a partly seen
// board keeping its ids. The corners' precision on rendered boards is in test/cross_module.
#include <fstream>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <visp3/io/vpImageIo.h>

#include "detection/charuco.h"
#include "detection/charuco_pattern.h"
#include "detection/detect_points.h"

namespace selfcal::detection {
namespace {

const std::string kKvasios = std::string(SELFCAL_SOURCE_DIR) + "/test/data/kvasios-franka-handeye";

CharucoOptions KvasiosBoard() {
  CharucoOptions o;
  o.dictionary = "DICT_6X6_250";
  o.cols = 5;
  o.rows = 7;
  return o;
}

vpImage<unsigned char> Read(const std::string& path) {
  vpImage<unsigned char> image;
  vpImageIo::read(image, path);
  return image;
}

TEST(CharucoOptions, AnUnknownDictionaryIsRefusedNamingTheValidOnes) {
  CharucoOptions o;
  o.dictionary = "DICT_6X6_25";
  const Status s = o.Validate();
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
  EXPECT_NE(s.message().find("unknown ChArUco dictionary `DICT_6X6_25`"), std::string::npos) << s.message();
  for (const std::string& name : CharucoDictionaryNames()) EXPECT_NE(s.message().find(name), std::string::npos) << name;
  EXPECT_EQ(CharucoDictionaryNames().size(), 21u);
  EXPECT_EQ(*CharucoDictionarySize("DICT_4X4_50"), 50);
  EXPECT_EQ(*CharucoDictionarySize("DICT_APRILTAG_36h11"), 587);
}

TEST(CharucoOptions, ABoardWithMoreMarkersThanTheDictionaryIsRefused) {
  CharucoOptions o;
  o.dictionary = "DICT_4X4_50";
  o.cols = 10;
  o.rows = 11;  // 55 markers
  const Status s = o.Validate();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("holds 55 markers, more than the 50 of DICT_4X4_50"), std::string::npos) << s.message();
  o.rows = 10;  // 50
  EXPECT_TRUE(o.Validate().ok());
  o.cols = 1;
  EXPECT_FALSE(o.Validate().ok());
}

TEST(CharucoOptions, TheDetectorIsChosenByName) {
  EXPECT_EQ(*ParseDetector("charuco"), Detector::kCharuco);
  EXPECT_STREQ(DetectorName(Detector::kCharuco), "charuco");
  DetectionOptions o;
  o.detector = Detector::kCharuco;
  o.rows = 7;
  o.cols = 5;
  o.charuco.dictionary = "DICT_6X6_250";
  EXPECT_TRUE(o.Validate().ok()) << o.Validate().message();
  o.identity = Identity::kOrder;
  EXPECT_FALSE(o.Validate().ok());
  o.identity = Identity::kGrid;
  o.charuco.dictionary = "no such";
  EXPECT_NE(o.Validate().message().find("unknown ChArUco dictionary"), std::string::npos);
}

// The recorder's own ChArUco pose of the board (OpenCV's estimatePoseCharucoBoard on its ids, in data.json)
// projects every corner selfcal names to within 2 px of where selfcal finds it (measured: at most 1.6 px;
// its pose is a fit through the recorder's corners): the ids are the markers' ids. A corner on the wrong
// square would be 60 px off. Every image gives at least 20 of the 24 corners (the markers a drawn axis
// crosses are not found, and their corners, when no other marker beside them is, neither).
TEST(CharucoRealData, KvasiosEveryImageNamedAsTheRecordersPose) {
  const CharucoPattern pattern(KvasiosBoard(), 0.034, 0.028);
  int images = 0, corners = 0;
  double worst = 0;
  for (const std::string session : {"s1", "s2", "s3"}) {
    for (int n = 0; n < 12; ++n) {
      char pose[16];
      std::snprintf(pose, sizeof(pose), "pose_%02d", n);
      const std::string dir = kKvasios + "/" + session + "/" + pose;
      std::ifstream in(dir + "/data.json");
      const nlohmann::json data = nlohmann::json::parse(in);
      cv::Mat k(3, 3, CV_64F), dist(1, 5, CV_64F), rvec(3, 1, CV_64F), tvec(3, 1, CV_64F);
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) k.at<double>(r, c) = data.at("camera_intrinsics")[r][c];
        rvec.at<double>(r) = data.at("T_cam_target_rvec")[r][0];
        tvec.at<double>(r) = data.at("T_cam_target_tvec")[r][0];
      }
      for (int c = 0; c < 5; ++c) dist.at<double>(c) = data.at("dist_coeffs")[c];
      const CharucoDetection d = DetectCharuco(Read(dir + "/image.png"), KvasiosBoard());
      ASSERT_TRUE(d.found) << session << "/" << pose << ": " << d.message;
      EXPECT_GE(d.corners_px.size(), 20u) << session << "/" << pose << ": " << d.message;
      std::vector<cv::Point3f> board;
      for (const auto& [id, px] : d.corners_px) {
        const Eigen::Vector3d& x = pattern.corners_m()[static_cast<size_t>(id)];
        board.emplace_back(static_cast<float>(x.x()), static_cast<float>(x.y()), 0.f);
      }
      std::vector<cv::Point2f> projected;
      cv::projectPoints(board, rvec, tvec, k, dist, projected);
      size_t i = 0;
      for (const auto& [id, px] : d.corners_px) {
        const double e = std::hypot(projected[i].x - px.x(), projected[i].y - px.y());
        worst = std::max(worst, e);
        EXPECT_LT(e, 2.0) << session << "/" << pose << " corner " << id;
        ++i;
      }
      ++images;
      corners += static_cast<int>(d.corners_px.size());
    }
  }
  EXPECT_EQ(images, 36);
  RecordProperty("corners", corners);
  std::printf("kvasios: %d images, %d corners, largest distance to the recorder's pose %.3f px\n", images, corners, worst);
}

// Half the board painted over (the paper's grey): the corners still seen keep their ids, at the same pixels.
TEST(CharucoRealData, APartlySeenBoardKeepsItsIds) {
  vpImage<unsigned char> image = Read(kKvasios + "/s1/pose_06/image.png");
  const CharucoDetection whole = DetectCharuco(image, KvasiosBoard());
  ASSERT_EQ(whole.corners_px.size(), 24u) << whole.message;
  // The left part of the board: left of the middle of its corners' span.
  double lo = 1e9, hi = -1e9;
  for (const auto& [id, px] : whole.corners_px) {
    lo = std::min(lo, px.x());
    hi = std::max(hi, px.x());
  }
  const unsigned cut = static_cast<unsigned>(0.5 * (lo + hi));
  for (unsigned v = 0; v < image.getHeight(); ++v) {
    for (unsigned u = 0; u < cut; ++u) image[v][u] = 200;
  }
  const CharucoDetection part = DetectCharuco(image, KvasiosBoard());
  ASSERT_TRUE(part.found) << part.message;
  EXPECT_GE(part.corners_px.size(), 6u) << part.message;
  EXPECT_LT(part.corners_px.size(), 20u) << part.message;
  for (const auto& [id, px] : part.corners_px) {
    ASSERT_TRUE(whole.corners_px.count(id)) << id;
    EXPECT_GT(px.x(), cut);
    EXPECT_LT((px - whole.corners_px.at(id)).norm(), 0.05) << "corner " << id;
  }
}

}  // namespace
}  // namespace selfcal::detection
