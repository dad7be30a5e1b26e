// The check of a requested V4L2 mode against what a device lists, without a device: the list is written
// out as a UVC webcam's (discrete sizes and intervals) and a sensor driver's (stepwise) enumerations read.
#include "capture/v4l2_modes.h"

#include <linux/videodev2.h>

#include <gtest/gtest.h>

#include "capture/capture_test_util.h"
#include "capture/frame_source.h"
#include "capture/v4l2_camera.h"

namespace selfcal::capture {
namespace {

using testing::Contains;

V4l2Mode Discrete(uint32_t fourcc, int w, int h, std::vector<double> fps) {
  V4l2Mode m;
  m.fourcc = fourcc;
  m.min_width_px = m.max_width_px = w;
  m.min_height_px = m.max_height_px = h;
  for (double f : fps) m.periods_s.push_back(1.0 / f);
  return m;
}

// A typical UVC webcam: YUYV only up to 640x480 at 30 fps and 1280x720 at 10; MJPEG up to 1920x1080 at 30.
std::vector<V4l2Mode> Webcam() {
  return {Discrete(V4L2_PIX_FMT_YUYV, 640, 480, {30, 15}), Discrete(V4L2_PIX_FMT_YUYV, 1280, 720, {10}),
          Discrete(V4L2_PIX_FMT_MJPEG, 640, 480, {30}), Discrete(V4L2_PIX_FMT_MJPEG, 1280, 720, {30, 60}),
          Discrete(V4L2_PIX_FMT_MJPEG, 1920, 1080, {30})};
}

TEST(V4l2Modes, OfferedModesPass) {
  EXPECT_TRUE(CheckV4l2ModeOffered(Webcam(), "/dev/video0", V4L2_PIX_FMT_MJPEG, 1280, 720, 1.0 / 60).ok());
  EXPECT_TRUE(CheckV4l2ModeOffered(Webcam(), "/dev/video0", V4L2_PIX_FMT_YUYV, 640, 480, 1.0 / 15).ok());
  // Drivers give 1/30 s as 333333/10000000: within 1 %.
  EXPECT_TRUE(CheckV4l2ModeOffered(Webcam(), "/dev/video0", V4L2_PIX_FMT_MJPEG, 1920, 1080, 0.0333333).ok());
}

TEST(V4l2Modes, RefusalNamesTheDeviceWhatWasAskedAndWhatItOffers) {
  const Status size = CheckV4l2ModeOffered(Webcam(), "/dev/video2", V4L2_PIX_FMT_YUYV, 1920, 1080, 1.0 / 30);
  ASSERT_FALSE(size.ok());
  EXPECT_EQ(CaptureErrorOf(size), CaptureError::kFormatMismatch);
  EXPECT_TRUE(Contains(size.message(), "camera /dev/video2 does not offer YUYV 1920x1080 at 30 fps (not at that size)"))
      << size.message();
  EXPECT_TRUE(Contains(size.message(), "  MJPG 1280x720 @ 30, 60 fps\n")) << size.message();
  EXPECT_TRUE(Contains(size.message(), "  YUYV 640x480 @ 30, 15 fps\n")) << size.message();
  const Status rate = CheckV4l2ModeOffered(Webcam(), "/dev/video2", V4L2_PIX_FMT_YUYV, 1280, 720, 1.0 / 30);
  EXPECT_TRUE(Contains(rate.message(), "(not at that frame rate)")) << rate.message();
  // No rate asked for (period 0): the size and format decide, the driver's rate is taken.
  EXPECT_TRUE(CheckV4l2ModeOffered(Webcam(), "/dev/video2", V4L2_PIX_FMT_YUYV, 1280, 720, 0).ok());
  const Status any_rate = CheckV4l2ModeOffered(Webcam(), "/dev/video2", V4L2_PIX_FMT_YUYV, 1920, 1080, 0);
  EXPECT_TRUE(Contains(any_rate.message(), "does not offer YUYV 1920x1080 (not at that size)")) << any_rate.message();
  const Status format = CheckV4l2ModeOffered(Webcam(), "/dev/video2", V4L2_PIX_FMT_GREY, 640, 480, 1.0 / 30);
  EXPECT_TRUE(Contains(format.message(), "GREY 640x480 at 30 fps (no such pixel format)")) << format.message();
  EXPECT_TRUE(Contains(format.message(), "--camera-width-px")) << format.message();
}

TEST(V4l2Modes, StepwiseSizesAndContinuousIntervals) {
  V4l2Mode sensor;
  sensor.fourcc = V4L2_PIX_FMT_GREY;
  sensor.min_width_px = 32, sensor.max_width_px = 2048, sensor.step_width_px = 16;
  sensor.min_height_px = 32, sensor.max_height_px = 1536, sensor.step_height_px = 2;
  sensor.min_period_s = 1.0 / 120, sensor.max_period_s = 1.0;
  const std::vector<V4l2Mode> modes = {sensor};
  EXPECT_TRUE(CheckV4l2ModeOffered(modes, "/dev/video0", V4L2_PIX_FMT_GREY, 1280, 720, 1.0 / 50).ok());
  EXPECT_FALSE(CheckV4l2ModeOffered(modes, "/dev/video0", V4L2_PIX_FMT_GREY, 1288, 720, 1.0 / 50).ok());  // step
  EXPECT_FALSE(CheckV4l2ModeOffered(modes, "/dev/video0", V4L2_PIX_FMT_GREY, 4096, 720, 1.0 / 50).ok());
  EXPECT_FALSE(CheckV4l2ModeOffered(modes, "/dev/video0", V4L2_PIX_FMT_GREY, 1280, 720, 1.0 / 200).ok());
  EXPECT_EQ(V4l2ModesText(modes), "  GREY 32x32 to 2048x1536 in steps of 16x2 @ 1 to 120 fps\n");
}

TEST(V4l2Modes, ADriverThatListsNothingIsCheckedByReadBackOnly) {
  EXPECT_TRUE(CheckV4l2ModeOffered({}, "/dev/video0", V4L2_PIX_FMT_MJPEG, 1280, 720, 1.0 / 30).ok());
  V4l2Mode no_periods = Discrete(V4L2_PIX_FMT_MJPEG, 1280, 720, {});
  EXPECT_TRUE(CheckV4l2ModeOffered({no_periods}, "/dev/video0", V4L2_PIX_FMT_MJPEG, 1280, 720, 1.0 / 25).ok());
}

TEST(V4l2Modes, PixelFormatNames) {
  V4l2PixelFormat format = V4l2PixelFormat::kGrey;
  ASSERT_TRUE(V4l2PixelFormatFromName("MJPG", &format));
  EXPECT_EQ(format, V4l2PixelFormat::kMjpeg);
  EXPECT_FALSE(V4l2PixelFormatFromName("mjpeg", &format));
}

TEST(V4l2Modes, EnumeratingSomethingThatIsNotADeviceGivesNothing) {
  EXPECT_TRUE(EnumerateV4l2Modes(-1).empty());
}

}  // namespace
}  // namespace selfcal::capture
