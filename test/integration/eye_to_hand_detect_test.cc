// `selfcal detect --configuration eye_to_hand` on ViSP's eye-to-hand Franka set (test/data's copy): a camera
// fixed in the cell, one AprilTag on the flange, its four corners the unknown points. The corners are checked
// against a criterion independent of the detector: the rotation angle of every relative motion of the tag seen
// by the fixed camera (OpenCV's PnP on the square of known side) against that of the matching relative flange
// motion, equal whatever the flange-to-tag and base-to-camera transforms; a corner order turned by one corner in
// an image puts that image's tag 90 degrees off. Then the refusals of an eye-to-hand file given a
// flange-to-camera transform, by `calibrate` (nothing written) and by `detect` (an eye-in-hand nominal).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "io/observations_file.h"
#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::FreshDir;
using testing::ReadFile;
using testing::RunSelfcal;
using testing::WriteFile;

const std::string kSet = std::string(SELFCAL_SOURCE_DIR) + "/test/data/visp-franka-eye-to-hand";
const std::string kShared = std::string(SELFCAL_SOURCE_DIR) + "/../shared/data/visp-franka-eye-to-hand";
constexpr double kTagSideM = 0.048;

std::string DetectArguments(const fs::path& out) {
  return "detect --configuration eye_to_hand --images '" + kSet + "/franka_image-*.png' --poses '" + kSet +
         "/franka_pose_rPe_*.yaml' --detector apriltag --tag-side-mm 48 --camera-file " + kSet +
         "/franka_camera.xml --out " + out.string();
}

// The tag's rotation in the fixed camera, by PnP on its four corners (ids 4 * tag + k: bottom-left,
// bottom-right, top-right, top-left, at (-+s/2, -+s/2) in the tag frame): both solutions of OpenCV's IPPE for a
// square, since four corners of a small tag leave the two poses of the planar ambiguity close in reprojection.
std::vector<Eigen::Matrix3d> CamFromTagRotations(const PoseObservation& pose, const cv::Matx33d& k) {
  std::vector<cv::Point3d> tag;
  std::vector<cv::Point2d> image;
  const double h = kTagSideM / 2;
  const double corners[4][2] = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
  for (const auto& [id, px] : pose.dots_px) {
    tag.emplace_back(corners[id % 4][0], corners[id % 4][1], 0.0);
    image.emplace_back(px.x(), px.y());
  }
  std::vector<cv::Mat> rvecs, tvecs;
  EXPECT_GT(cv::solvePnPGeneric(tag, image, k, cv::noArray(), rvecs, tvecs, false, cv::SOLVEPNP_IPPE_SQUARE), 0) << pose.id;
  std::vector<Eigen::Matrix3d> out;
  for (const cv::Mat& rvec : rvecs) {
    cv::Mat r;
    cv::Rodrigues(rvec, r);
    Eigen::Matrix3d e;
    cv::cv2eigen(r, e);
    out.push_back(e);
  }
  return out;
}

double AngleDeg(const Eigen::Matrix3d& r) { return Eigen::AngleAxisd(r).angle() * 180 / M_PI; }

// Over every pair of poses, |angle(tag motion seen by the camera) - angle(flange motion)|, the tag's rotation in
// each image the IPPE solution that agrees best: the largest, and the median in *median_deg.
double WorstRelativeRotationDeg(const ObservationSet& set, const cv::Matx33d& k, double* median_deg) {
  std::vector<std::vector<Eigen::Matrix3d>> cam_from_tag;
  for (const PoseObservation& p : set.poses) cam_from_tag.push_back(CamFromTagRotations(p, k));
  std::vector<double> diffs;
  for (size_t i = 0; i < set.poses.size(); ++i) {
    for (size_t j = i + 1; j < set.poses.size(); ++j) {
      const Eigen::Matrix3d flange = set.poses[i].base_from_flange->rotation.transpose() * set.poses[j].base_from_flange->rotation;
      double best = 180;
      for (const Eigen::Matrix3d& a : cam_from_tag[i]) {
        for (const Eigen::Matrix3d& b : cam_from_tag[j]) best = std::min(best, std::abs(AngleDeg(a.transpose() * b) - AngleDeg(flange)));
      }
      diffs.push_back(best);
    }
  }
  std::sort(diffs.begin(), diffs.end());
  *median_deg = diffs[diffs.size() / 2];
  return diffs.back();
}

