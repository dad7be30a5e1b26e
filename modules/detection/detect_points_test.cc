#include "detection/detect_points.h"

#include <gtest/gtest.h>

#include "detection/detection_test_util.h"
#include "support/test_robots.h"

namespace selfcal::detection {
namespace {

using testing::RenderChessboard;
using testing::RenderDotGrid;
using testing::TruePoints;
using testing::View;

constexpr int kRows = 7, kCols = 9;
// The centroid of a projected disc lies off the projected centre by a fraction of a pixel (perspective);
// a dot on the wrong id is one spacing (~30 px) off.
constexpr double kDotTolPx = 0.3;

DetectionOptions GridOptions() {
  DetectionOptions o;
  o.detector = Detector::kDots;
  o.identity = Identity::kGrid;
  o.rows = kRows;
  o.cols = kCols;
  return o;
}

TEST(DetectionOptions, ValidateNamesTheProblems) {
  DetectionOptions o = GridOptions();
  EXPECT_TRUE(o.Validate().ok());
  o.detector = Detector::kChessboard;
  o.identity = Identity::kAprilTag;
  Status s = o.Validate();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("dots only"), std::string::npos) << s.message();
  o = GridOptions();
  o.identity = Identity::kAprilTag;
  s = o.Validate();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("tag side"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("layout"), std::string::npos) << s.message();
  EXPECT_FALSE(ParseDetector("blobs").ok());
  EXPECT_FALSE(ParseIdentity("random").ok());
  EXPECT_EQ(*ParseIdentity("order"), Identity::kOrder);
}

// The grid identity names every dot of a rendered modified circle grid with its true id, whatever the
// target's roll in the image.
TEST(DetectImagePoints, GridIdsAreTheTrueIdsAtEveryRoll) {
  for (int roll : {0, 75, 160, 250, 330}) {
    const Eigen::Matrix3d view = View(kRows, kCols, roll, 30.0, 2.0);
    const ImagePoints p = DetectImagePoints(RenderDotGrid(view, kRows, kCols, 1.5, roll + 1), GridOptions(), nullptr);
    ASSERT_TRUE(p.ok) << "roll " << roll << ": " << p.message;
    ASSERT_EQ(p.points_px.size(), static_cast<size_t>(kRows * kCols));
    const std::vector<Eigen::Vector2d> truth = TruePoints(view, kRows, kCols);
    for (const auto& [id, px] : p.points_px) {
      EXPECT_LT((px - truth[static_cast<size_t>(id)]).norm(), kDotTolPx) << "roll " << roll << " id " << id;
    }
  }
}

TEST(DetectImagePoints, GridFailureSaysWhy) {
  DetectionOptions o = GridOptions();
  o.rows = 8;  // the target has 7 rows
  const ImagePoints p = DetectImagePoints(RenderDotGrid(View(kRows, kCols, 20, 30.0), kRows, kCols), o, nullptr);
  EXPECT_FALSE(p.ok);
  EXPECT_NE(p.message.find("grid not identified"), std::string::npos) << p.message;
  EXPECT_NE(p.message.find("too_few_dots): 63 detections, need 72"), std::string::npos) << p.message;
}

// Raster order: every dot named once, ids 0..N-1, and each on a true dot centre.
TEST(DetectImagePoints, OrderNamesEveryDotOnce) {
  DetectionOptions o = GridOptions();
  o.identity = Identity::kOrder;
  const Eigen::Matrix3d view = View(kRows, kCols, 10, 30.0);
  const ImagePoints p = DetectImagePoints(RenderDotGrid(view, kRows, kCols), o, nullptr);
  ASSERT_TRUE(p.ok) << p.message;
  // The origin dot, larger than the others by design, is left out as unlike the target's dots
  // (blob_candidates.h's texture filter); every other dot is named once.
  ASSERT_EQ(p.points_px.size(), static_cast<size_t>(kRows * kCols - 1));
  EXPECT_NE(p.message.find("(1 blobs unlike the others left out)"), std::string::npos) << p.message;
  EXPECT_EQ(p.points_px.begin()->first, 0);
  EXPECT_EQ(p.points_px.rbegin()->first, kRows * kCols - 2);
  const std::vector<Eigen::Vector2d> truth = TruePoints(view, kRows, kCols);
  for (const auto& [id, px] : p.points_px) {
    double nearest = 1e9;
    for (const Eigen::Vector2d& t : truth) nearest = std::min(nearest, (px - t).norm());
    EXPECT_LT(nearest, kDotTolPx) << "id " << id;
  }
}

// A chessboard sequence through DetectAllImagePoints: ids are the true corner ids in every image, and an
// image without the board in the middle neither fails the others nor breaks the continuity.
TEST(DetectAllImagePoints, ChessboardSequenceKeepsIds) {
  constexpr int kBoardRows = 6, kBoardCols = 8;  // rows + cols even: continuity decides
  DetectionOptions o;
  o.detector = Detector::kChessboard;
  o.rows = kBoardRows;
  o.cols = kBoardCols;
  std::vector<vpImage<unsigned char>> images;
  std::vector<Eigen::Matrix3d> views;
  for (int roll = 10; roll <= 190; roll += 30) {
    views.push_back(View(kBoardRows, kBoardCols, roll, 28.0));
    images.push_back(RenderChessboard(views.back(), kBoardRows, kBoardCols, 1.0, roll));
    if (roll == 100) {
      views.push_back(Eigen::Matrix3d::Zero());
      images.emplace_back(480, 640, 180);  // blank
    }
  }
  std::vector<const vpImage<unsigned char>*> pointers;
  for (const auto& im : images) pointers.push_back(&im);
  const std::vector<ImagePoints> points = DetectAllImagePoints(pointers, o);
  ASSERT_EQ(points.size(), images.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (views[i].isZero()) {
      EXPECT_FALSE(points[i].ok);
      continue;
    }
    ASSERT_TRUE(points[i].ok) << "image " << i << ": " << points[i].message;
    const std::vector<Eigen::Vector2d> truth = TruePoints(views[i], kBoardRows, kBoardCols);
    for (const auto& [id, px] : points[i].points_px) {
      EXPECT_LT((px - truth[static_cast<size_t>(id)]).norm(), 0.3) << "image " << i << " id " << id;  // chessboard_test.cc
    }
  }
}

ImagePoints Found(std::map<int, Eigen::Vector2d> px) {
  ImagePoints p;
  p.ok = true;
  p.points_px = std::move(px);
  return p;
}

ObservationSetup JointSetup() {
  ObservationSetup s;
  s.robot = selfcal::testing::Puma560();
  s.camera.width_px = 640;
  s.camera.height_px = 480;
  s.camera.fx_px = 800;
  s.pixel_noise_px = 0.3;
  return s;
}

TEST(BuildObservationSet, OneIdentificationPosePerImage) {
  const std::vector<ImagePoints> points = {Found({{0, {10, 20}}, {1, {30, 40}}}), Found({{0, {11, 21}}, {1, {31, 41}}})};
  const std::vector<ImageRobotPose> poses = {{std::nullopt, Eigen::VectorXd::Zero(6)},
                                             {std::nullopt, Eigen::VectorXd::Constant(6, 0.1)}};
  ObservationSetup setup = JointSetup();
  setup.yardsticks.push_back({0, 1, 0.25});
  const Result<ObservationSet> set = BuildObservationSet({"img_0", "img_1"}, points, poses, setup);
  ASSERT_TRUE(set.ok()) << set.status().message();
  ASSERT_EQ(set->poses.size(), 2u);
  EXPECT_EQ(set->poses[1].id, "img_1");
  EXPECT_EQ(set->poses[1].role, PoseRole::kIdentification);
  EXPECT_DOUBLE_EQ(set->poses[1].joints_rad[3], 0.1);
  EXPECT_EQ(set->poses[1].dots_px.at(1), Eigen::Vector2d(31, 41));
  EXPECT_DOUBLE_EQ(set->pixel_noise_px, 0.3);
  ASSERT_EQ(set->yardsticks.size(), 1u);
}

TEST(BuildObservationSet, AFailedImageIsRefusedUnlessSkipped) {
  ImagePoints failed;
  failed.message = "no 6 x 9 chessboard (inner corners) found";
  const std::vector<ImagePoints> points = {Found({{0, {10, 20}}}), failed};
  const std::vector<ImageRobotPose> poses = {{std::nullopt, Eigen::VectorXd::Zero(6)},
                                             {std::nullopt, Eigen::VectorXd::Zero(6)}};
  ObservationSetup setup = JointSetup();
  const Result<ObservationSet> refused = BuildObservationSet({"a", "b"}, points, poses, setup);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), ErrorCode::kDegenerateData);
  EXPECT_NE(refused.status().message().find("b: no 6 x 9 chessboard"), std::string::npos) << refused.status().message();
  setup.skip_failed = true;
  const Result<ObservationSet> kept = BuildObservationSet({"a", "b"}, points, poses, setup);
  ASSERT_TRUE(kept.ok()) << kept.status().message();
  ASSERT_EQ(kept->poses.size(), 1u);
  EXPECT_EQ(kept->poses[0].id, "a");
  // Wrong joint count: the set's own validation, naming the pose.
  const std::vector<ImageRobotPose> short_joints = {{std::nullopt, Eigen::VectorXd::Zero(5)},
                                                    {std::nullopt, Eigen::VectorXd::Zero(6)}};
  const Result<ObservationSet> bad = BuildObservationSet({"a", "b"}, points, short_joints, setup);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("pose a: 5 joint values"), std::string::npos) << bad.status().message();
}

