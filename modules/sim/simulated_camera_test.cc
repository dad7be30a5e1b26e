#include "sim/simulated_camera.h"

#include <gtest/gtest.h>

#include "capture/capture_test_util.h"
#include "capture/frame_source.h"

namespace selfcal::sim {
namespace {

using capture::CaptureError;
using capture::CaptureErrorOf;
using capture::Frame;
using capture::FrameSource;

// Two dots straight ahead; pose A looks at them from 0.6 m, pose B from 0.4 m (bigger dots).
DotScene TwoDots() {
  DotScene scene;
  scene.centres_in_base = {{-0.02, 0.0, 0.0}, {0.03, 0.01, 0.0}};
  scene.normals_in_base = {-Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()};
  scene.radius_m = 0.004;
  return scene;
}
Rigid3 PoseAt(double distance_m) { return Rigid3::FromTranslation(Eigen::Vector3d(0, 0, -distance_m)); }

TEST(SimulatedCamera, SimulatedTimeGivesTheFirstGridFrameAfterNotBefore) {
  SimulatedCameraOptions options;
  options.frame_period_s = 0.1;
  SimulatedCamera camera(CameraIntrinsics(), TwoDots(), options);
  FrameSource& source = camera;  // used exactly like a live camera
  EXPECT_TRUE(source.Describe().find("not open") != std::string::npos);
  ASSERT_TRUE(source.Open().ok());
  camera.SetPose(PoseAt(0.6), 0.0);
  camera.SetPose(PoseAt(0.4), 1.0);  // the simulated robot arrives at B at t = 1.0 s

  Result<Frame> f = source.Grab(1.25, 0.0);  // settled at 1.25 s
  ASSERT_TRUE(f.ok()) << f.status().ToString();
  EXPECT_EQ(f->sequence, 13);  // t_13 = 1.3 s: the first grid frame at or after 1.25 s
  EXPECT_NEAR(f->exposure_time_s, 1.3, 1e-12);
  EXPECT_EQ(f->source, "sim");
  // The image is the render of pose B with the frame's noise seed, and last_render holds its truth.
  const RenderedImage expected = RenderDots(CameraIntrinsics(), PoseAt(0.4), TwoDots(), options.render,
                                            FrameNoiseSeed(options.render.noise_seed, 13));
  EXPECT_TRUE(capture::testing::SameImage(f->image, expected.image));
  EXPECT_EQ(camera.last_render().dots[1].area_centroid_px, expected.dots[1].area_centroid_px);
  // Frames advance even if not_before_s lies in the past.
  f = source.Grab(0.0, 0.0);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f->sequence, 14);
  source.Close();
  EXPECT_FALSE(source.Grab(0.0, 0.0).ok());
}

TEST(SimulatedCamera, AFrameExposedBeforeTheMoveEndedShowsTheOldPose) {
  SimulatedCameraOptions options;
  options.frame_period_s = 0.1;
  SimulatedCamera camera(CameraIntrinsics(), TwoDots(), options);
  ASSERT_TRUE(camera.Open().ok());
  camera.SetPose(PoseAt(0.6), 0.0);
  camera.SetPose(PoseAt(0.4), 1.0);
  // A caller that does not wait for the settle time gets a stale image (V5): the simulator does not
  // hide the mistake.
  Result<Frame> stale = camera.Grab(0.55, 0.0);
  ASSERT_TRUE(stale.ok());
  EXPECT_LT(stale->exposure_time_s, 1.0);
  const double radius_a = std::sqrt(camera.last_render().dots[0].area_px2 / kPi);
  EXPECT_NEAR(radius_a, 1000 * 0.004 / 0.6, 1e-6);  // pose A's distance, not B's
}

TEST(SimulatedCamera, NoPoseIsACallerErrorAndBadFramesAreRefused) {
  SimulatedCamera camera(CameraIntrinsics(), TwoDots());
  ASSERT_TRUE(camera.Open().ok());
  const Result<Frame> none = camera.Grab(0.0, 0.0);
  EXPECT_EQ(none.status().code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(none.status().message().find("SetPose") != std::string::npos);

  SimulatedCameraOptions dark;
  dark.render.background_grey = 5;  // lights off
  dark.render.dot_grey = 0;
  SimulatedCamera black(CameraIntrinsics(), TwoDots(), dark);
  ASSERT_TRUE(black.Open().ok());
  black.SetPose(PoseAt(0.6), 0.0);
  EXPECT_EQ(CaptureErrorOf(black.Grab(0.0, 0.0).status()), CaptureError::kBadFrame);

  SimulatedCameraOptions invalid;
  invalid.render.supersampling = 9;
  EXPECT_EQ(SimulatedCamera(CameraIntrinsics(), TwoDots(), invalid).Open().code(), ErrorCode::kInvalidInput);
}

TEST(SimulatedCamera, RealTimeWaitsForTheExposureAndTimesOut) {
  SimulatedCameraOptions options;
  options.real_time = true;
  options.frame_period_s = 0.01;
  options.readout_s = 0.005;
  CameraIntrinsics small;
  small.width_px = 160;
  small.height_px = 120;
  small.cx_px = 79.5;
  small.cy_px = 59.5;
  small.fx_px = 250;
  SimulatedCamera camera(small, TwoDots(), options);
  ASSERT_TRUE(camera.Open().ok());
  camera.SetPose(PoseAt(0.6), capture::MonotonicNowS() - 1.0);
  const double settle = capture::MonotonicNowS() + 0.03;
  Result<Frame> f = camera.Grab(settle, 1.0);
  ASSERT_TRUE(f.ok()) << f.status().ToString();
  EXPECT_GE(f->exposure_time_s, settle);
  EXPECT_LT(f->exposure_time_s, settle + options.frame_period_s + 1e-9);
  EXPECT_GE(capture::MonotonicNowS(), f->exposure_time_s + options.readout_s);  // delivered after readout
  // A settle time 5 s away cannot be met within 50 ms.
  const double asked = capture::MonotonicNowS();
  const Result<Frame> late = camera.Grab(asked + 5.0, 0.05);
  EXPECT_EQ(CaptureErrorOf(late.status()), CaptureError::kTimeout);
  const double waited = capture::MonotonicNowS() - asked;
  EXPECT_GE(waited, 0.05 - 1e-3);
  EXPECT_LT(waited, 1.0);
}

}  // namespace
}  // namespace selfcal::sim
