// The real data sets copied into test/data (always present) and, when ../shared/data is there, that the
// copies hold the originals' pixels:
//  - ros-industrial-dotgrid-10x10: 15 images of a 10 x 10 modified circle grid, every dot named;
//  - visp-franka-eye-in-hand: 8 images of a 9 x 6 (inner corners) chessboard, every corner named, the
//    ordering fixed by the squares' colours in every image.
// Ids are checked against OpenCV's homography of the ideal grid (a dot or corner on the wrong cell is a
// whole spacing off it). The CLI tests (test/integration/detect_test.cc) check the ids across images.
#include <sys/stat.h>

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <visp3/io/vpImageIo.h>

#include "detection/detect_points.h"

namespace selfcal::detection {
namespace {

const std::string kTestData = std::string(SELFCAL_SOURCE_DIR) + "/test/data";
const std::string kShared = SELFCAL_SHARED_DATA_DIR;

bool Exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

std::string Bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

vpImage<unsigned char> Read(const std::string& path) {
  vpImage<unsigned char> image;
  vpImageIo::read(image, path);
  return image;
}

std::vector<std::string> RosImages() {
  std::vector<std::string> names;
  for (int i = 0; i < 15; ++i) names.push_back("images/" + std::to_string(i) + ".png");
  return names;
}

std::vector<std::string> FrankaImages() {
  std::vector<std::string> names;
  for (int i = 1; i <= 8; ++i) names.push_back("franka_image-" + std::to_string(i) + ".png");
  return names;
}

// The largest distance of a point from the least-squares homography of the ideal rows x cols grid.
double MaxHomographyResidual(const ImagePoints& p, int cols) {
  std::vector<cv::Point2f> ideal, image;
  for (const auto& [id, px] : p.points_px) {
    ideal.emplace_back(static_cast<float>(id % cols), static_cast<float>(id / cols));
    image.emplace_back(static_cast<float>(px.x()), static_cast<float>(px.y()));
  }
  const cv::Mat h = cv::findHomography(ideal, image, 0);
  std::vector<cv::Point2f> mapped;
  cv::perspectiveTransform(ideal, mapped, h);
  double worst = 0;
  for (size_t k = 0; k < image.size(); ++k) worst = std::max(worst, static_cast<double>(cv::norm(mapped[k] - image[k])));
  return worst;
}

// The PNGs were re-encoded (grey, zlib level 9): selfcal's reader must see exactly the originals' pixels.
// The pose files, camera file and READMEs' sources are byte-for-byte copies.
TEST(TestData, CopiesHoldTheOriginalsPixelsAndBytes) {
  const std::string ros = "/ros-industrial-dotgrid-10x10/", franka = "/visp-franka-eye-in-hand/";
  if (!Exists(kShared + ros) || !Exists(kShared + franka)) GTEST_SKIP() << "no " << kShared << ": originals not checked";
  for (const std::string& name : RosImages()) {
    EXPECT_TRUE(Read(kTestData + ros + name) == Read(kShared + ros + name)) << name;
  }
  for (const std::string& name : FrankaImages()) {
    EXPECT_TRUE(Read(kTestData + franka + name) == Read(kShared + franka + name)) << name;
  }
  for (int i = 0; i < 15; ++i) {
    const std::string pose = "poses/" + std::to_string(i) + ".yaml";
    EXPECT_EQ(Bytes(kTestData + ros + pose), Bytes(kShared + ros + pose)) << pose;
  }
  for (const char* file : {"cal_data.yaml", "rct_camera_intr_calibrated.yaml", "rct_pose_guesses.yaml"}) {
    EXPECT_EQ(Bytes(kTestData + ros + file), Bytes(kShared + ros + file)) << file;
  }
  for (int i = 1; i <= 8; ++i) {
    const std::string pose = "franka_pose_rPe_" + std::to_string(i) + ".yaml";
    EXPECT_EQ(Bytes(kTestData + franka + pose), Bytes(kShared + franka + pose)) << pose;
  }
  for (const char* file : {"franka_camera.xml", "chessboard-data.txt"}) {
    EXPECT_EQ(Bytes(kTestData + franka + file), Bytes(kShared + franka + file)) << file;
  }
}

// Every dot of all 15 images named; a lattice step off would be ~18 px, the lens (no distortion model in
// this data) moves corner dots by up to ~3 px off the homography (tracking/real_images_test.cc).
TEST(RealData, RosDotGridEveryDotOfEveryImage) {
  DetectionOptions o;
  o.rows = o.cols = 10;
  std::vector<vpImage<unsigned char>> images;
  for (const std::string& name : RosImages()) images.push_back(Read(kTestData + "/ros-industrial-dotgrid-10x10/" + name));
  std::vector<const vpImage<unsigned char>*> pointers;
  for (const auto& im : images) pointers.push_back(&im);
  const std::vector<ImagePoints> points = DetectAllImagePoints(pointers, o);
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_TRUE(points[i].ok) << "image " << i << ": " << points[i].message;
    EXPECT_EQ(points[i].points_px.size(), 100u) << "image " << i;
    EXPECT_LT(MaxHomographyResidual(points[i], 10), 4.0) << "image " << i;
  }
}

// Every corner of all 8 images, the ordering decided by colour in each (a 9 x 6 board's corner squares
// differ); corners lie within 2 px of the ideal board's homography (measured: up to 1.1 px, the lens's
// distortion, which the factory intrinsics do not model), a wrong cell is ~25 px off.
TEST(RealData, FrankaChessboardEveryCornerOfEveryImage) {
  DetectionOptions o;
  o.detector = Detector::kChessboard;
  o.rows = 6;
  o.cols = 9;
  std::vector<vpImage<unsigned char>> images;
  for (const std::string& name : FrankaImages()) images.push_back(Read(kTestData + "/visp-franka-eye-in-hand/" + name));
  std::vector<const vpImage<unsigned char>*> pointers;
  for (const auto& im : images) pointers.push_back(&im);
  const std::vector<ImagePoints> points = DetectAllImagePoints(pointers, o);
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_TRUE(points[i].ok) << "image " << i + 1 << ": " << points[i].message;
    EXPECT_EQ(points[i].points_px.size(), 54u) << "image " << i + 1;
    EXPECT_NE(points[i].message.find("ordered by colour"), std::string::npos) << points[i].message;
    EXPECT_LT(MaxHomographyResidual(points[i], 9), 2.0) << "image " << i + 1;
  }
}

