// V4L2 error paths that need no camera (../shared/RELIABILITY.md V1). What needs hardware is listed in
// v4l2_camera.h.
#include "capture/v4l2_camera.h"

#include <sys/stat.h>

#include <gtest/gtest.h>

#include "capture/capture_test_util.h"

namespace selfcal::capture {
namespace {

using testing::Contains;
using testing::TempDir;

TEST(V4l2V1, MissingDeviceNamesTheNodeAndErrno) {
  const Result<V4l2DeviceInfo> probe = ProbeV4l2Device("/dev/video99");
  ASSERT_FALSE(probe.ok());
  EXPECT_EQ(CaptureErrorOf(probe.status()), CaptureError::kDeviceMissing);
  EXPECT_EQ(probe.status().code(), ErrorCode::kHardware);
  EXPECT_TRUE(Contains(probe.status().message(), "/dev/video99")) << probe.status().message();
  EXPECT_TRUE(Contains(probe.status().message(), "ENOENT")) << probe.status().message();
  EXPECT_TRUE(Contains(probe.status().message(), "video nodes present:")) << probe.status().message();

  V4l2Options options;
  options.device = "/dev/video99";
  V4l2Camera camera(options);
  EXPECT_TRUE(Contains(camera.Describe(), "/dev/video99 (not open"));
  const Status open = camera.Open();
  EXPECT_EQ(CaptureErrorOf(open), CaptureError::kDeviceMissing);
  EXPECT_TRUE(Contains(open.message(), "/dev/video99")) << open.message();
  // Grab without a successful Open is a caller error, not a hang.
  const Result<Frame> grab = camera.Grab(0.0, 0.1);
  EXPECT_FALSE(grab.ok());
  EXPECT_EQ(grab.status().code(), ErrorCode::kInvalidInput);
  camera.Close();
  camera.Close();
}

TEST(V4l2V1, RegularFileIsNotV4l2) {
  TempDir dir;
  const std::string path = dir.File("video0");
  testing::WriteFile(path, "not a device");
  const Result<V4l2DeviceInfo> probe = ProbeV4l2Device(path);
  EXPECT_EQ(CaptureErrorOf(probe.status()), CaptureError::kNotV4l2);
  EXPECT_TRUE(Contains(probe.status().message(), path + ": is a regular file")) << probe.status().message();
  V4l2Options options;
  options.device = path;
  V4l2Camera camera(options);
  EXPECT_EQ(CaptureErrorOf(camera.Open()), CaptureError::kNotV4l2);
}

TEST(V4l2V1, DirectoryIsNotV4l2) {
  TempDir dir;
  const Result<V4l2DeviceInfo> probe = ProbeV4l2Device(dir.path());
  EXPECT_EQ(CaptureErrorOf(probe.status()), CaptureError::kNotV4l2);
  EXPECT_TRUE(Contains(probe.status().message(), dir.path() + ": is a directory")) << probe.status().message();
}

TEST(V4l2V1, CharacterDeviceThatIsNotV4l2) {
  struct stat st {};
  if (::stat("/dev/null", &st) != 0 || !S_ISCHR(st.st_mode)) GTEST_SKIP() << "no /dev/null character device here";
  const Result<V4l2DeviceInfo> probe = ProbeV4l2Device("/dev/null");
  EXPECT_EQ(CaptureErrorOf(probe.status()), CaptureError::kNotV4l2);
  EXPECT_TRUE(Contains(probe.status().message(), "/dev/null: not a V4L2 device")) << probe.status().message();
  EXPECT_TRUE(Contains(probe.status().message(), "ENOTTY")) << probe.status().message();
}

TEST(V4l2Options, ValidateListsEveryProblemAndOpenRefusesBeforeTouchingTheDevice) {
  V4l2Options options;
  EXPECT_EQ(options.Validate(), "");
  options.device = "/dev/video99";
  options.width_px = 0;
  options.num_buffers = 0;
  options.open_timeout_s = -1;
  const std::string problems = options.Validate();
  EXPECT_TRUE(Contains(problems, "image size 0x480"));
  EXPECT_TRUE(Contains(problems, "num_buffers = 0"));
  EXPECT_TRUE(Contains(problems, "open_timeout_s = -1"));
  V4l2Camera camera(options);
  const Status open = camera.Open();
  EXPECT_EQ(open.code(), ErrorCode::kInvalidInput);  // configuration, not hardware: the device was not probed
  EXPECT_TRUE(Contains(open.message(), "num_buffers")) << open.message();
}

TEST(V4l2, FourccNames) {
  EXPECT_EQ(FourccToString(0x56595559u), "YUYV");
  EXPECT_STREQ(V4l2PixelFormatName(V4l2PixelFormat::kGrey), "GREY");
}

}  // namespace
}  // namespace selfcal::capture
