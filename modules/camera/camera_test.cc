#include "camera/camera.h"

#include <gtest/gtest.h>

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
