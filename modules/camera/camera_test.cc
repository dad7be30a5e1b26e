#include "camera/camera.h"

#include <random>
#include <vector>

#include <ceres/jet.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

namespace selfcal {
namespace {

TEST(Camera, ProjectUnprojectRoundTrip) {
  CameraIntrinsics cam;
  cam.mu = 1.01;
  cam.k1 = -0.05;
  for (double x = -0.3; x <= 0.3; x += 0.05) {
    for (double y = -0.2; y <= 0.2; y += 0.05) {
      const Eigen::Vector3d p(x * 2.0, y * 2.0, 2.0);
      const auto uv = Project(cam, p);
      ASSERT_TRUE(uv.has_value());
      const Eigen::Vector2d n = PixelToNormalized(cam, cam.fx_px, *uv);
      EXPECT_NEAR(n.x(), x, 1e-12);
      EXPECT_NEAR(n.y(), y, 1e-12);
    }
  }
}

TEST(Camera, BehindCameraIsRejected) {
  CameraIntrinsics cam;
  EXPECT_FALSE(Project(cam, Eigen::Vector3d(0, 0, -1)).has_value());
  EXPECT_FALSE(Project(cam, Eigen::Vector3d(0, 0, 0)).has_value());
}

// Lenses with realistic coefficients: an Intel D435-like colour camera (mild barrel, tangential ~1e-4) and
// a cheap webcam (strong barrel with a sixth-order correction, tangential ~1e-3).
// Fields in order: width, height, f_x, mu, c_x, c_y, k1, k2, p1, p2, k3.
CameraIntrinsics D435Like() {
  return CameraIntrinsics{1280, 720, 912.6, 911.9 / 912.6, 641.3, 362.8, 0.1462, -0.4667, 0.00061, -0.00042, 0.4103};
}

CameraIntrinsics WebcamLike() {
  return CameraIntrinsics{640, 480, 598.2, 1.0137, 322.7, 235.9, -0.3711, 0.1823, -0.0013, 0.0021, -0.0457};
}

// Random points in front of the camera whose projections fall inside the image (with a margin beyond
// it: the model must match out to the corners).
std::vector<Eigen::Vector3d> PointsInView(const CameraIntrinsics& cam, int count, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-0.1 * cam.width_px, 1.1 * cam.width_px);
  std::uniform_real_distribution<double> v(-0.1 * cam.height_px, 1.1 * cam.height_px);
  std::uniform_real_distribution<double> depth(0.2, 5.0);
  std::vector<Eigen::Vector3d> points;
  while (static_cast<int>(points.size()) < count) {
    // Undistorted normalised coordinates spread over the field of view (pinhole guess).
    const double x = (u(*rng) - cam.cx_px) / cam.fx_px, y = (v(*rng) - cam.cy_px) / cam.fy_px();
    const double z = depth(*rng);
    points.emplace_back(x * z, y * z, z);
  }
  return points;
}

void ExpectMatchesOpenCv(const CameraIntrinsics& cam) {
  std::mt19937 rng(7);
  const std::vector<Eigen::Vector3d> points = PointsInView(cam, 500, &rng);
  std::vector<cv::Point3d> object;
  for (const Eigen::Vector3d& p : points) object.emplace_back(p.x(), p.y(), p.z());
  const cv::Matx33d k(cam.fx_px, 0, cam.cx_px, 0, cam.fy_px(), cam.cy_px, 0, 0, 1);
  const std::vector<double> dist = {cam.k1, cam.k2, cam.p1, cam.p2, cam.k3};
  std::vector<cv::Point2d> image;
  cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, dist, image);
  for (size_t i = 0; i < points.size(); ++i) {
    const auto uv = Project(cam, points[i]);
    ASSERT_TRUE(uv.has_value());
    EXPECT_NEAR(uv->x(), image[i].x, 1e-9) << "point " << i;
    EXPECT_NEAR(uv->y(), image[i].y, 1e-9) << "point " << i;
  }
}