TEST(EyeToHandDetect, TheTagsCornersOfEveryImageWithFlangePosesAndTheTagAsYardstick) {
  const fs::path dir = FreshDir("e2h_detect", "visp");
  std::string out;
  ASSERT_EQ(RunSelfcal(DetectArguments(dir / "obs.yaml") + " --contact-sheet " + (dir / "sheet.png").string(), &out), 0)
      << out;
  EXPECT_NE(out.find("8 of 8 images with points (4 to 4 points each), flange poses, eye_to_hand"), std::string::npos)
      << out;
  const std::string text = ReadFile((dir / "obs.yaml").string());
  EXPECT_NE(text.find("version: 1.2\nconfiguration: eye_to_hand\n"), std::string::npos) << text;
  Result<ObservationSet> set = io::LoadObservations((dir / "obs.yaml").string());
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  EXPECT_EQ(set->robot.mount, CameraMount::kEyeToHand);
  EXPECT_TRUE(set->UsesFlangePoses());
  EXPECT_FALSE(set->flange_from_cam_known);  // no nominal fixed camera: the calibration starts it from the images
  ASSERT_EQ(set->poses.size(), 8u);
  std::set<int> ids;
  for (size_t i = 0; i < set->poses.size(); ++i) {
    const PoseObservation& p = set->poses[i];
    EXPECT_EQ(p.id, "franka_image-" + std::to_string(i + 1));
    ASSERT_EQ(p.dots_px.size(), 4u) << p.id;
    for (const auto& [id, px] : p.dots_px) ids.insert(id);
  }
  // One tag, its four corners in every image; ViSP's tag is 36h11 id 10.
  EXPECT_EQ(ids, (std::set<int>{40, 41, 42, 43}));
  // franka_pose_rPe_1.yaml, as written there (m, theta-u rad).
  const Rigid3& first = *set->poses[0].base_from_flange;
  EXPECT_LT((first.translation - Eigen::Vector3d(0.719437, -0.0332613, 0.412152)).norm(), 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(first.rotation).angle(), Eigen::Vector3d(3.05894, 0.00390122, 0.105226).norm(), 1e-9);
  // franka_camera.xml: the D435's factory intrinsics.
  EXPECT_NEAR(set->camera.fx_px, 607.5931396484375, 1e-9);
  EXPECT_NEAR(set->camera.cy_px, 243.25529479980469, 1e-9);
  // The tag of 48 mm: its bottom edge the yardstick, its top edge a held-out check.
  ASSERT_EQ(set->yardsticks.size(), 1u);
  EXPECT_EQ(set->yardsticks[0].dot_a, 40);
  EXPECT_EQ(set->yardsticks[0].dot_b, 41);
  EXPECT_EQ(set->yardsticks[0].length_m, kTagSideM);
  ASSERT_EQ(set->check_distances.size(), 1u);
  EXPECT_EQ(set->check_distances[0].dot_a, 43);
  EXPECT_EQ(set->check_distances[0].dot_b, 42);
  EXPECT_TRUE(fs::exists(dir / "sheet.png"));

  const cv::Matx33d k(set->camera.fx_px, 0, set->camera.cx_px, 0, set->camera.mu * set->camera.fx_px, set->camera.cy_px,
                      0, 0, 1);
  double median = 0;
  const double worst = WorstRelativeRotationDeg(*set, k, &median);
  std::cout << "[ e2h detect ] tag vs flange relative rotations over 28 pairs: median " << median << " deg, max "
            << worst << " deg\n";
  // Measured: a median of 0.41 deg and at most 5.3 deg (four corners of a 48 mm tag: the rotation of one view is
  // poorly fixed by them); a corner order turned by one corner in an image is tens of degrees off in that image's
  // pairs.
  EXPECT_LT(median, 1.0);
  EXPECT_LT(worst, 10.0);
  ObservationSet turned = *set;
  std::map<int, Eigen::Vector2d> rotated;
  for (const auto& [id, px] : turned.poses[3].dots_px) rotated[40 + (id + 1) % 4] = px;
  turned.poses[3].dots_px = rotated;
  double turned_median = 0;
  const double turned_worst = WorstRelativeRotationDeg(turned, k, &turned_median);
  std::cout << "[ e2h detect ] with image 4's corners turned by one: max " << turned_worst << " deg\n";
  EXPECT_GT(turned_worst, 30.0);
}