// ViSP's 6 x 6 circle grid (../shared/data, 5 images, dark dots, no origin dot): every dot of every image
// on the grid (a wrong cell is ~20 px off), auto polarity choosing dark; the same images inverted (white
// dots on black) give the same centres with light polarity.
TEST(RealData, VispCircleGridInEitherPolarity) {
  const std::string dir = kShared + "/visp-franka-eye-in-hand/circles-grid/";
  if (!Exists(dir + "circles-01.jpg")) GTEST_SKIP() << dir << " is not there";
  DetectionOptions o;
  o.detector = Detector::kCircles;
  o.rows = o.cols = 6;
  o.polarity = Polarity::kAuto;
  for (int i = 1; i <= 5; ++i) {
    const vpImage<unsigned char> image = Read(dir + "circles-0" + std::to_string(i) + ".jpg");
    vpImage<unsigned char> inverted = image;
    for (unsigned k = 0; k < inverted.getSize(); ++k) inverted.bitmap[k] = static_cast<unsigned char>(255 - image.bitmap[k]);
    const ImagePoints p = DetectImagePoints(image, o, nullptr);
    ASSERT_TRUE(p.ok) << "image " << i << ": " << p.message;
    EXPECT_EQ(p.polarity, Polarity::kDark);
    EXPECT_EQ(p.points_px.size(), 36u);
    EXPECT_LT(MaxHomographyResidual(p, 6), 1.5) << "image " << i;
    DetectionOptions light = o;
    light.polarity = Polarity::kLight;
    const ImagePoints q = DetectImagePoints(inverted, light, nullptr);
    ASSERT_TRUE(q.ok) << "inverted image " << i << ": " << q.message;
    for (const auto& [id, px] : p.points_px) EXPECT_LT((q.points_px.at(id) - px).norm(), 1e-9) << "image " << i << " dot " << id;
  }
}

}  // namespace
}  // namespace selfcal::detection