TEST(Camera, ProjectionMatchesOpenCvD435Like) { ExpectMatchesOpenCv(D435Like()); }
TEST(Camera, ProjectionMatchesOpenCvWebcamLike) { ExpectMatchesOpenCv(WebcamLike()); }

TEST(Camera, UndistortInvertsTheFullModel) {
  for (const CameraIntrinsics& cam : {D435Like(), WebcamLike()}) {
    std::mt19937 rng(11);
    for (const Eigen::Vector3d& p : PointsInView(cam, 500, &rng)) {
      const auto uv = Project(cam, p);
      ASSERT_TRUE(uv.has_value());
      const Eigen::Vector2d n = PixelToNormalized(cam, cam.fx_px, *uv);
      EXPECT_NEAR(n.x(), p.x() / p.z(), 1e-12);
      EXPECT_NEAR(n.y(), p.y() / p.z(), 1e-12);
    }
  }
}

TEST(Camera, DistortJacobianMatchesAutodiff) {
  using Jet = ceres::Jet<double, 2>;
  const CameraIntrinsics cam = WebcamLike();
  for (const Eigen::Vector2d& xy : {Eigen::Vector2d(0.31, -0.22), Eigen::Vector2d(-0.5, 0.4)}) {
    Eigen::Matrix2d jacobian;
    const Eigen::Vector2d d = Distort(cam, xy, &jacobian);
    const Jet x(xy.x(), 0), y(xy.y(), 1);
    Jet radial, tx, ty;
    DistortNormalized<Jet>(Jet(cam.k1), Jet(cam.k2), Jet(cam.p1), Jet(cam.p2), Jet(cam.k3), x, y, &radial, &tx, &ty);
    const Jet xd = x * radial + tx, yd = y * radial + ty;
    EXPECT_NEAR(d.x(), xd.a, 1e-15);
    EXPECT_NEAR(d.y(), yd.a, 1e-15);
    for (int c = 0; c < 2; ++c) {
      EXPECT_NEAR(jacobian(0, c), xd.v[c], 1e-14);
      EXPECT_NEAR(jacobian(1, c), yd.v[c], 1e-14);
    }
  }
}

TEST(Camera, GeneralProjectionAgreesWithFixedTerms) {
  const CameraIntrinsics cam = D435Like();
  const IntrinsicsVector in = IntrinsicsOf(cam);
  const Eigen::Vector3d p(0.3, -0.2, 1.4);
  double u, v;
  ASSERT_TRUE(ProjectWithIntrinsics<double>(in.data(), p, &u, &v));
  const auto uv = Project(cam, p);
  EXPECT_EQ(u, uv->x());
  EXPECT_EQ(v, uv->y());
  EXPECT_EQ(IntrinsicIndex("k3"), kK3);
  EXPECT_EQ(std::string(IntrinsicName(kMu)), "mu");
  EXPECT_EQ(IntrinsicIndex("focal"), -1);
  EXPECT_EQ(IntrinsicsOf(WithIntrinsics(CameraIntrinsics(), in)), in);
}

TEST(Camera, ValidateNamesBadLensTerms) {
  CameraIntrinsics cam;
  cam.k2 = std::nan("");
  cam.p1 = 2;
  cam.k3 = 1e6;
  const std::string problems = cam.Validate();
  EXPECT_NE(problems.find("k2 = nan"), std::string::npos) << problems;
  EXPECT_NE(problems.find("p1 = 2"), std::string::npos) << problems;
  EXPECT_NE(problems.find("k3 = 1000000"), std::string::npos) << problems;
  EXPECT_EQ(problems.find("p2"), std::string::npos) << problems;
}

TEST(Camera, ValidateNamesEveryBadField) {
  CameraIntrinsics cam;
  EXPECT_EQ(cam.Validate(), "");
  cam.fx_px = 0;
  cam.mu = std::nan("");
  cam.cx_px = -3;
  const std::string problems = cam.Validate();
  EXPECT_NE(problems.find("fx_px"), std::string::npos);
  EXPECT_NE(problems.find("mu"), std::string::npos);
  EXPECT_NE(problems.find("cx_px"), std::string::npos);
}

}  // namespace
}  // namespace selfcal
