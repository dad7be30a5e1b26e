// `selfcal detect` on the real data sets of test/data, checked against criteria independent of the
// detector: a homography of the ideal grid through every image's ids (a point on the wrong cell is a
// whole spacing off), and across images the rotation angle of every relative camera motion (OpenCV's
// PnP on the ids) against the matching relative flange motion, which agree whatever the hand-eye
// transform; an image whose ids were turned or mirrored gets a camera rotation tens of degrees off.
// Then the refusals: unreadable image, mismatched sizes, missing pose, bad pose key, failed detection.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "io/observations_file.h"
#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::FreshDir;
using testing::RunSelfcal;

const std::string kData = std::string(SELFCAL_SOURCE_DIR) + "/test/data";
const std::string kRos = kData + "/ros-industrial-dotgrid-10x10";
const std::string kFranka = kData + "/visp-franka-eye-in-hand";

// The largest distance of a pose's points from the least-squares homography of the ideal grid.
double MaxHomographyResidual(const PoseObservation& pose, int cols) {
  std::vector<cv::Point2f> ideal, image;
  for (const auto& [id, px] : pose.dots_px) {
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

// cam_from_target by OpenCV's PnP on the ids (grid pitch `spacing_m`, intrinsics k): rotation, translation.
std::pair<cv::Mat, cv::Mat> CameraFromTarget(const PoseObservation& pose, int cols, double spacing_m, const cv::Matx33d& k) {
  std::vector<cv::Point3d> target;
  std::vector<cv::Point2d> image;
  for (const auto& [id, px] : pose.dots_px) {
    target.emplace_back((id % cols) * spacing_m, (id / cols) * spacing_m, 0.0);
    image.emplace_back(px.x(), px.y());
  }
  cv::Mat rvec, tvec, r;
  EXPECT_TRUE(cv::solvePnP(target, image, k, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_IPPE)) << pose.id;
  cv::solvePnPRefineLM(target, image, k, cv::noArray(), rvec, tvec);
  cv::Rodrigues(rvec, r);
  return {r, tvec};
}

Eigen::Matrix3d CameraRotation(const PoseObservation& pose, int cols, double spacing_m, const cv::Matx33d& k) {
  Eigen::Matrix3d out;
  cv::cv2eigen(CameraFromTarget(pose, cols, spacing_m, k).first, out);
  return out;
}

double AngleDeg(const Eigen::Matrix3d& r) { return Eigen::AngleAxisd(r).angle() * 180 / M_PI; }

struct RotationAgreement {
  double median_deg = 0, max_deg = 0;
  int pairs = 0;
};

// |angle(camera motion) - angle(flange motion)| over every pair of poses.
RotationAgreement CompareRelativeRotations(const ObservationSet& set, int cols, double spacing_m, const cv::Matx33d& k) {
  std::vector<Eigen::Matrix3d> cam;
  for (const PoseObservation& p : set.poses) cam.push_back(CameraRotation(p, cols, spacing_m, k));
  std::vector<double> diffs;
  for (size_t i = 0; i < set.poses.size(); ++i) {
    for (size_t j = i + 1; j < set.poses.size(); ++j) {
      const Eigen::Matrix3d flange = set.poses[i].base_from_flange->rotation.transpose() * set.poses[j].base_from_flange->rotation;
      const Eigen::Matrix3d camera = cam[i] * cam[j].transpose();
      diffs.push_back(std::abs(AngleDeg(camera) - AngleDeg(flange)));
    }
  }
  RotationAgreement a;
  a.pairs = static_cast<int>(diffs.size());
  std::sort(diffs.begin(), diffs.end());
  a.median_deg = diffs[diffs.size() / 2];
  a.max_deg = diffs.back();
  return a;
}

ObservationSet Load(const fs::path& path) {
  Result<ObservationSet> set = io::LoadObservations(path.string());
  EXPECT_TRUE(set.ok()) << set.status().ToString();
  return set.ok() ? *set : ObservationSet();
}

// 15/15 images, 100 dots each, the ids consistent across images; the contact sheet shows every image.
TEST(DetectCli, RosDotGridEveryDotOfEveryImageWithConsistentIds) {
  const fs::path dir = FreshDir("detect", "ros");
  std::string out;
  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(RunSelfcal("detect --images " + kRos + "/images --poses " + kRos + "/poses --camera-fx-px 542.3 --out " +
                           (dir / "obs.yaml").string() + " --contact-sheet " + (dir / "sheet.png").string(),
                       &out),
            0)
      << out;
  std::cout << "[ detect ] ros-industrial-dotgrid-10x10: "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s\n";
  const ObservationSet set = Load(dir / "obs.yaml");
  ASSERT_EQ(set.poses.size(), 15u) << out;
  EXPECT_TRUE(set.UsesFlangePoses());
  EXPECT_EQ(set.camera.width_px, 640);
  for (const PoseObservation& p : set.poses) {
    EXPECT_EQ(p.dots_px.size(), 100u) << p.id;
    // A dot on the wrong cell is ~18 px off; the lens (no distortion model) leaves up to ~3 px.
    EXPECT_LT(MaxHomographyResidual(p, 10), 4.0) << p.id;
  }
  EXPECT_EQ(set.poses.front().id, "0");
  EXPECT_EQ(set.poses.back().id, "14");
  // Across images: the data's calibrated intrinsics, 25.4 mm pitch. ../shared/data's README measured a
  // median of 1.6 deg (p90 4.5) for Kinect-quality images without a distortion model.
  const cv::Matx33d k(542.324, 0, 320.474, 0, 543.515, 226.039, 0, 0, 1);
  const RotationAgreement a = CompareRelativeRotations(set, 10, 0.0254, k);
  std::cout << "[ detect ] ros relative rotations: median " << a.median_deg << " deg, max " << a.max_deg << " deg over "
            << a.pairs << " pairs\n";
  EXPECT_LT(a.median_deg, 3.0);
  EXPECT_LT(a.max_deg, 10.0);
  // The origin is the larger dot, found by OpenCV's own blob detector (independent of ours).
  const cv::Mat first = cv::imread(kRos + "/images/0.png", cv::IMREAD_GRAYSCALE);
  std::vector<cv::KeyPoint> blobs;
  cv::SimpleBlobDetector::create()->detect(first, blobs);
  ASSERT_FALSE(blobs.empty());
  const auto largest = std::max_element(blobs.begin(), blobs.end(),
                                        [](const cv::KeyPoint& x, const cv::KeyPoint& y) { return x.size < y.size; });
  const Eigen::Vector2d origin = set.poses[0].dots_px.at(0);
  EXPECT_LT(std::hypot(largest->pt.x - origin.x(), largest->pt.y - origin.y()), 2.0);
  const cv::Mat sheet = cv::imread((dir / "sheet.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(sheet.empty());
  EXPECT_GE(sheet.cols, 4 * 640);  // 15 images: 4 columns of full-size tiles, 4 rows
  EXPECT_GE(sheet.rows, 4 * 480);
}

// 8/8 images, 54 corners each, corner 0 the same physical corner in every image (relative rotations, and
// the published hand-eye result through OpenCV).
TEST(DetectCli, FrankaChessboardEveryCornerWithConsistentOrdering) {
  const fs::path dir = FreshDir("detect", "franka");
  std::string out;
  ASSERT_EQ(RunSelfcal("detect --images '" + kFranka + "/franka_image-*.png' --poses '" + kFranka +
                           "/franka_pose_rPe_*.yaml' --detector chessboard --grid 6x9 --camera-fx-px 607.6 "
                           "--camera-cx-px 323.46 --camera-cy-px 243.26 --pixel-noise-px 0.2 --out " +
                           (dir / "obs.yaml").string(),
                       &out),
            0)
      << out;
  EXPECT_NE(out.find("8 of 8 images with points (54 to 54 points each), flange poses"), std::string::npos) << out;
  const ObservationSet set = Load(dir / "obs.yaml");
  ASSERT_EQ(set.poses.size(), 8u);
  for (const PoseObservation& p : set.poses) {
    EXPECT_EQ(p.dots_px.size(), 54u) << p.id;
    EXPECT_LT(MaxHomographyResidual(p, 9), 2.0) << p.id;  // measured up to 1.1 px (lens); a cell is ~25 px
  }
  // The factory intrinsics of franka_camera.xml, 23.6 mm squares; ../shared/data's README measured a
  // median of 0.18 deg and at most 0.58 deg over the 28 pairs.
  const cv::Matx33d k(607.5931396484375, 0, 323.46282958984375, 0, 607.574951171875, 243.25529479980469, 0, 0, 1);
  const RotationAgreement a = CompareRelativeRotations(set, 9, 0.0236, k);
  std::cout << "[ detect ] franka relative rotations: median " << a.median_deg << " deg, max " << a.max_deg
            << " deg over " << a.pairs << " pairs\n";
  EXPECT_LT(a.median_deg, 0.5);
  EXPECT_LT(a.max_deg, 2.0);
  // OpenCV's hand-eye calibration (Park) on PnP poses from the ids and the flange poses gives the ViSP
  // tutorial's published result, translation [57.7, -33.9, -42.3] mm and theta-u [0.10, 0.53, 90.63] deg
  // (measured: within 0.1 mm and 0.02 deg); an image whose corner 0 sat on another corner would move it by
  // centimetres and degrees.
  std::vector<cv::Mat> r_flange, t_flange, r_cam, t_cam;
  for (const PoseObservation& p : set.poses) {
    const auto [r, t] = CameraFromTarget(p, 9, 0.0236, k);
    r_cam.push_back(r);
    t_cam.push_back(t);
    cv::Mat rf, tf;
    cv::eigen2cv(Eigen::Matrix3d(p.base_from_flange->rotation), rf);
    cv::eigen2cv(Eigen::Vector3d(p.base_from_flange->translation), tf);
    r_flange.push_back(rf);
    t_flange.push_back(tf);
  }
  cv::Mat r_he, t_he, rotvec;
  cv::calibrateHandEye(r_flange, t_flange, r_cam, t_cam, r_he, t_he, cv::CALIB_HAND_EYE_PARK);
  cv::Rodrigues(r_he, rotvec);
  std::cout << "[ detect ] franka hand-eye (OpenCV Park on the ids): translation " << t_he.t() * 1e3 << " mm, theta-u "
            << rotvec.t() * (180 / M_PI) << " deg\n";
  const double reference_mm[3] = {57.7, -33.9, -42.3}, reference_deg[3] = {0.10, 0.53, 90.63};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(t_he.at<double>(i) * 1e3, reference_mm[i], 1.0) << i;
    EXPECT_NEAR(rotvec.at<double>(i) * 180 / M_PI, reference_deg[i], 0.2) << i;
  }
}

// A copy of the first three ROS images and poses to break.
fs::path SmallRosCopy(const std::string& name) {
  const fs::path dir = FreshDir("detect", name);
  fs::create_directories(dir / "images");
  fs::create_directories(dir / "poses");
  for (int i = 0; i < 3; ++i) {
    fs::copy_file(kRos + "/images/" + std::to_string(i) + ".png", dir / "images" / (std::to_string(i) + ".png"));
    fs::copy_file(kRos + "/poses/" + std::to_string(i) + ".yaml", dir / "poses" / (std::to_string(i) + ".yaml"));
  }
  return dir;
}

// Runs detect on the copy; returns the exit code, *out the output. No output file may exist after an error,
// but for the contact sheet after a detection that failed (exit 3): it shows why.
int DetectOnCopy(const fs::path& dir, std::string* out, const std::string& extra = "") {
  const int code = RunSelfcal("detect --images " + (dir / "images").string() + " --poses " + (dir / "poses").string() +
                                  " --camera-fx-px 542.3 --out " + (dir / "obs.yaml").string() + " --contact-sheet " +
                                  (dir / "sheet.png").string() + " " + extra,
                              out);
  if (code != 0) {
    EXPECT_FALSE(fs::exists(dir / "obs.yaml")) << *out;
    EXPECT_FALSE(fs::exists(dir / "obs.skipped.yaml")) << *out;
    EXPECT_EQ(fs::exists(dir / "sheet.png"), code == 3) << *out;
  }
  return code;
}

// Red text pixels (a failed image's outcome and reason) in the top 80 rows of the k-th of three 640 x 480
// tiles of a contact sheet (two columns).
int RedOnTile(const cv::Mat& sheet, int k) {
  const int x0 = 6 + (k % 2) * 646, y0 = 22 + (k / 2) * (480 + 22 + 6) + 22;
  int red = 0;
  for (int v = y0; v < y0 + 80; ++v) {
    for (int u = x0; u < x0 + 640; ++u) {
      const cv::Vec3b p = sheet.at<cv::Vec3b>(v, u);
      red += (p[2] > 200 && p[1] < 80 && p[0] < 80) ? 1 : 0;
    }
  }
  return red;
}

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

TEST(DetectCli, BadInputsNameTheFileAndWriteNothing) {
  std::string out;
  {
    const fs::path dir = SmallRosCopy("unreadable");
    WriteText(dir / "images" / "1.png", "this is not a PNG");
    EXPECT_EQ(DetectOnCopy(dir, &out), 2) << out;
    EXPECT_NE(out.find((dir / "images" / "1.png").string() + ": cannot"), std::string::npos) << out;
  }
  {
    const fs::path dir = SmallRosCopy("sizes");
    cv::Mat small(240, 320, CV_8UC1, cv::Scalar(128));
    cv::imwrite((dir / "images" / "2.png").string(), small);
    EXPECT_EQ(DetectOnCopy(dir, &out), 2) << out;
    EXPECT_NE(out.find((dir / "images" / "2.png").string() + ": is 320x240 px, but"), std::string::npos) << out;
  }
  {
    const fs::path dir = SmallRosCopy("missing_pose");
    fs::remove(dir / "poses" / "1.yaml");
    EXPECT_EQ(DetectOnCopy(dir, &out), 2) << out;
    EXPECT_NE(out.find((dir / "images" / "1.png").string() + ": no pose for image number `1`"), std::string::npos) << out;
  }
  {
    const fs::path dir = SmallRosCopy("bad_key");
    WriteText(dir / "poses" / "2.yaml", "x: 0.7\ny: 0.0\nz: 0.85\nqx: 0\nqy: 1\nqz: 0\nqw: 0\nroll: 0\n");
    EXPECT_EQ(DetectOnCopy(dir, &out), 2) << out;
    EXPECT_NE(out.find("unknown key `roll` at " + (dir / "poses" / "2.yaml").string() + ":8"), std::string::npos) << out;
  }
}

// An image where the grid is not found: exit code 3 naming it, and the contact sheet written all the same,
// the failed image's reason on its tile; with --skip-failed that image is left out, named on stdout and in
// the skipped list beside the observations, with its reason.
TEST(DetectCli, AFailedDetectionIsDegenerateDataUnlessSkipped) {
  const fs::path dir = SmallRosCopy("failed");
  cv::imwrite((dir / "images" / "1.png").string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(200)));
  std::string out;
  EXPECT_EQ(DetectOnCopy(dir, &out), 3) << out;
  EXPECT_NE(out.find("1: grid not identified"), std::string::npos) << out;
  EXPECT_NE(out.find("contact sheet " + (dir / "sheet.png").string()), std::string::npos) << out;
  const cv::Mat sheet = cv::imread((dir / "sheet.png").string(), cv::IMREAD_COLOR);
  ASSERT_EQ(sheet.cols, 6 + 2 * 646);
  EXPECT_GT(RedOnTile(sheet, 1), 200);
  EXPECT_EQ(RedOnTile(sheet, 0), 0);
  EXPECT_EQ(RedOnTile(sheet, 2), 0);
  // The sheet of the failed run is an earlier result: replaced only with --force.
  EXPECT_EQ(RunSelfcal("detect --images " + (dir / "images").string() + " --poses " + (dir / "poses").string() +
                           " --camera-fx-px 542.3 --out " + (dir / "obs.yaml").string() + " --contact-sheet " +
                           (dir / "sheet.png").string() + " --skip-failed", &out),
            2)
      << out;
  ASSERT_EQ(DetectOnCopy(dir, &out, "--skip-failed --force"), 0) << out;
  const ObservationSet set = Load(dir / "obs.yaml");
  ASSERT_EQ(set.poses.size(), 2u);
  EXPECT_EQ(set.poses[1].id, "2");
  EXPECT_TRUE(fs::exists(dir / "sheet.png"));
  EXPECT_NE(out.find("skipped 1 of 3 images, listed in " + (dir / "obs.skipped.yaml").string()), std::string::npos)
      << out;
  EXPECT_NE(out.find("  SKIPPED " + (dir / "images" / "1.png").string() + ": grid not identified"), std::string::npos)
      << out;
  const YAML::Node skipped = YAML::LoadFile((dir / "obs.skipped.yaml").string());
  EXPECT_EQ(skipped["format"].as<std::string>(), "selfcal-skipped-images");
  EXPECT_EQ(skipped["observations"].as<std::string>(), (dir / "obs.yaml").string());
  EXPECT_EQ(skipped["images"].as<int>(), 3);
  EXPECT_EQ(skipped["kept"].as<int>(), 2);
  ASSERT_EQ(skipped["skipped"].size(), 1u);
  EXPECT_EQ(skipped["skipped"][0]["pose"].as<std::string>(), "1");
  EXPECT_EQ(skipped["skipped"][0]["image"].as<std::string>(), (dir / "images" / "1.png").string());
  EXPECT_EQ(skipped["skipped"][0]["reason"].as<std::string>().rfind("grid not identified", 0), 0u);
  // --skipped-out names the list; without --skip-failed it is refused.
  ASSERT_EQ(DetectOnCopy(dir, &out, "--skip-failed --force --skipped-out " + (dir / "left-out.yaml").string()), 0)
      << out;
  EXPECT_EQ(YAML::LoadFile((dir / "left-out.yaml").string())["skipped"].size(), 1u);
  fs::remove(dir / "obs.yaml");
  EXPECT_EQ(RunSelfcal("detect --images " + (dir / "images").string() + " --poses " + (dir / "poses").string() +
                           " --camera-fx-px 542.3 --out " + (dir / "obs.yaml").string() + " --skipped-out " +
                           (dir / "x.yaml").string(), &out),
            2)
      << out;
  EXPECT_NE(out.find("--skipped-out"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "obs.yaml"));
}

// A selfcal-poses list of joint angles on a robot config, and the yardstick option.
TEST(DetectCli, JointAnglesFromAPosesListAndAYardstick) {
  const fs::path dir = SmallRosCopy("joints");
  fs::remove_all(dir / "poses");
  WriteText(dir / "poses.yaml",
            "format: selfcal-poses\nversion: 1\nposes:\n"
            "  - {image: 0.png, joints_deg: [0, -30, -120, 0, 45, 0]}\n"
            "  - {image: 1.png, joints_deg: [5, -35, -115, 3, 40, 10]}\n"
            "  - {image: 2.png, joints_deg: [-5, -25, -125, -3, 50, -10]}\n");
  const std::string base = "detect --images " + (dir / "images").string() + " --poses " + (dir / "poses.yaml").string() +
                           " --camera-fx-px 542.3 --out " + (dir / "obs.yaml").string();
  std::string out;
  EXPECT_EQ(RunSelfcal(base, &out), 2) << out;
  EXPECT_NE(out.find("need the robot's config"), std::string::npos) << out;
  EXPECT_EQ(RunSelfcal(base + " --robot " + std::string(SELFCAL_SOURCE_DIR) + "/config/robots/puma560.yaml --yardstick 0,9", &out), 2)
      << out;
  // A length no two dots have (under 1 mm, the bound of every yardstick in a file) is refused before any image
  // is read, not by the observations writer at the end.
  EXPECT_EQ(RunSelfcal(base + " --robot " + std::string(SELFCAL_SOURCE_DIR) + "/config/robots/puma560.yaml --yardstick 0,9,0.5", &out), 2)
      << out;
  EXPECT_NE(out.find("--yardstick A,B,LENGTH_MM: two point ids and their distance in [1, 100000] mm"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "obs.yaml"));
  ASSERT_EQ(RunSelfcal(base + " --robot " + std::string(SELFCAL_SOURCE_DIR) +
                           "/config/robots/puma560.yaml --yardstick 0,9,228.6 --pixel-noise-px 0.3",
                       &out),
            0)
      << out;
  const ObservationSet set = Load(dir / "obs.yaml");
  ASSERT_EQ(set.poses.size(), 3u);
  EXPECT_FALSE(set.UsesFlangePoses());
  EXPECT_EQ(set.robot.num_joints(), 6);
  EXPECT_NEAR(set.poses[1].joints_rad[5], 10 * M_PI / 180, 1e-12);
  EXPECT_EQ(set.poses[2].dots_px.size(), 100u);
  EXPECT_DOUBLE_EQ(set.pixel_noise_px, 0.3);
  ASSERT_EQ(set.yardsticks.size(), 1u);
  EXPECT_EQ(set.yardsticks[0].dot_b, 9);
  EXPECT_NEAR(set.yardsticks[0].length_m, 0.2286, 1e-15);
  // --scene marks the folder a scene of its own: every pose says so in the file (read back as written).
  ASSERT_EQ(RunSelfcal(base + " --robot " + std::string(SELFCAL_SOURCE_DIR) +
                           "/config/robots/puma560.yaml --scene next_day --force",
                       &out),
            0)
      << out;
  for (const PoseObservation& pose : Load(dir / "obs.yaml").poses) EXPECT_EQ(pose.scene, "next_day") << pose.id;
}

}  // namespace
}  // namespace selfcal
