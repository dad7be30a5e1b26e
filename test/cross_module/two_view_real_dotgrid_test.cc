// The two-view estimator's pure-rotation verdict on real flat-target images: the ROS-Industrial 10 x 10 dot
// grid of test/data (15 images from a wrist camera, the wrist pose of each), every one of its 105 pairs.
// Whether a pair translated is known from the wrist poses; a `pure_rotation` verdict on a pair whose
// wrist moved is false. Detection by selfcal's own detector (io reads, detection names the dots by the
// grid's origin dot), the estimator called directly as the paper pipeline and the hand-eye start call it.
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <random>

#include <gtest/gtest.h>

#include "detection/detect_points.h"
#include "io/file_lists.h"
#include "io/image_files.h"
#include "io/pose_files.h"
#include "twoview/two_view.h"

namespace selfcal {
namespace {

const std::string kRos = std::string(SELFCAL_SOURCE_DIR) + "/test/data/ros-industrial-dotgrid-10x10";
// A pair whose wrist moved farther than this is a translation: far above what the images can miss at
// 0.79 m (the false verdicts were on 3 to 11 cm).
constexpr double kTranslatedM = 0.02;

struct RosData {
  std::vector<detection::ImagePoints> points;
  std::vector<Rigid3> base_from_flange;
};

RosData LoadRos() {
  RosData data;
  Result<std::vector<std::string>> paths = io::ListFiles(kRos + "/images", io::ImageExtensions(), "images");
  EXPECT_TRUE(paths.ok()) << paths.status().ToString();
  Result<std::vector<io::ImagePose>> poses = io::LoadImagePoses(kRos + "/poses", nullptr);
  EXPECT_TRUE(poses.ok()) << poses.status().ToString();
  Result<std::vector<io::ImagePose>> matched = io::MatchPosesToImages(*paths, *poses);
  EXPECT_TRUE(matched.ok()) << matched.status().ToString();
  Result<std::vector<io::NamedImage>> images = io::ReadGreyImages(*paths);
  EXPECT_TRUE(images.ok()) << images.status().ToString();
  std::vector<const vpImage<unsigned char>*> pixels;
  for (const io::NamedImage& image : *images) pixels.push_back(&image.image);
  data.points = detection::DetectAllImagePoints(pixels, detection::DetectionOptions());
  for (const io::ImagePose& pose : *matched) data.base_from_flange.push_back(*pose.base_from_flange);
  return data;
}

struct PairVerdicts {
  std::map<std::string, int> by_outcome;
  int pairs = 0, translated = 0, false_pure_rotation = 0;
  std::string false_ones;
  double least_moved_m = 1e9;  // the pair whose wrist moved least, and its verdict
  std::string least_moved_outcome;
};

PairVerdicts CountVerdicts(const RosData& data, const CameraIntrinsics& camera) {
  PairVerdicts v;
  for (size_t a = 0; a < data.points.size(); ++a) {
    for (size_t b = a + 1; b < data.points.size(); ++b) {
      std::vector<Eigen::Vector2d> pa, pb;
      for (const auto& [id, uv] : data.points[a].points_px) {
        const auto it = data.points[b].points_px.find(id);
        if (it == data.points[b].points_px.end()) continue;
        pa.push_back(uv);
        pb.push_back(it->second);
      }
      const twoview::TwoViewReport r = twoview::EstimateTwoView(twoview::TwoViewOptions(), camera, pa, pb);
      const double moved_m = (data.base_from_flange[a].Inverse() * data.base_from_flange[b]).translation.norm();
      ++v.pairs;
      ++v.by_outcome[twoview::OutcomeName(r.outcome)];
      if (moved_m < v.least_moved_m) {
        v.least_moved_m = moved_m;
        v.least_moved_outcome = twoview::OutcomeName(r.outcome);
      }
      v.translated += moved_m > kTranslatedM ? 1 : 0;
      if (r.outcome == twoview::Outcome::kPureRotation && moved_m > kTranslatedM) {
        ++v.false_pure_rotation;
        char line[160];
        std::snprintf(line, sizeof(line), "\n  images %zu-%zu: wrist moved %.1f mm; ", a, b, 1e3 * moved_m);
        v.false_ones += line + r.message;
      }
    }
  }
  return v;
}

void Print(const char* camera_name, const PairVerdicts& v) {
  std::printf("[ measured ] %s: %d pairs (%d translated > %.0f mm):", camera_name, v.pairs, v.translated,
              1e3 * kTranslatedM);
  for (const auto& [outcome, count] : v.by_outcome) std::printf(" %s %d", outcome.c_str(), count);
  std::printf("; false pure_rotation %d%s; least wrist motion %.1f mm: %s\n", v.false_pure_rotation,
              v.false_ones.c_str(), 1e3 * v.least_moved_m, v.least_moved_outcome.c_str());
}

CameraIntrinsics RosCamera(bool calibrated) {
  CameraIntrinsics camera;
  camera.width_px = 640;
  camera.height_px = 480;
  camera.fx_px = 542.324;  // rct_camera_intr_calibrated.yaml; docs/detect.md's --camera-fx-px 542.3
  if (calibrated) {
    camera.mu = 543.515 / 542.324;
    camera.cx_px = 320.474;
    camera.cy_px = 226.039;
  } else {
    camera.cx_px = 319.5;  // selfcal detect's default: the image centre
    camera.cy_px = 239.5;
  }
  return camera;
}

TEST(TwoViewRealDotGrid, NoFalsePureRotationOnTheRosDotGridPairs) {
  const RosData data = LoadRos();
  ASSERT_EQ(data.points.size(), 15u);
  for (const detection::ImagePoints& p : data.points) ASSERT_EQ(p.points_px.size(), 100u) << p.message;
  for (const bool calibrated : {false, true}) {
    const PairVerdicts v = CountVerdicts(data, RosCamera(calibrated));
    Print(calibrated ? "calibrated intrinsics" : "f_x and the image centre", v);
    EXPECT_EQ(v.pairs, 105);
    EXPECT_EQ(v.false_pure_rotation, 0) << v.false_ones;
  }
}

// The other side of the verdict: a camera that only rotates in front of the same target (10 x 10 dots
// 25.4 mm apart at 0.79 m, the plane tilted 20 deg, the ROS camera) is still a pure rotation, at the
// pixel noise of a real detector, for 20 seeded rotations of 5 to 15 deg about random axes.
TEST(TwoViewRealDotGrid, SimulatedPureRotationOfTheSameTargetIsStillDetected) {
  const CameraIntrinsics camera = RosCamera(false);
  std::mt19937_64 rng(13);
  std::normal_distribution<double> gauss(0, 1);
  std::uniform_real_distribution<double> angle_deg(5, 15);
  const Eigen::Matrix3d tilt = ExpSO3<double>(Eigen::Vector3d(DegToRad(20), 0, 0));
  int detected = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d axis = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Eigen::Matrix3d cam2_from_cam1 = ExpSO3<double>(DegToRad(angle_deg(rng)) * axis);
    std::vector<Eigen::Vector2d> p1, p2;
    for (int r = 0; r < 10; ++r) {
      for (int c = 0; c < 10; ++c) {
        const Eigen::Vector3d p = Eigen::Vector3d(0, 0, 0.79) + tilt * Eigen::Vector3d(0.0254 * (c - 4.5), 0.0254 * (r - 4.5), 0);
        const auto a = Project(camera, p), b = Project(camera, cam2_from_cam1 * p);
        if (!a || !b || !InImage(camera, *a, 5) || !InImage(camera, *b, 5)) continue;
        p1.push_back(*a + 0.2 * Eigen::Vector2d(gauss(rng), gauss(rng)));
        p2.push_back(*b + 0.2 * Eigen::Vector2d(gauss(rng), gauss(rng)));
      }
    }
    ASSERT_GE(p1.size(), 30u) << "trial " << trial << ": the rotation took the target out of view";
    const twoview::TwoViewReport report = twoview::EstimateTwoView(twoview::TwoViewOptions(), camera, p1, p2);
    EXPECT_EQ(report.outcome, twoview::Outcome::kPureRotation) << "trial " << trial << ": " << report.message;
    detected += report.outcome == twoview::Outcome::kPureRotation ? 1 : 0;
  }
  std::printf("[ measured ] simulated pure rotations detected: %d of 20\n", detected);
}

}  // namespace
}  // namespace selfcal