// Flange poses: the set has no joints (FlangePoseModel), the hand-eye transform is known only when given;
// flange poses in some images only are refused.
TEST(BuildObservationSet, FlangePoses) {
  const std::vector<ImagePoints> points = {Found({{0, {10, 20}}}), Found({{0, {12, 22}}})};
  const Rigid3 a(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.5, 0, 0.4));
  const Rigid3 b(RotZ(0.3), Eigen::Vector3d(0.5, 0.1, 0.4));
  const std::vector<ImageRobotPose> poses = {{a, Eigen::VectorXd()}, {b, Eigen::VectorXd()}};
  ObservationSetup setup = JointSetup();
  Result<ObservationSet> set = BuildObservationSet({"1", "2"}, points, poses, setup);
  ASSERT_TRUE(set.ok()) << set.status().message();
  EXPECT_TRUE(set->UsesFlangePoses());
  EXPECT_EQ(set->robot.num_joints(), 0);
  EXPECT_FALSE(set->flange_from_cam_known);
  ASSERT_TRUE(set->poses[1].base_from_flange.has_value());
  EXPECT_EQ(set->poses[1].base_from_flange->translation, b.translation);
  EXPECT_EQ(set->poses[1].joints_rad.size(), 0);
  setup.flange_from_cam = Rigid3(RotX(0.1), Eigen::Vector3d(0, 0, 0.06));
  set = BuildObservationSet({"1", "2"}, points, poses, setup);
  ASSERT_TRUE(set.ok()) << set.status().message();
  EXPECT_TRUE(set->flange_from_cam_known);
  EXPECT_EQ(set->robot.flange_from_cam.translation, setup.flange_from_cam->translation);
  const std::vector<ImageRobotPose> mixed = {{a, Eigen::VectorXd()}, {std::nullopt, Eigen::VectorXd::Zero(6)}};
  const Result<ObservationSet> refused = BuildObservationSet({"1", "2"}, points, mixed, setup);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("1 of 2 images have flange poses"), std::string::npos);
}

}  // namespace
}  // namespace selfcal::detection