// An eye-to-hand file that gives a flange-to-camera transform: `calibrate` refuses it naming the file, the line
// and the key, exit 2, and writes nothing into its output directory.
TEST(EyeToHandDetect, CalibrateRefusesAnEyeToHandFileWithAFlangeToCameraKey) {
  const fs::path dir = FreshDir("e2h_detect", "refused");
  ASSERT_EQ(RunSelfcal(DetectArguments(dir / "obs.yaml")), 0);
  std::string text = ReadFile((dir / "obs.yaml").string());
  const std::string anchor = "configuration: eye_to_hand\n";
  const size_t at = text.find(anchor);
  ASSERT_NE(at, std::string::npos) << text;
  text.insert(at + anchor.size(), "flange_from_cam: {xyz_mm: [0, 0, 60], rpy_deg: [0, 0, 90]}\n");
  const fs::path bad = dir / "bad.yaml";
  WriteFile(bad.string(), text);
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at + anchor.size()), '\n'));
  fs::create_directories(dir / "out");
  std::string out;
  EXPECT_EQ(RunSelfcal("calibrate " + bad.string() + " --out " + (dir / "out").string(), &out), 2) << out;
  EXPECT_NE(out.find("`flange_from_cam` at " + bad.string() + ":" + std::to_string(line) +
                     " does not fit `configuration: eye_to_hand`"),
            std::string::npos)
      << out;
  EXPECT_TRUE(fs::is_empty(dir / "out")) << "calibrate wrote into its output directory on a refused input";

  // detect: an eye-in-hand nominal (a hand-eye result of the camera on the flange) for an eye-to-hand set.
  const fs::path hand_eye = dir / "hand_eye.yaml";
  WriteFile(hand_eye.string(),
            "format: selfcal-hand-eye\nversion: 1\nflange_from_cam: {xyz_mm: [0, 0, 60], rpy_deg: [0, 0, 0]}\n"
            "flange_from_cam_exact: {xyz_m: [0, 0, 0.06], rotation: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}\nfx_px: 600\n");
  EXPECT_EQ(RunSelfcal(DetectArguments(dir / "second.yaml") + " --hand-eye " + hand_eye.string(), &out), 2) << out;
  EXPECT_NE(out.find("is an eye_in_hand result; this set is eye_to_hand"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "second.yaml"));
}

// The copy in test/data is the shared data set's, byte for byte (only COPYING and the README added).
TEST(EyeToHandDetect, TheCopyHoldsTheSharedSetsBytes) {
  if (!fs::exists(kShared)) GTEST_SKIP() << "no " << kShared << ": the copy is not compared with it";
  int compared = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(kShared)) {
    const std::string name = entry.path().filename().string();
    if (name == "README.md") continue;
    EXPECT_EQ(ReadFile(entry.path().string()), ReadFile(kSet + "/" + name)) << name;
    ++compared;
  }
  EXPECT_EQ(compared, 18);  // 8 images, 8 pose files, the camera and the tag's description
}

}  // namespace
}  // namespace selfcal
